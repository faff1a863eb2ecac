"""What a worker does with an :class:`~humanmpc.eval.campaign.EpisodeTask`: one episode, its metrics row
and (if asked) its per-step trace. Runs in any process that has humanmpc: a Dask worker on this machine
or another one, or the submitting process itself.

The solver: before a task's planner is made, the process's solver choice
(:func:`humanmpc.planners.solver_cache.select_solver`) is set to the task's :class:`SolverRef`: a spec's solver
is generated and built into this worker's cache (``generated/.cache/`` in its working folder) by the first
planner that needs it and reused by every later task; the cache builds in a staging folder renamed into
place under a file lock, so workers sharing a folder build one spec once and never see a half-built
solver. A solver folder is used as it is. Either way the spec digest must be the task's: a worker whose
folder or humanmpc holds another solver fails the task instead of computing another campaign's rows.
"""

from __future__ import annotations

import os
import socket
import threading
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from ..codegen.resources import generator_digest
from ..codegen.spec import Spec
from ..planners.interface import Planner
from ..planners.registry import make_planner
from ..planners.solver_cache import SolverChoice, held_spec_hash, select_solver, selected_solver
from ..sim.scenarios import make_scenario
from .campaign import EpisodeTask, SolverRef
from .episode import run_episode
from .metrics import compute_metrics
from .traces import log_to_trace

if TYPE_CHECKING:
    import pyarrow as pa

Row = dict[str, float | int | bool | str]

# Columns a rerun of the same episode does not reproduce: measured times and where it ran.
MEASURED_COLUMNS = ("planner_ms_mean", "planner_ms_p99", "planner_ms_max", "wall_s", "worker")

_lock = threading.Lock()


@dataclass(frozen=True)
class EpisodeResult:
    """A finished task: its metrics row and its trace (None unless the task asked for it)."""

    key: str
    row: Row
    trace: pa.Table | None


def use_solver(ref: SolverRef) -> None:
    """Make ``ref`` the solver of this process's MPC planners (module docstring); ``ValueError`` when its
    folder or spec is not the digest's."""
    folder = Path(ref.solver_dir) if ref.solver_dir is not None else None
    with _lock:
        if selected_solver() == SolverChoice(ref.spec, folder, ref.source):
            return
        if folder is not None:
            held = held_spec_hash(folder)
            if held != ref.digest:
                raise ValueError(f"worker {socket.gethostname()}: the solver folder {folder} holds spec sha256 "
                                 f"{held or 'none'}, the campaign's is {ref.digest}: give the workers the same "
                                 "folder (a shared file system) or let them build the spec (--spec)")
        elif (ref.spec or Spec()).digest() != ref.digest:
            raise ValueError(f"the task's spec has sha256 {(ref.spec or Spec()).digest()}, not the campaign's "
                             f"{ref.digest}")
        select_solver(ref.spec, folder, ref.source)


def make_task_planner(task: EpisodeTask) -> Planner:
    """The task's planner, with its runtime parameters set (``ValueError`` / ``KeyError`` naming a bad one)."""
    use_solver(task.solver)
    planner = task.factory() if task.factory is not None else make_planner(task.planner.name)
    if task.planner.params:
        controller = getattr(planner, "controller", None)
        if controller is None or not hasattr(controller, "set_params"):
            raise ValueError(f"planner {task.planner.name} has no runtime parameters; --grid applies to the MPC "
                             "planners")
        controller.set_params(**{k: list(v) if isinstance(v, tuple) else v for k, v in task.planner.params})
    return planner


def run_task(task: EpisodeTask) -> EpisodeResult:
    """Run one episode: its metrics row (task columns, then :class:`~humanmpc.eval.metrics.EpisodeMetrics`,
    then the wall time and the worker) and its trace if the task keeps one."""
    t0 = time.perf_counter()
    planner = make_task_planner(task)
    scenario = make_scenario(task.scenario, task.seed)
    log = run_episode(scenario, planner, replace(task.episode_config, keep_plans=False))
    log.planner = task.planner.label
    row: Row = {
        "key": task.key, "scenario": task.scenario, "crowd": task.crowd, "people": int(log.humans.shape[1]),
        "planner": task.planner.label, "planner_name": task.planner.name, "params": task.planner.params_json,
        "seed": task.seed, "spec_digest": task.solver.digest, "generator_digest": generator_digest()[:12],
        "ended_by": log.ended_by,
    }
    row.update(compute_metrics(log).as_row())
    row["wall_s"] = time.perf_counter() - t0
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return EpisodeResult(task.key, row, log_to_trace(task.key, log) if task.traces else None)

