"""The generated MPC as a planner of the evaluation (registered as "mpc" and "mpc_paper").

Per control step it hands the solver what the robot observes: its state, a goal, the humans now
and their constant-velocity predictions, and the nearest obstacle point (the OCP of the paper,
unchanged). Around the OCP it does what the paper's ROS controller plugin does around it, and
what the DWB baseline of the evaluation gets as well (:class:`MPCPlannerConfig`):

- the goal it hands the OCP: a carrot ``lookahead`` metres along a global path from the global
  planner the DWB uses too (:class:`~humanmpc.planners.global_path.GlobalPlanner`: A* on the static map,
  replanned at 1 Hz), with the path's heading there; or, with ``global_path=False``, the final
  goal itself. The DWB's global path also avoids the humans' current positions; the MPC's does
  not (``path_humans=False``): the OCP handles the humans with their predictions, and a path
  around where they stand now sends the carrot across their way (docs/evaluation.md);
- the goal checker: v_ref tapers near the final goal (v_ref <= ``goal_taper`` m/s per metre
  left), so that the robot stops there instead of circling it at cruising speed (the OCP itself
  tracks v_ref); with ``approach=True``, once the horizon reaches the final goal, the OCP tracks
  no speed, weighs the position at every node (``approach_position``) and asks for the goal at
  rest at the end (``approach_stop``);
- the speed limit: with ``speed_limit=True`` the OCP's bound on v is min(v_max, v_ref), the cap
  the DWB samples its speeds under (without it the goal terms drive the MPC at v_max);
- runtime parameters set on the solver (``params``, e.g. the RTI Hessian);
- a restart out of loops: a real-time iteration improves the last plan by one step, so it stays in
  the local solution it is in; when that is a loop (the plan's end nearer its start than
  ``loop_restart`` times its length), the step is replaced by a full SQP from a cold start
  (``restart_iterations`` at most), whose plan the next real-time iterations continue from;
- more humans than the solver's N_h: the N_h closest to the robot are passed, which is what
  matters for the hard distance rows and, with f decaying in d, for the cost.

``MPCPlannerConfig.paper()`` is the configuration the evaluation started from: the final goal,
no speed limit beyond the spec's bounds, the spec's parameters (the paper's values).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import numpy as np

from ..bindings import load
from ..solver import Solver
from .global_path import GlobalPlanner, GridConfig, local_segment
from .interface import Observation, PlanResult
from .solver_dir import DEFAULT_SOLVER_DIR as DEFAULT_SOLVER_DIR  # moved to solver_dir, re-exported here
from .solver_dir import ensure_solver as ensure_solver

GOAL_TAPER = 0.5  # v_ref <= GOAL_TAPER * distance to the goal
LOOP_RATIO = 0.5  # a plan whose end is nearer its start than half its length is a loop
LOOP_MIN_LENGTH = 1.0  # [m] shorter plans (stopping, waiting, arriving) are never loops
RESTART_ITERATIONS = 10  # SQP iterations of a loop restart: 1.5..5 ms, well inside the 20 ms deadline
APPROACH_POSITION = 5.0  # stage weight on the position once the horizon reaches the goal (paper: 0.5)
APPROACH_STOP = 40.0  # terminal weight on the speed there (to 0), that of the terminal position

# Runtime parameters of the evaluation's MPC (docs/evaluation.md has the measurements behind them):
# - exact_hessian: the Gauss-Newton RTI throws omega between its bounds when the goal is metres away;
# - slack_l1 (obstacle row): 100 is no exact penalty against the speed-tracking weight, the plans cut
#   d_s to the nearest obstacle by up to 0.46 m with nobody near and the robot hits walls; 1000 keeps
#   d_s whenever it can be kept and still yields to the human rows (1e4);
# - q: with the paper's q = 2 the collision potential (at most q/2 + kappa q d_th / 4 = 3.5 per human
#   and node) is negligible next to the speed-tracking term, the robot never trades speed for distance;
# - w_goal[3], the speed-tracking weight w_v: with the paper's 250, standing still for the 5 s horizon
#   costs 250 * 0.8^2 * 50 = 8000, more than running metres off the way beside a crossing group;
#   q = 50 and w_v = 50 were chosen together on the tuning seeds 100..139 (docs/weight_selection.py).
EVALUATION_PARAMS: Mapping[str, Any] = MappingProxyType(
    {"exact_hessian": 1, "slack_l1": 1000.0, "q": 50.0, "w_goal": (0.5, 0.5, 0.0, 50.0)}
)


@dataclass(frozen=True)
class MPCPlannerConfig:
    """What the planner does around the OCP (see the module docstring)."""

    global_path: bool = True
    lookahead: float | None = None  # carrot distance [m]; None: v_ref * T, the plan's length at v_ref
    replan_period: float = 1.0
    grid: GridConfig = field(default_factory=GridConfig)
    goal_taper: float = GOAL_TAPER
    approach: bool = True
    approach_position: float | None = APPROACH_POSITION  # stage weight on px, py in the approach; None: unchanged
    approach_stop: float | None = APPROACH_STOP  # terminal weight on v (to 0) in the approach; None: unchanged
    speed_limit: bool = True
    path_humans: bool = False  # the global path also avoids the humans' current positions
    loop_restart: float | None = LOOP_RATIO
    restart_iterations: int = RESTART_ITERATIONS
    params: Mapping[str, Any] = field(default_factory=lambda: dict(EVALUATION_PARAMS))

    def __post_init__(self) -> None:
        if self.lookahead is not None and not self.lookahead > 0:
            raise ValueError(f"MPCPlannerConfig.lookahead must be > 0 or None, got {self.lookahead}")
        if not (self.replan_period > 0 and self.goal_taper > 0):
            raise ValueError(f"MPCPlannerConfig: replan_period and goal_taper must be > 0, got {self}")
        if self.loop_restart is not None and not 0 < self.loop_restart < 1:
            raise ValueError(f"MPCPlannerConfig.loop_restart must be in (0, 1) or None, got {self.loop_restart}")
        if self.restart_iterations < 1:
            raise ValueError(f"MPCPlannerConfig.restart_iterations must be >= 1, got {self.restart_iterations}")

    @staticmethod
    def paper() -> MPCPlannerConfig:
        """The final goal, the spec's bounds and parameters: the paper's OCP with nothing around it but
        the goal taper and the choice of the closest N_h humans."""
        return MPCPlannerConfig(global_path=False, approach=False, speed_limit=False, loop_restart=None,
                                params={})


class MPCPlanner:
    name = "mpc"

    def __init__(self, solver: Solver | None = None, config: MPCPlannerConfig | None = None,
                 name: str | None = None) -> None:
        self.solver = solver or load(ensure_solver())
        self.config = config or MPCPlannerConfig()
        if name is not None:
            self.name = name
        if self.config.params:
            self.solver.set_params(**dict(self.config.params))
        self._v_bounds = tuple(self.solver.params["v_bounds"])
        self._w_goal = tuple(self.solver.params["w_goal"])
        self._w_goal_terminal = tuple(self.solver.params["w_goal_terminal"])
        self._global = GlobalPlanner(self.config.grid, self.config.replan_period)
        self.last_goal: np.ndarray | None = None  # the goal handed to the OCP at the last step
        self.restarts = 0  # loop restarts in this episode

    def reset(self) -> None:
        self.solver.reset()
        self._global.reset()
        self.last_goal = None
        self.restarts = 0

    def ocp_goal(self, obs: Observation) -> np.ndarray:
        """The goal handed to the OCP: the carrot on the global path (or the final goal) with the
        tapered v_ref."""
        cfg = self.config
        final = np.array(obs.goal, dtype=float)
        goal = final.copy()
        if cfg.global_path:
            robot = obs.robot
            self._global.update(obs.time, obs.world, obs.x[:2], final, robot.radius,
                                obs.humans_now if cfg.path_humans else None, robot.human_radius)
            path = self._global.path
            assert path is not None
            lookahead = cfg.lookahead if cfg.lookahead is not None else final[3] * self.solver.dims.T
            segment = local_segment(path, obs.x[:2], lookahead)
            carrot = segment[-1]
            if np.linalg.norm(carrot - final[:2]) > 1e-9:  # at the final goal keep its heading
                direction = segment[-1] - segment[-2]
                goal[:2] = carrot
                goal[2] = float(np.arctan2(direction[1], direction[0]))
        left = float(np.hypot(*(final[:2] - obs.x[:2])))
        goal[3] = min(final[3], cfg.goal_taper * left)
        if cfg.approach:
            # Once the horizon reaches the final goal, a speed to track over all of it makes the plan
            # loop around the goal to spend its length; the approach drops that weight and lets the
            # position terms bring the robot to the goal. With the paper's stage weight on the
            # position (0.5) nothing asks it to get there before the end of the horizon, and a plan
            # that arrives in 5 s is renewed every step: the robot circles the goal at cruising speed
            # (approach_position); the terminal speed weight makes the plan arrive at rest
            # (approach_stop).
            w, wt = list(self._w_goal), list(self._w_goal_terminal)
            if left < final[3] * self.solver.dims.T:
                w[3] = 0.0
                if cfg.approach_position is not None:
                    w[0] = w[1] = cfg.approach_position
                if cfg.approach_stop is not None:
                    wt[3] = cfg.approach_stop
                    goal[3] = 0.0
            if tuple(self.solver.params["w_goal"]) != tuple(w):
                self.solver.set_params(w_goal=w)
            if tuple(self.solver.params["w_goal_terminal"]) != tuple(wt):
                self.solver.set_params(w_goal_terminal=wt)
        return goal

    def _apply_speed_limit(self, v_ref: float) -> None:
        lo, hi = self._v_bounds
        bounds = (lo, min(hi, v_ref)) if self.config.speed_limit and v_ref > lo else (lo, hi)
        if tuple(self.solver.params["v_bounds"]) != bounds:
            self.solver.set_params(v_bounds=list(bounds))

    def plan(self, obs: Observation) -> PlanResult:
        s = self.solver
        if obs.humans_pred.shape[0] != s.dims.N + 1 or abs(obs.dt - s.dims.dt) > 1e-9:
            raise ValueError(f"the episode predicts {obs.humans_pred.shape[0] - 1} intervals of {obs.dt} s; "
                             f"the solver needs {s.dims.N} of {s.dims.dt} s (EpisodeConfig(horizon, dt))")
        goal = self.ocp_goal(obs)
        self.last_goal = goal
        self._apply_speed_limit(float(obs.goal[3]))
        now, pred = obs.humans_now, obs.humans_pred
        if now.shape[0] > s.dims.nh:
            closest = np.argsort(np.linalg.norm(now - obs.x[:2], axis=1))[: s.dims.nh]
            now, pred = now[closest], pred[:, closest]
        r = s.step(obs.x, goal, now, pred, obs.obstacle)
        time_ms = r.time_total_ms
        if self.config.loop_restart is not None and not r.stop and is_loop(r.x, self.config.loop_restart):
            s.reset()
            cold = s.solve(obs.x, goal, now, pred, obs.obstacle, max_iter=self.config.restart_iterations)
            time_ms += cold.time_total_ms
            self.restarts += 1
            if cold.stop:
                s.reset()  # the loop's first control is applied; the next step starts cold
            else:
                r = cold
        return PlanResult(
            u=r.u0, command=r.command, path=r.x, controls=r.u, stop=r.stop, reason=r.reason,
            status=r.status_name, solve_time_ms=time_ms,
            timings={"prepare_ms": r.time_prepare_ms, "feedback_ms": r.time_feedback_ms,
                     "qp_iterations": float(r.qp_iterations)},
        )


def is_loop(plan: np.ndarray, ratio: float = LOOP_RATIO, min_length: float = LOOP_MIN_LENGTH) -> bool:
    """Whether a planned path (rows x, y, ...) of at least ``min_length`` metres ends nearer its start
    than ``ratio`` times its length."""
    length = float(np.sum(np.linalg.norm(np.diff(plan[:, :2], axis=0), axis=1)))
    return length >= min_length and float(np.linalg.norm(plan[-1, :2] - plan[0, :2])) < ratio * length


def with_params(config: MPCPlannerConfig, **params: Any) -> MPCPlannerConfig:
    """``config`` with more runtime parameters (e.g. ``q=20.0``)."""
    return replace(config, params={**dict(config.params), **params})
