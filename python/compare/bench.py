"""Timing benchmark of the real-time iteration in random crowds (humanmpc-gen bench).

For each crowd size k a solver with N_h = k is generated and built, then driven in a seeded closed
loop: the robot (the unicycle, integrated finely) crosses an area with k humans walking at constant
velocity (re-entering on the far side when they leave it), constant-velocity predictions, and one
static obstacle near the path; one RTI step per control period. Reported per k: the step time as
the C code measures it and as Python sees it (binding included), the same over the steps whose QP
was solved (the steps that compare across runtimes: how many steps are cheap protective stops
depends on the chaotic closed loop), the preparation/feedback split, QP iterations and statuses, and
the closest robot-human distance.
"""

from __future__ import annotations

import json
import os
import platform
import statistics
import sys
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..bindings import load
from ..codegen.build import build, compiler_and_flags
from ..codegen.generate import generate
from ..codegen.spec import Spec, resolve_spec
from ..sim.unicycle import euler
from ..solver import Solver
from ..status import QP_STATUS_NAMES, STOP_REASONS

AREA_X = (-1.0, 13.0)
AREA_Y = (-5.0, 5.0)
OBSTACLE_CENTRE = np.array([6.0, 0.9])
OBSTACLE_RADIUS = 0.3


@dataclass(frozen=True)
class TimingStats:
    mean: float
    median: float
    min: float
    max: float
    p99: float

    @staticmethod
    def of(samples: Sequence[float]) -> TimingStats:
        a = np.asarray(samples, dtype=float)
        return TimingStats(mean=float(a.mean()), median=float(np.median(a)), min=float(a.min()),
                           max=float(a.max()), p99=float(np.percentile(a, 99)))


@dataclass(frozen=True)
class BenchResult:
    humans: int
    steps: int
    seeds: int
    c_total_ms: TimingStats
    python_ms: TimingStats
    c_solved_ms: TimingStats | None  # over the steps whose QP was solved (None: there were none)
    python_solved_ms: TimingStats | None
    prepare_share: float  # of the C total
    qp_iterations_mean: float
    qp_iterations_max: int
    qp_status: dict[str, int]
    solved_fraction: float  # of the steps where a QP ran
    stops: dict[str, int]
    min_human_distance: float


class CrowdScene:
    """k humans at constant velocity in a box; a human leaving it re-enters on the opposite side."""

    def __init__(self, k: int, rng: np.random.Generator, robot_xy: np.ndarray) -> None:
        self.rng = rng
        pos: list[np.ndarray] = []
        while len(pos) < k:
            p = np.array([rng.uniform(1.0, 12.0), rng.uniform(*AREA_Y)])
            if np.linalg.norm(p - robot_xy) > 2.0:
                pos.append(p)
        self.pos = np.array(pos).reshape(k, 2)
        speed = rng.uniform(0.3, 1.2, k)
        heading = rng.uniform(-np.pi, np.pi, k)
        self.vel = np.column_stack([speed * np.cos(heading), speed * np.sin(heading)])

    def predict(self, N: int, dt: float) -> np.ndarray:
        return np.stack([self.pos + self.vel * dt * n for n in range(N + 1)])

    def advance(self, dt: float) -> None:
        self.pos = self.pos + self.vel * dt
        width = AREA_X[1] - AREA_X[0]
        height = AREA_Y[1] - AREA_Y[0]
        self.pos[:, 0] = (self.pos[:, 0] - AREA_X[0]) % width + AREA_X[0]
        self.pos[:, 1] = (self.pos[:, 1] - AREA_Y[0]) % height + AREA_Y[0]


def nearest_obstacle_point(p: np.ndarray) -> np.ndarray:
    d = p - OBSTACLE_CENTRE
    n = float(np.linalg.norm(d))
    return OBSTACLE_CENTRE + (d / n if n > 1e-9 else np.array([1.0, 0.0])) * OBSTACLE_RADIUS


def run_closed_loop(solver: Solver, k: int, seed: int, steps: int,
                    record: Callable[[dict[str, Any]], None] | None = None) -> dict[str, list[float]]:
    """One seeded closed loop; returns per-step samples. record(inputs) sees every step's inputs."""
    rng = np.random.default_rng(seed)
    dims = solver.dims
    x = np.array([0.0, 0.0, 0.0, 0.0])
    goals = [np.array([12.0, 0.0, 0.0, 0.8]), np.array([0.0, 0.0, np.pi, 0.8])]
    goal_index = 0
    scene = CrowdScene(k, rng, x[:2])
    solver.reset()
    out: dict[str, list[float]] = {key: [] for key in
                                   ("c_ms", "py_ms", "prep_ms", "qp_iter", "qp_status", "dist", "reason")}
    for _ in range(steps):
        goal = goals[goal_index].copy()
        dist_goal = float(np.hypot(*(goal[:2] - x[:2])))
        if dist_goal < 0.3:
            goal_index = 1 - goal_index
            goal = goals[goal_index].copy()
            dist_goal = float(np.hypot(*(goal[:2] - x[:2])))
        goal[3] = min(goal[3], 0.5 * dist_goal)
        pred = scene.predict(dims.N, dims.dt)
        obstacle = nearest_obstacle_point(x[:2])
        if record is not None:
            record({"x0": x.copy(), "goal": goal, "humans_now": scene.pos.copy(), "humans_pred": pred,
                    "obstacle": obstacle})
        t0 = time.perf_counter_ns()
        r = solver.step(x, goal, scene.pos, pred, obstacle)
        t1 = time.perf_counter_ns()
        out["c_ms"].append(r.time_total_ms)
        out["py_ms"].append((t1 - t0) * 1e-6)
        out["prep_ms"].append(r.time_prepare_ms)
        out["qp_iter"].append(r.qp_iterations)
        out["qp_status"].append(r.qp_status)
        out["dist"].append(float(np.min(np.linalg.norm(scene.pos - x[:2], axis=1))) if k else np.inf)
        out["reason"].append(r.stop_reason)
        u = r.u0 if np.all(np.isfinite(r.u0)) else np.array([-1.0, 0.0])
        x = euler(x, u, dims.dt)
        x[3] = min(max(x[3], 0.0), 1.0)
        scene.advance(dims.dt)
    return out


def bench_solver(solver: Solver, k: int, seeds: int, steps: int) -> BenchResult:
    samples: dict[str, list[float]] = {}
    for seed in range(seeds):
        for key, vals in run_closed_loop(solver, k, seed, steps).items():
            samples.setdefault(key, []).extend(vals)
    return summarize(k, seeds, samples)


def summarize(k: int, seeds: int, samples: dict[str, list[float]]) -> BenchResult:
    """The statistics of the per-step samples of run_closed_loop, pooled over the seeds."""
    solved = [i for i, s in enumerate(samples["qp_status"]) if QP_STATUS_NAMES.get(int(s)) == "solved"]

    def over_solved(key: str) -> TimingStats | None:
        return TimingStats.of([samples[key][i] for i in solved]) if solved else None

    statuses = Counter(QP_STATUS_NAMES.get(int(s), str(s)) for s in samples["qp_status"])
    ran = len(samples["qp_status"]) - statuses.get("not_run", 0)
    stops = Counter(str(STOP_REASONS[int(r)]) for r in samples["reason"] if int(r))
    c_total = sum(samples["c_ms"])
    return BenchResult(
        humans=k, steps=len(samples["c_ms"]), seeds=seeds,
        c_total_ms=TimingStats.of(samples["c_ms"]), python_ms=TimingStats.of(samples["py_ms"]),
        c_solved_ms=over_solved("c_ms"), python_solved_ms=over_solved("py_ms"),
        prepare_share=sum(samples["prep_ms"]) / c_total if c_total > 0 else 0.0,
        qp_iterations_mean=statistics.fmean(samples["qp_iter"]), qp_iterations_max=int(max(samples["qp_iter"])),
        qp_status=dict(statuses), solved_fraction=statuses.get("solved", 0) / max(ran, 1), stops=dict(stops),
        min_human_distance=float(min(samples["dist"])),
    )


def pin_to_one_core() -> str:
    """Pin this process to the last CPU it may use (less interference from the shell's)."""
    try:
        cpus = sorted(os.sched_getaffinity(0))
        os.sched_setaffinity(0, {cpus[-1]})
        return f"pinned to CPU {cpus[-1]} of {len(cpus)}"
    except (AttributeError, OSError) as err:
        return f"not pinned ({err})"


def cpu_name() -> str | None:
    """The CPU's model name from /proc/cpuinfo (None where there is none)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def machine_description() -> str:
    cpu = cpu_name() or platform.processor() or platform.machine()
    return f"{cpu}, {os.cpu_count()} CPUs, Python {platform.python_version()}, {platform.system()}"


def markdown_table(results: Sequence[BenchResult]) -> str:
    rows = [
        "| N_h [people] | steps [count] | C step mean / median / min / max / p99 [ms] "
        "| Python step mean / p99 / max [ms] | solved steps: C / Python mean [ms] | prep. share [% of step] "
        "| QP iter mean / max [count] "
        "| QP status [steps] | stops [steps] | min dist [m] |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        c, p = r.c_total_ms, r.python_ms
        solved = (f"{r.c_solved_ms.mean:.3f} / {r.python_solved_ms.mean:.3f}"
                  if r.c_solved_ms is not None and r.python_solved_ms is not None else "none")
        status = ", ".join(f"{k}: {v}" for k, v in sorted(r.qp_status.items()))
        stops = ", ".join(f"{k}: {v}" for k, v in sorted(r.stops.items())) or "none"
        rows.append(
            f"| {r.humans} | {r.steps} | {c.mean:.3f} / {c.median:.3f} / {c.min:.3f} / {c.max:.3f} / {c.p99:.3f} "
            f"| {p.mean:.3f} / {p.p99:.3f} / {p.max:.3f} | {solved} | {100 * r.prepare_share:.0f}% "
            f"| {r.qp_iterations_mean:.1f} / {r.qp_iterations_max} | {status} | {stops} | {r.min_human_distance:.2f} |"
        )
    return "\n".join(rows) + "\n"


def bench_spec(base: Spec, k: int) -> Spec:
    data = base.to_dict()
    data["name"] = f"bench_h{k}"
    data["humans"]["max"] = k
    # the controller takes at least the solver's N_h tracks (the spec's rule): room for a crowd of k
    data["controller"]["max_tracks"] = max(int(data["controller"]["max_tracks"]), k)
    return resolve_spec(data)


def run_bench(base: Spec, humans: Sequence[int], *, seeds: int = 3, steps: int = 300,
              out_dir: Path = Path("out/bench"), log: Callable[[str], None] | None = None) -> list[BenchResult]:
    say = log or (lambda m: print(m, file=sys.stderr))
    say(f"[bench] {pin_to_one_core()}; {machine_description()}")
    results = []
    for k in humans:
        solver_dir = out_dir / "solvers" / f"bench_h{k}"
        generate(bench_spec(base, k), solver_dir, force=True, log=say)
        build(solver_dir, log=say)
        solver = load(solver_dir)
        say(f"[bench] N_h = {k}: {seeds} seeds x {steps} RTI steps ...")
        res = bench_solver(solver, k, seeds, steps)
        solved_mean = f"{res.python_solved_ms.mean:.3f} ms" if res.python_solved_ms is not None else "none"
        say(f"[bench] N_h = {k}: mean {res.python_ms.mean:.3f} ms (Python), {res.c_total_ms.mean:.3f} ms (C), "
            f"p99 {res.python_ms.p99:.3f} ms, solved steps {solved_mean} (Python), "
            f"QP solved {100 * res.solved_fraction:.1f}%")
        results.append(res)
    out_dir.mkdir(parents=True, exist_ok=True)
    compiler, cflags = compiler_and_flags()
    payload = {"machine": machine_description(), "compiler": f"{compiler} {cflags}", "spec_base": base.to_dict(),
               "results": [asdict(r) for r in results]}
    (out_dir / "bench.json").write_text(json.dumps(payload, indent=2) + "\n")
    (out_dir / "bench.md").write_text(markdown_table(results) + f"\nMachine: {payload['machine']}; compiled with "
                                      f"`{payload['compiler']}`.\n")
    return results
