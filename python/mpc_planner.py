"""The generated MPC as a planner of the evaluation (registered as "mpc").

Per control step it hands the solver what the robot observes: its state, the goal, the humans now
and their constant-velocity predictions, and the nearest obstacle point. Two things a local
planner does around the OCP, as the paper's move_base/nav2 plugin does:

- the goal checker: v_ref tapers near the goal (v_ref <= 0.5 m/s per metre left), so that the
  robot stops there instead of circling it at cruising speed (the OCP itself tracks v_ref);
- more humans than the solver's N_h: the N_h closest to the robot are passed, which is what
  matters for the hard distance rows and, with f decaying in d, for the cost.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from humanmpc.codegen.build import build, is_stale
from humanmpc.codegen.generate import MANIFEST, generate
from humanmpc.codegen.resources import PROJECT_ROOT
from humanmpc.codegen.spec import Spec

from .bindings import load
from .planner import Observation, PlanResult
from .solver import Solver

DEFAULT_SOLVER_DIR = PROJECT_ROOT / "generated" / "paper"
GOAL_TAPER = 0.5  # v_ref <= GOAL_TAPER * distance to the goal


def ensure_solver(solver_dir: Path = DEFAULT_SOLVER_DIR, spec: Spec | None = None) -> Path:
    """The solver of ``spec`` (default: the paper's) in solver_dir, generated and built if needed."""
    spec = spec or Spec()
    manifest = solver_dir / MANIFEST
    current = manifest.is_file() and f'"spec_hash": "{spec.digest()}"' in manifest.read_text()
    if not current:
        generate(spec, solver_dir, force=manifest.is_file(), log=lambda m: print(m, file=sys.stderr))
    if is_stale(solver_dir):
        build(solver_dir, log=lambda m: print(m, file=sys.stderr))
    return solver_dir


class MPCPlanner:
    name = "mpc"

    def __init__(self, solver: Solver | None = None) -> None:
        self.solver = solver or load(ensure_solver())

    def reset(self) -> None:
        self.solver.reset()

    def plan(self, obs: Observation) -> PlanResult:
        s = self.solver
        if obs.humans_pred.shape[0] != s.dims.N + 1 or abs(obs.dt - s.dims.dt) > 1e-9:
            raise ValueError(f"the episode predicts {obs.humans_pred.shape[0] - 1} intervals of {obs.dt} s; "
                             f"the solver needs {s.dims.N} of {s.dims.dt} s (EpisodeConfig(horizon, dt))")
        goal = np.array(obs.goal, dtype=float)
        goal[3] = min(goal[3], GOAL_TAPER * float(np.hypot(*(goal[:2] - obs.x[:2]))))
        now, pred = obs.humans_now, obs.humans_pred
        if now.shape[0] > s.dims.nh:
            closest = np.argsort(np.linalg.norm(now - obs.x[:2], axis=1))[: s.dims.nh]
            now, pred = now[closest], pred[:, closest]
        r = s.step(obs.x, goal, now, pred, obs.obstacle)
        return PlanResult(
            u=r.u0, command=r.command, path=r.x, controls=r.u, stop=r.stop, reason=r.reason,
            status=r.status_name, solve_time_ms=r.time_total_ms,
            timings={"prepare_ms": r.time_prepare_ms, "feedback_ms": r.time_feedback_ms,
                     "qp_iterations": float(r.qp_iterations)},
        )
