"""Timing benchmark of the whole controller step (humanmpc-gen bench --controller).

The controller of one solver package (the built-in default spec's unless a spec is given) is driven in
seeded closed loops through the crowd scene of the RTI bench (:mod:`humanmpc.compare.bench`): M tracked
people walking at constant velocity (more than the solver's N_h, so the selection has work to do), the
static obstacle as points on its boundary (a scan's returns), the goal alternating between the two ends
of the area. Every period is one ``controller_step``: predictions of every track, the N_h selection,
the obstacle point, the goal, the OCP's real-time iteration, the monitors and, when the controller
detects a loop or a stall, its recovery SQP. Reported, from the C's own clock: the step's time, the
solver's part (the RTI), the recovery's and the rest (the controller's own work), over every step and
pooled over the seeds.
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..bindings import load
from ..codegen.build import build, compiler_and_flags
from ..codegen.generate import generate
from ..codegen.spec import Spec, resolve_spec
from ..controller import Controller
from ..sim.unicycle import euler
from ..status import OUTCOME_NAMES
from .bench import (
    OBSTACLE_CENTRE,
    OBSTACLE_RADIUS,
    CrowdScene,
    TimingStats,
    machine_description,
    pin_to_one_core,
)

OBSTACLE_POINTS = 64  # points on the obstacle's boundary, 3 cm apart


@dataclass(frozen=True)
class ControllerBenchResult:
    tracks: int
    nh: int
    steps: int
    seeds: int
    step_ms: TimingStats  # the whole controller step
    solver_ms: TimingStats  # its real-time iteration
    own_ms: TimingStats  # the step less the RTI and any recovery: predictions, selection, goal, monitors
    recovery_steps: int
    recovery_ms_max: float
    own_share: float  # of the total time over all steps
    outcomes: dict[str, int]
    min_human_distance: float


def obstacle_points() -> np.ndarray:
    a = np.linspace(0.0, 2 * np.pi, OBSTACLE_POINTS, endpoint=False)
    return OBSTACLE_CENTRE + OBSTACLE_RADIUS * np.column_stack([np.cos(a), np.sin(a)])


def run_controller_loop(ctl: Controller, tracks: int, seed: int, steps: int) -> dict[str, list[float]]:
    """One seeded closed loop; per-step samples of the C's timings, the outcome and the nearest person."""
    rng = np.random.default_rng(seed)
    dt = ctl.dims.dt
    x = np.array([0.0, 0.0, 0.0, 0.0])
    goals = [(12.0, 0.0, 0.0), (0.0, 0.0, np.pi)]
    which = 0
    scene = CrowdScene(tracks, rng, x[:2])
    points = obstacle_points()
    ctl.reset()
    out: dict[str, list[float]] = {k: [] for k in ("step", "solver", "recovery", "outcome", "dist")}
    omega = 0.0
    for k in range(steps):
        if np.hypot(goals[which][0] - x[0], goals[which][1] - x[1]) < 0.35:
            which = 1 - which
        people = np.hstack([scene.pos, scene.vel])
        r = ctl.step(k * dt, pose=x[:3], v=float(x[3]), omega=omega, goal=goals[which], people=people,
                     obstacles=points)
        out["step"].append(r.time_ms)
        out["solver"].append(r.time_solver_ms)
        out["recovery"].append(r.time_recovery_ms)
        out["outcome"].append(r.outcome)
        out["dist"].append(float(np.min(np.linalg.norm(scene.pos - x[:2], axis=1))) if tracks else np.inf)
        omega = float(r.command[1])
        x = euler(x, r.u, dt)
        x[3] = min(max(x[3], 0.0), 1.0)
        scene.advance(dt)
    return out


def bench_controller(ctl: Controller, tracks: int, seeds: int, steps: int) -> ControllerBenchResult:
    s: dict[str, list[float]] = {}
    for seed in range(seeds):
        for key, vals in run_controller_loop(ctl, tracks, seed, steps).items():
            s.setdefault(key, []).extend(vals)
    step, solver, recovery = (np.asarray(s[k]) for k in ("step", "solver", "recovery"))
    own = step - solver - recovery
    outcomes = Counter(OUTCOME_NAMES.get(int(o), str(o)) for o in s["outcome"])
    return ControllerBenchResult(
        tracks=tracks, nh=ctl.dims.nh, steps=step.size, seeds=seeds, step_ms=TimingStats.of(s["step"]),
        solver_ms=TimingStats.of(s["solver"]), own_ms=TimingStats.of(own.tolist()),
        recovery_steps=int(np.count_nonzero(recovery > 0)), recovery_ms_max=float(recovery.max()),
        own_share=float(own.sum() / step.sum()) if step.sum() > 0 else 0.0, outcomes=dict(outcomes),
        min_human_distance=float(min(s["dist"])),
    )


def controller_markdown(r: ControllerBenchResult) -> str:
    def row(name: str, t: TimingStats) -> str:
        return f"| {name} | {t.mean:.4f} | {t.median:.4f} | {t.min:.4f} | {t.max:.4f} | {t.p99:.4f} |"

    outcomes = ", ".join(f"{k}: {v}" for k, v in sorted(r.outcomes.items()))
    return "\n".join([
        f"Controller step at {r.tracks} tracked people (N_h = {r.nh}), {r.seeds} seeds x {r.steps // r.seeds} steps:",
        "",
        "| part | mean [ms] | median [ms] | min [ms] | max [ms] | p99 [ms] |",
        "|---|---|---|---|---|---|",
        row("whole step", r.step_ms),
        row("real-time iteration (solver)", r.solver_ms),
        row("the rest (predictions, selection, goal, monitors)", r.own_ms),
        "",
        f"The rest is {100 * r.own_share:.1f} % of the total time; recovery SQPs on {r.recovery_steps} steps "
        f"(at most {r.recovery_ms_max:.3f} ms); outcomes: {outcomes}; nearest person {r.min_human_distance:.2f} m.",
        "",
    ])


def run_controller_bench(spec: Spec | None, tracks: int, *, seeds: int = 3, steps: int = 300,
                         out_dir: Path = Path("out/bench"),
                         log: Callable[[str], None] | None = None) -> ControllerBenchResult:
    say = log or (lambda m: print(m, file=sys.stderr))
    say(f"[bench] {pin_to_one_core()}; {machine_description()}")
    base = spec or Spec()
    data = base.to_dict()
    data["name"] = "benchctl"
    data.setdefault("controller", {})["max_tracks"] = max(tracks, base.humans.max)
    solver_dir = out_dir / "solvers" / "benchctl"
    generate(resolve_spec(data), solver_dir, force=True, log=say)
    build(solver_dir, log=say)
    ctl = load(solver_dir).controller()
    say(f"[bench] controller at {tracks} tracks: {seeds} seeds x {steps} steps ...")
    result = bench_controller(ctl, tracks, seeds, steps)
    out_dir.mkdir(parents=True, exist_ok=True)
    compiler, cflags = compiler_and_flags()
    payload = {"machine": machine_description(), "compiler": f"{compiler} {cflags}", "spec": data,
               "result": asdict(result)}
    (out_dir / "controller.json").write_text(json.dumps(payload, indent=2) + "\n")
    (out_dir / "controller.md").write_text(controller_markdown(result) + f"\nMachine: {payload['machine']}; "
                                           f"compiled with `{payload['compiler']}`.\n")
    return result
