"""Dynamic-window baseline in the style of nav2's DWB controller.

Per control step:

1. the global path (A* on an inflated grid, :mod:`humanmpc.planners.global_path`) is replanned every
   ``replan_period`` seconds with the humans' *current* positions as obstacles, as nav2's
   default behaviour tree replans at 1 Hz on a costmap whose obstacle layer sees the people;
2. (v, omega) pairs are sampled in the dynamic window: v within ``a_min dt .. a_max dt`` of the
   current speed (and in [v_min, min(v_max, v_ref)]), omega over its whole range (the robot's
   omega is a control, it has no angular acceleration limit);
3. each sample is rolled out for ``sim_time``: the acceleration that reaches v in one period,
   then constant (v, omega) (what the robot does if the command is kept);
4. critics, with nav2's default scales: PathDist and PathAlign (distance of the end pose / of a
   point ``forward_point_distance`` ahead of it to the local path), GoalDist and GoalAlign (the
   same to the local goal, the end of the local path), in costmap cells of ``cell_size`` as
   nav2 measures them (the two Align critics are off within ``align_off_distance`` of the
   goal); BaseObstacle-style costs from a costmap inflation model
   (``252 exp(-cost_scaling * clearance)``) of static obstacles and of humans at their current
   positions (no predictions), where a pose with negative clearance makes the sample invalid;
5. the cheapest valid sample wins, ``u = ((v - v0) / dt, omega)``. Without a valid sample the
   planner commands a protective stop (reason ``"no_valid_trajectory"``).

Not modelled: the Oscillation and RotateToGoal critics (the episode ends at the goal position)
and nav2's trajectory-generator details (sim granularity, include_last_point).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..sim.unicycle import integrate
from .global_path import GlobalPlanner, GridConfig, local_segment
from .interface import Observation, PlanResult, protective_stop

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class DWBConfig:
    """Sampling, rollout and critic parameters (scales: nav2 DWB defaults)."""

    sim_time: float = 1.7
    rollout_dt: float = 0.1
    v_samples: int = 7
    omega_samples: int = 21
    lookahead: float = 3.0
    forward_point_distance: float = 0.325
    cell_size: float = 0.05
    path_dist_scale: float = 32.0
    path_align_scale: float = 32.0
    goal_dist_scale: float = 24.0
    goal_align_scale: float = 24.0
    obstacle_scale: float = 0.02
    human_scale: float = 0.02
    cost_scaling: float = 3.0
    inflation_radius: float = 0.55
    replan_period: float = 1.0
    align_off_distance: float = 1.0
    grid: GridConfig = field(default_factory=GridConfig)

    def __post_init__(self) -> None:
        if self.sim_time <= 0 or self.rollout_dt <= 0 or self.v_samples < 1 or self.omega_samples < 1:
            raise ValueError(f"DWBConfig: invalid sampling {self}")


@dataclass(frozen=True)
class Rollouts:
    """Sampled commands (S, 2) as (v, omega) and their rolled-out states (S, T + 1, 4)."""

    commands: FloatArray
    states: FloatArray


def sample_window(obs: Observation, cfg: DWBConfig) -> FloatArray:
    """(v, omega) samples reachable within one control period, (S, 2)."""
    lim = obs.robot.limits
    v0 = float(obs.x[3])
    v_ref = float(obs.goal[3])
    v_cap = min(lim.v_max, v_ref) if v_ref > 0 else lim.v_max
    v_hi = min(v_cap, v0 + lim.a_max * obs.dt)
    v_lo = max(lim.v_min, v0 + lim.a_min * obs.dt)
    if v_hi < v_lo:  # faster than the cap: brake as hard as allowed
        v_hi = v_lo
    vs = np.unique(np.linspace(v_lo, v_hi, cfg.v_samples))
    ws = np.unique(np.concatenate([np.linspace(lim.omega_min, lim.omega_max, cfg.omega_samples), [0.0]]))
    vv, ww = np.meshgrid(vs, ws, indexing="ij")
    return np.stack([vv.ravel(), ww.ravel()], axis=1)


def rollout(obs: Observation, commands: FloatArray, cfg: DWBConfig) -> Rollouts:
    """Simulate every command from the current state (vectorised over samples)."""
    steps = round(cfg.sim_time / cfg.rollout_dt)
    s = commands.shape[0]
    x = np.tile(np.asarray(obs.x, dtype=float), (s, 1))
    a = (commands[:, 0] - x[:, 3]) / obs.dt
    states = [x]
    # First control period: accelerate to the sampled speed.
    x = integrate(x, np.stack([a, commands[:, 1]], axis=1), obs.dt, substeps=2)
    x[:, 3] = commands[:, 0]
    states.append(x)
    u_hold = np.stack([np.zeros(s), commands[:, 1]], axis=1)
    for _ in range(steps - 1):
        x = integrate(x, u_hold, cfg.rollout_dt, substeps=1)
        states.append(x)
    return Rollouts(commands, np.stack(states, axis=1))


def inflation_cost(clearance: FloatArray, cfg: DWBConfig) -> FloatArray:
    """nav2 costmap inflation value of a clearance (m); only meaningful for clearance >= 0."""
    c = np.maximum(clearance, 0.0)
    return np.where(c <= cfg.inflation_radius, 252.0 * np.exp(-cfg.cost_scaling * c), 0.0)


def _distance_to_polyline(points: FloatArray, line: FloatArray) -> FloatArray:
    a, b = line[:-1], line[1:]
    ab = b - a
    denom = np.maximum(np.einsum("sk,sk->s", ab, ab), 1e-12)
    ap = points[:, None, :] - a[None]
    t = np.clip(np.einsum("psk,sk->ps", ap, ab) / denom, 0.0, 1.0)
    proj = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - proj, axis=-1).min(axis=1)


def score(obs: Observation, ro: Rollouts, local_path: FloatArray, cfg: DWBConfig) -> tuple[FloatArray, FloatArray]:
    """Total cost (S,) and validity mask (S,) of every rollout."""
    pos = ro.states[:, 1:, :2]  # the current pose is where the robot is anyway
    robot = obs.robot
    static_clear = obs.world.signed_distance(pos) - robot.radius  # (S, T)
    if obs.n_humans:
        d = np.linalg.norm(pos[:, :, None, :] - obs.humans_now[None, None], axis=-1).min(axis=-1)
        human_clear = d - robot.radius - robot.human_radius
    else:
        human_clear = np.full(pos.shape[:2], np.inf)
    valid = (static_clear.min(axis=1) >= 0.0) & (human_clear.min(axis=1) >= 0.0)

    end = ro.states[:, -1]
    fwd = end[:, :2] + cfg.forward_point_distance * np.stack([np.cos(end[:, 2]), np.sin(end[:, 2])], axis=1)
    carrot = local_path[-1]
    cells = 1.0 / cfg.cell_size
    path_dist = _distance_to_polyline(end[:, :2], local_path) * cells
    path_align = _distance_to_polyline(fwd, local_path) * cells
    goal_dist = np.linalg.norm(end[:, :2] - carrot, axis=1) * cells
    goal_align = np.linalg.norm(fwd - carrot, axis=1) * cells
    if np.linalg.norm(np.asarray(obs.x[:2]) - np.asarray(obs.goal[:2])) < cfg.align_off_distance:
        # Like nav2, the alignment critics are switched off near the goal: their forward point
        # would otherwise stop the robot a forward_point_distance short of it.
        path_align = goal_align = np.zeros_like(path_align)
    obstacle = inflation_cost(static_clear, cfg).max(axis=1)
    human = inflation_cost(human_clear, cfg).max(axis=1)
    total = (
        cfg.path_dist_scale * path_dist
        + cfg.path_align_scale * path_align
        + cfg.goal_dist_scale * goal_dist
        + cfg.goal_align_scale * goal_align
        + cfg.obstacle_scale * obstacle
        + cfg.human_scale * human
    )
    return total, valid


class DWBPlanner:
    """nav2-DWB-style local planner following an A* global path (see the module docstring)."""

    name = "dwb"

    def __init__(self, config: DWBConfig | None = None) -> None:
        self.config = config or DWBConfig()
        self._global = GlobalPlanner(self.config.grid, self.config.replan_period)

    def reset(self) -> None:
        self._global.reset()

    @property
    def global_path(self) -> FloatArray | None:
        return self._global.path

    def plan(self, obs: Observation) -> PlanResult:
        robot = obs.robot
        global_ms = self._global.update(
            obs.time, obs.world, obs.x[:2], obs.goal, robot.radius, obs.humans_now, robot.human_radius
        )
        path = self._global.path
        assert path is not None
        t0 = time.perf_counter()
        cfg = self.config
        local_path = local_segment(path, obs.x[:2], cfg.lookahead)
        ro = rollout(obs, sample_window(obs, cfg), cfg)
        total, valid = score(obs, ro, local_path, cfg)
        local_ms = (time.perf_counter() - t0) * 1e3
        timings = {"local_ms": local_ms, "global_plan_ms": global_ms}
        if not np.any(valid):
            res = protective_stop(obs, "no_valid_trajectory", local_ms)
            return PlanResult(
                u=res.u, command=res.command, stop=True, reason=res.reason, status="no_valid_trajectory",
                solve_time_ms=local_ms, timings=timings,
            )
        best = int(np.argmin(np.where(valid, total, np.inf)))
        v, omega = ro.commands[best]
        a = (v - float(obs.x[3])) / obs.dt
        return PlanResult(
            u=np.array([a, omega]),
            command=np.array([v, omega]),
            path=ro.states[best],
            status="ok",
            solve_time_ms=local_ms,
            timings=timings,
        )
