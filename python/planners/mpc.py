"""The generated controller as a planner of the evaluation (registered as "mpc" and "mpc_paper").

A thin adapter with no navigation logic of its own: per control step it hands the C controller
(``humanmpc.load(DIR).controller()``, c_runtime/controller.c) what a robot's stack would hand it, and
returns the controller's decision as it is. So the evaluation measures the C that firmware and robot
nodes embed. What it hands over:

- the path: the global planner's (:class:`~humanmpc.planners.global_path.GlobalPlanner`, A* on the
  static map replanned at 1 Hz, the role nav2's planner server plays; the DWB baseline gets the same
  path), or with ``global_path=False`` only the goal pose;
- the people as the episode's tracks ``[x, y, vx, vy]`` with their ids (and covariances, if given):
  positions and the episode tracker's velocities; the controller predicts their paths, once, in C;
- the obstacles as points: the static obstacles' boundary within sensor range (a scan's returns,
  :class:`~humanmpc.sim.sensors.ObstacleSensor`);
- the odometry and the time.

"mpc" runs the controller with the spec's parameters (the defaults that won the evaluation);
"mpc_paper" with the paper's (:func:`paper_params`: its weights, Gauss-Newton, the final goal, no speed
limit, no recovery) and only the goal pose.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..bindings import load
from ..codegen.params import PARAMS
from ..controller import Controller
from ..results import ControllerResult
from ..sim.sensors import ObstacleSensor
from ..solver import Solver
from .global_path import GlobalPlanner, GridConfig
from .interface import Observation, PlanResult
from .solver_cache import DEFAULT_SOLVER_DIR as DEFAULT_SOLVER_DIR  # moved to solver_cache, re-exported here
from .solver_cache import ensure_solver as ensure_solver


def paper_params() -> dict[str, Any]:
    """The runtime parameters whose paper value differs from the default, at the paper's values."""
    return {p.name: p.spec_value(p.paper) for p in PARAMS if p.paper is not None}


class MPCPlanner:
    """The C controller behind the evaluation's planner interface."""

    name = "mpc"

    def __init__(self, controller: Controller | Solver | None = None, *, params: Mapping[str, Any] | None = None,
                 global_path: bool = True, grid: GridConfig | None = None, replan_period: float = 1.0,
                 name: str | None = None) -> None:
        """``controller``: a controller, or a loaded solver package to make one from (kept as ``solver``, so
        the tools can name the package that runs), or None for the process's chosen solver (solver_dir)."""
        if controller is None:
            controller = load(ensure_solver(), build_if_needed=False)
        self.solver: Solver | None = controller if isinstance(controller, Solver) else None
        self.controller = controller.controller() if isinstance(controller, Solver) else controller
        if params:
            self.controller.set_params(**dict(params))
        if name is not None:
            self.name = name
        self.global_path = global_path
        self._global = GlobalPlanner(grid, replan_period)
        self._sensor: ObstacleSensor | None = None
        self._omega = 0.0
        self.recoveries = 0  # recovery SQPs in this episode (loops and stalls)
        self.last: ControllerResult | None = None  # the controller's last result, all of it

    @staticmethod
    def paper(controller: Controller | Solver | None = None, name: str = "mpc_paper") -> MPCPlanner:
        """The paper's configuration: its parameters, the goal pose alone."""
        return MPCPlanner(controller, params=paper_params(), global_path=False, name=name)

    def reset(self) -> None:
        self.controller.reset()
        self._global.reset()
        self._sensor = None
        self._omega = 0.0
        self.recoveries = 0
        self.last = None

    def _path(self, obs: Observation) -> np.ndarray | None:
        if not self.global_path:
            return None
        self._global.update(obs.time, obs.world, obs.x[:2], obs.goal[:2], obs.robot.radius, None,
                            obs.robot.human_radius)
        path = self._global.path
        assert path is not None
        cap = self.controller.max_path_points
        if len(path) > cap:  # transport, not navigation: every k-th waypoint and the goal
            keep = np.unique(np.append(np.linspace(0, len(path) - 1, cap).round().astype(int), len(path) - 1))
            path = path[keep]
        return path

    def plan(self, obs: Observation) -> PlanResult:
        ctl = self.controller
        if abs(obs.dt - ctl.dims.dt) > 1e-9:
            raise ValueError(f"the episode's control period is {obs.dt} s; the controller's interval is "
                             f"{ctl.dims.dt} s (horizon.T / horizon.N of its spec)")
        if abs(float(obs.goal[3]) - ctl.params["v_ref"]) > 1e-12:  # the episode's cruising speed, DWB's cap too
            ctl.set_params(v_ref=float(obs.goal[3]), speed_limit=float(obs.goal[3]))
        if self._sensor is None or self._sensor.world is not obs.world:
            self._sensor = ObstacleSensor(obs.world, max_points=ctl.max_obstacle_points)
        # every person as a track, as the tracker gave it (the C predicts); more than the controller holds:
        # the C keeps the nearest
        r = ctl.step(obs.time, pose=obs.x[:3], v=float(obs.x[3]), omega=self._omega, path=self._path(obs),
                     goal=obs.goal[:3], people=obs.tracks, ids=obs.ids, covariances=obs.human_covariances,
                     obstacles=self._sensor.points(obs.x[:2]))
        self.last = r
        self._omega = float(r.command[1])
        self.recoveries += int(r.recovered)
        reason = r.reason if r.stop else ("stalled" if r.stalled else None)
        return PlanResult(
            u=r.u, command=r.command, path=r.plan, controls=r.controls, stop=r.stop, reason=reason,
            status=r.outcome_name, solve_time_ms=r.time_ms,
            timings={"solver_ms": r.time_solver_ms, "recovery_ms": r.time_recovery_ms,
                     "qp_iterations": float(r.qp_iterations)},
        )
