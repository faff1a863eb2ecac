"""Side by side with the references: humanmpc's SQP-RTI, acados SQP-RTI + HPIPM, Ipopt in C.

Every solver gets the same replay (the inputs of every step of a closed loop, see
:mod:`humanmpc.compare.replay`), step by step, each keeping its own warm start:

=================  ====================================================================  ==========================
solver             what runs                                                             step time
=================  ====================================================================  ==========================
humanmpc           ``humanmpc.load(DIR).step`` (one RTI step, C through cffi)            its own timer (total ms)
acados default     acados_template SQP_RTI, PARTIAL_CONDENSING_HPIPM, HPIPM defaults     acados' ``time_tot``
acados fastest     the same with hpipm_mode SPEED_ABS, partial condensing to 5 stages   acados' ``time_tot``
Ipopt cold         ``<name>_ipopt`` (Debian Ipopt, exact Hessian) from x_n = x0, u = 0    ``IpoptSolve`` wall time
Ipopt warm         the same from the previous solution shifted by one interval           ``IpoptSolve`` wall time
=================  ====================================================================  ==========================

Relative cumulative sub-optimality (RCSO), as in the acados paper (Verschueren et al. 2021)::

    RCSO = sum_t (J_t(solver) - J*_t) / sum_t J*_t

over the steps t where the solver succeeded (status 0; its failures are reported apart: a failed
RTI step returns a plan of no meaning, which would swamp the sum) and the reference J*_t exists,
where

- J_t(solver) is the NLP objective of the plan the solver returned at step t, evaluated by ONE
  function for every solver (``ReferenceNlp.plan_cost``): the solver's planned controls u_0..u_{N-1}
  are simulated from the measured x0_t with the model's RK4 (so every plan is dynamically
  consistent, whatever the solver's own states), and each obstacle slack takes its smallest
  feasible value max(0, d_s - d). Hard-row violations of the plan are not in J; they are reported
  separately (largest violation of d >= d_h by a plan the solver called solved, in metres,
  over the steps the reference found feasible);
- J*_t is the lowest cost (the same function) of Ipopt's plans at step t, over its cold and warm
  runs that succeeded (the problem is not convex: the two can end in different local optima).
  Steps where neither succeeded are left out, as are steps where a solver returned non-finite
  controls; ``rcso_steps`` says how many steps remain.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..bindings import load
from ..codegen.cli import non_negative_int, output_dir
from ..codegen.manifest import held_spec_hash
from ..codegen.reference_nlp import ReferenceNlp
from ..codegen.spec import Spec, load_spec, resolve_spec
from .bench import cpu_name
from .peers.acados_client import (
    ACADOS_PACKAGE,
    DEFAULT_ACADOS_VENV,
    AcadosUnavailableError,
    ensure_acados_venv,
    progress,
    run_acados,
)
from .peers.ipopt import IpoptRun, IpoptUnavailableError, build_ipopt_reference, ipopt_unavailable_reason
from .rcso import plan_costs, rcso, reference_costs
from .replay import Replay, ReplayRun, replay_solver, synthetic_replay

FloatArray = NDArray[np.float64]
Log = Callable[[str], None]

SOLVERS = ("humanmpc", "humanmpc exact+LS", "acados default", "acados fastest", "Ipopt cold", "Ipopt warm")
# The real-time iterations, whose RCSO is also reported over the steps all of them solved.
RTI_SOLVERS = ("humanmpc", "humanmpc exact+LS", "acados default", "acados fastest")
# humanmpc's second row: the same generated solver with the exact-Hessian RTI and the merit line search
# (runtime parameters), the configuration of the behaviour evaluation (docs/evaluation.md).
EXACT_LS_PARAMS = {"exact_hessian": True, "line_search": True}



# ----------------------------------------------------------------------------------------------
# The comparison
# ----------------------------------------------------------------------------------------------


@dataclass
class SolverStats:
    solver: str
    n_humans: int
    steps: int
    mean_ms: float = float("nan")
    median_ms: float = float("nan")
    min_ms: float = float("nan")
    max_ms: float = float("nan")
    p99_ms: float = float("nan")
    ratio_to_ours: float = float("nan")
    median_ratio_to_ours: float = float("nan")  # robust to the odd step a shared machine interrupts
    iterations_mean: float = float("nan")
    iterations_max: int = -1
    failures: int = 0
    rcso: float = float("nan")
    rcso_steps: int = 0
    rcso_common: float = float("nan")  # over the steps every RTI solver of this N_h solved
    rcso_common_steps: int = 0
    max_violation_m: float = float("nan")
    wall_mean_ms: float = float("nan")
    error: str | None = None
    times_ms: list[float] = field(default_factory=list)


def _time_stats(s: SolverStats, times: FloatArray) -> None:
    s.times_ms = [float(v) for v in times]
    if times.size:
        s.mean_ms, s.min_ms, s.max_ms = float(np.mean(times)), float(np.min(times)), float(np.max(times))
        s.median_ms = float(np.median(times))
        s.p99_ms = float(np.percentile(times, 99))


def _finish(s: SolverStats, nlp: ReferenceNlp, replay: Replay, u: FloatArray, ok: NDArray[np.bool_],
            optimal: FloatArray | None) -> FloatArray:
    """RCSO over the steps the solver solved (its failures are counted apart) and the largest
    violation of the human rows by the plans it called solved, over the steps where the
    reference found the problem feasible. Returns the plan costs of the solved steps (NaN
    elsewhere)."""
    costs, viol = plan_costs(nlp, replay, u)
    feasible = np.isfinite(optimal) if optimal is not None else np.ones(replay.steps, dtype=bool)
    v = viol[ok & feasible & np.isfinite(viol)]
    s.max_violation_m = float(np.max(v)) if v.size else float("nan")
    solved_costs = np.where(ok, costs, np.nan)
    if optimal is not None:
        s.rcso, s.rcso_steps = rcso(solved_costs, optimal)
    return solved_costs


def common_rcso(group: Sequence[SolverStats], costs: dict[str, FloatArray], optimal: FloatArray | None) -> None:
    """RCSO of every RTI solver of one N_h over the steps all of them solved: acados fails most
    steps of this problem, and an RCSO over its few solved steps would compare easy steps with all."""
    ran = [g for g in group if g.solver in RTI_SOLVERS and g.solver in costs and g.error is None]
    if optimal is None or len(ran) < 2:
        return
    common = np.ones(optimal.shape, dtype=bool)
    for g in ran:
        common &= np.isfinite(costs[g.solver])
    for g in ran:
        g.rcso_common, g.rcso_common_steps = rcso(np.where(common, costs[g.solver], np.nan), optimal)


def _load_spec(item: Spec | str | Path) -> Spec:
    return item if isinstance(item, Spec) else load_spec(item)


def machine_description() -> dict[str, str]:
    cpu = cpu_name() or platform.processor() or "unknown CPU"

    def version(cmd: list[str]) -> str:
        try:
            out = subprocess.run(cmd, capture_output=True, text=True, timeout=10, check=False)
            return (out.stdout or out.stderr).strip().splitlines()[0] if out.returncode == 0 else "n/a"
        except (OSError, subprocess.TimeoutExpired, IndexError):
            return "n/a"

    return {
        "cpu": cpu, "cores": str(os.cpu_count()), "os": f"{platform.system()} {platform.release()}",
        "python": platform.python_version(), "cc": version(["cc", "--version"]),
        "ipopt": version(["pkg-config", "--modversion", "ipopt"]), "acados": ACADOS_PACKAGE,
    }


def compare(specs: Sequence[Spec | str | Path], replays: Sequence[Replay | str | Path] | None, out_dir: str | Path,
            *, steps: int = 100, seed: int = 0, solver_dirs: Sequence[str | Path] | None = None,
            acados_venv: str | Path = DEFAULT_ACADOS_VENV, skip: Sequence[str] = (), command: str = "",
            log: Log | None = None) -> dict[str, Any]:
    """Run every solver on the replay of every spec (e.g. N_h = 5, 10, 20, 30) and write the report.

    ``replays[i]`` belongs to ``specs[i]``; None makes a synthetic replay per spec
    (``synthetic_replay(spec, N_h, steps, seed)``). ``solver_dirs[i]`` is a generated humanmpc
    solver of ``specs[i]``; None generates one under out_dir/solvers. Writes to ``out_dir``:
    ``results.json``, ``step_times.png`` and ``benchmarks.md`` (a section for docs/benchmarks.md).
    Solvers in ``skip`` are left out; a solver that cannot run here is reported with the reason.
    """
    say = progress(log)
    out = Path(out_dir).resolve()
    out.mkdir(parents=True, exist_ok=True)
    spec_list = [_load_spec(s) for s in specs]
    if replays is not None and len(replays) != len(spec_list):
        raise ValueError(f"{len(spec_list)} specs but {len(replays)} replays: give one replay per spec")
    if solver_dirs is not None and len(solver_dirs) != len(spec_list):
        raise ValueError(f"{len(spec_list)} specs but {len(solver_dirs)} solver folders")
    unknown = sorted(set(skip) - set(SOLVERS))
    if unknown:
        raise ValueError(f"unknown solver(s) to skip: {', '.join(unknown)}; solvers are {', '.join(SOLVERS)}")

    acados_python: Path | None = None
    acados_reason: str | None = None
    if not {"acados default", "acados fastest"} <= set(skip):
        try:
            acados_python = ensure_acados_venv(acados_venv, log=say)
        except AcadosUnavailableError as err:
            acados_reason = str(err)
            say(f"[compare] acados skipped: {acados_reason}")
    ipopt_reason = ipopt_unavailable_reason()

    rows: list[SolverStats] = []
    for i, spec in enumerate(spec_list):
        if replays is None:
            say(f"[compare] recording a synthetic replay: N_h={spec.humans.max}, {steps} steps, seed {seed}")
            replay = synthetic_replay(spec, spec.humans.max, steps, seed)
            replay.save(out / f"replay_{spec.name}_{spec.humans.max}.npz")
        else:
            r = replays[i]
            replay = r if isinstance(r, Replay) else Replay.load(r)
        if replay.spec_hash != spec.digest():
            raise ValueError(f"replay {i} was recorded for spec {replay.spec_hash[:12]}, not for spec {spec.name} "
                             f"({spec.digest()[:12]})")
        nh = int(spec.humans.max)
        nlp = ReferenceNlp(spec)
        T = replay.steps
        say(f"[compare] N_h={nh}: {T} steps")

        ipopt_runs: dict[str, IpoptRun] = {}
        if not {"Ipopt cold", "Ipopt warm"} <= set(skip) and ipopt_reason is None:
            try:
                ref = build_ipopt_reference(spec, out / "ipopt" / f"{spec.name}_{nh}")
                for label, warm in (("Ipopt cold", False), ("Ipopt warm", True)):
                    say(f"[compare]   {label}")
                    ipopt_runs[label] = ref.run(replay, warm=warm)
            except (IpoptUnavailableError, RuntimeError) as err:
                ipopt_reason = str(err)
        optimal = None
        if ipopt_runs:
            optimal = reference_costs([plan_costs(nlp, replay, r.u)[0] for r in ipopt_runs.values()],
                                      [r.success for r in ipopt_runs.values()])

        group: list[SolverStats] = []
        costs: dict[str, FloatArray] = {}
        # -- humanmpc, as generated and with the exact-Hessian line-search RTI ------------------
        for label, params in (("humanmpc", None), ("humanmpc exact+LS", EXACT_LS_PARAMS)):
            if label in skip:
                continue
            s = SolverStats(label, nh, T)
            try:
                run = _run_ours(spec, None if solver_dirs is None else solver_dirs[i], out, replay, say, params)
                _time_stats(s, run.time_ms)
                s.wall_mean_ms = float(np.mean(run.wall_ms))
                s.iterations_mean = float(np.mean(run.qp_iterations))
                s.iterations_max = int(np.max(run.qp_iterations))
                s.failures = run.failures
                costs[label] = _finish(s, nlp, replay, run.u, run.status == 0, optimal)
            except Exception as err:  # reported in the table; the other solvers still run
                s.error = f"{type(err).__name__}: {err}"
            group.append(s)
        # -- acados ------------------------------------------------------------------------
        for label, mode in (("acados default", "default"), ("acados fastest", "fastest")):
            if label in skip:
                continue
            s = SolverStats(label, nh, T)
            if acados_python is None:
                s.error = acados_reason
            else:
                try:
                    say(f"[compare]   {label}")
                    ar = run_acados(replay, mode, out / "acados", python=acados_python, log=say)
                    _time_stats(s, ar.time_tot_ms)
                    s.wall_mean_ms = float(np.mean(ar.wall_ms))
                    s.iterations_mean = float(np.mean(ar.qp_iterations))
                    s.iterations_max = int(np.max(ar.qp_iterations))
                    s.failures = ar.failures
                    costs[label] = _finish(s, nlp, replay, ar.u, ar.status == 0, optimal)
                except Exception as err:  # reported in the table
                    s.error = f"{type(err).__name__}: {err}"
            group.append(s)
        # -- Ipopt -------------------------------------------------------------------------
        for label in ("Ipopt cold", "Ipopt warm"):
            if label in skip:
                continue
            s = SolverStats(label, nh, T)
            if label not in ipopt_runs:
                s.error = ipopt_reason or "not run"
            else:
                ir = ipopt_runs[label]
                _time_stats(s, ir.solve_ms)
                s.wall_mean_ms = float(np.mean(ir.total_ms))
                s.iterations_mean = float(np.mean(ir.iterations))
                s.iterations_max = int(np.max(ir.iterations))
                s.failures = ir.failures
                _finish(s, nlp, replay, ir.u, ir.success, optimal)
            group.append(s)
        common_rcso(group, costs, optimal)
        ours = next((g for g in group if g.solver == "humanmpc" and g.error is None), None)
        for g in group:
            if ours is not None and g.error is None and ours.mean_ms > 0:
                g.ratio_to_ours = g.mean_ms / ours.mean_ms
                g.median_ratio_to_ours = g.median_ms / ours.median_ms
        rows += group

    report: dict[str, Any] = {
        "machine": machine_description(), "command": command, "date": time.strftime("%Y-%m-%d %H:%M:%S"),
        "rows": [asdict(r) for r in rows],
    }
    (out / "results.json").write_text(json.dumps(report, indent=1, default=float) + "\n")
    plot_step_times(rows, out / "step_times.png")
    (out / "benchmarks.md").write_text(markdown_section(rows, report["machine"], command))
    say(f"[compare] wrote {out / 'benchmarks.md'}, {out / 'results.json'}, {out / 'step_times.png'}")
    return report


def _run_ours(spec: Spec, solver_dir: str | Path | None, out: Path, replay: Replay, say: Log,
              params: dict[str, Any] | None = None) -> ReplayRun:
    """The replay through the generated solver (generated when no folder is given), with the
    replay's problem parameters and then ``params`` on top."""
    if solver_dir is None:
        solver_dir = out / "solvers" / f"{spec.name}_{spec.humans.max}"
        if held_spec_hash(solver_dir) != spec.digest() or params is None:
            from ..codegen.generate import generate

            solver_dir = generate(spec, solver_dir, force=True, log=lambda _m: None)
    solver = load(solver_dir)
    say(f"[compare]   humanmpc{'' if not params else ' with ' + str(params)} ({solver_dir})")
    solver.reset()
    solver.set_params(**replay.params)
    if params:
        solver.set_params(**params)
    return replay_solver(solver, replay, name="humanmpc", reset=False, apply_params=False)


# ----------------------------------------------------------------------------------------------
# Report: plot and Markdown
# ----------------------------------------------------------------------------------------------


def plot_step_times(rows: Sequence[SolverStats], path: str | Path) -> Path:
    """Mean step time against N_h per solver, with min..max bars and p99 marks (log scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.5))
    for k, name in enumerate(SOLVERS):
        mine = sorted((r for r in rows if r.solver == name and r.error is None and r.times_ms),
                      key=lambda r: r.n_humans)
        if not mine:
            continue
        nh = np.array([r.n_humans for r in mine], dtype=float) + (k - 2) * 0.25
        mean = np.array([r.mean_ms for r in mine])
        lo = mean - np.array([r.min_ms for r in mine])
        hi = np.array([r.max_ms for r in mine]) - mean
        ax.errorbar(nh, mean, yerr=[lo, hi], marker="o", capsize=3, label=name)
        ax.plot(nh, [r.p99_ms for r in mine], linestyle="none", marker="_", markersize=10, color="black")
    ax.set_yscale("log")
    ax.set_xlabel("number of humans N_h")
    ax.set_ylabel("step time [ms] (mean, min..max, p99 as -)")
    ax.set_title("Step time against the number of humans")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    p = Path(path)
    fig.savefig(p, dpi=120)
    plt.close(fig)
    return p


def _fmt(v: float, digits: int = 3) -> str:
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "–"
    return f"{v:.{digits}g}" if abs(v) < 1e-2 and v != 0 else f"{v:.{digits}f}" if abs(v) < 100 else f"{v:.0f}"


def markdown_section(rows: Sequence[SolverStats], machine: dict[str, str], command: str) -> str:
    lines = [
        "## Comparison with the references",
        "",
        "Same replay for every solver, step by step, each with its own warm start. Step time: humanmpc's own",
        "timer (prepare + feedback), acados' `time_tot`, Ipopt's `IpoptSolve` (clock_gettime). Iterations:",
        "QP (interior-point) iterations for humanmpc and acados, NLP iterations for Ipopt. Failures: status",
        "not 0 (humanmpc, acados: 4 = QP failure, 3 = minimum step) or Ipopt not solved. RCSO: relative",
        "cumulative sub-optimality against the best Ipopt optimum per step, over the steps the solver solved,",
        "each plan's controls simulated from the measured state and costed by one common function (see",
        "`humanmpc.compare`); RCSO common: the same over the steps that every real-time iteration of that",
        "N_h solved (acados fails most steps, and its RCSO alone covers only the steps it solved). Violation:",
        "the largest d_h - d to a human's current position of a plan the solver called solved, over the steps",
        "Ipopt found feasible (hard rows are not in the cost). `humanmpc exact+LS`: the same generated solver",
        "with the runtime parameters exact_hessian and line_search on (the behaviour evaluation's RTI).",
        "",
        "| N_h [people] | solver | mean [ms] | median [ms] | min [ms] | max [ms] | p99 [ms] | × ours (mean) [ratio] "
        "| × ours (median) [ratio] | iterations (mean/max) [count] | failures [steps] | RCSO [ratio] "
        "| RCSO common (steps) [ratio] | violation [m] |",
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        if r.error is not None:
            lines.append(f"| {r.n_humans} | {r.solver} | not run: {r.error.splitlines()[0][:120]} "
                         "| | | | | | | | | | | |")
            continue
        common = f"{_fmt(r.rcso_common, 3)} ({r.rcso_common_steps})" if r.rcso_common_steps else "–"
        lines.append(
            f"| {r.n_humans} | {r.solver} | {_fmt(r.mean_ms)} | {_fmt(r.median_ms)} | {_fmt(r.min_ms)} | "
            f"{_fmt(r.max_ms)} | {_fmt(r.p99_ms)} | {_fmt(r.ratio_to_ours, 2)} | {_fmt(r.median_ratio_to_ours, 2)} | "
            f"{_fmt(r.iterations_mean, 3)}/{r.iterations_max} | "
            f"{r.failures}/{r.steps} | {_fmt(r.rcso, 3)} | {common} | {_fmt(r.max_violation_m, 3)} |"
        )
    lines += [
        "",
        "![step time against the number of humans](step_times.png)",
        "",
        f"Command: `{command or 'humanmpc-gen bench --compare'}`",
        "",
        "Machine: " + ", ".join(f"{k}: {v}" for k, v in machine.items()),
        "",
    ]
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# Command line hook (humanmpc-gen bench --compare)
# ----------------------------------------------------------------------------------------------


def add_compare_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ``humanmpc-gen bench --compare``; run them with ``run_compare_from_args``."""
    g = parser.add_argument_group("comparison with acados and Ipopt (--compare)")
    g.add_argument("--compare", action="store_true", help="run humanmpc, acados (2 settings) and Ipopt (cold, warm) "
                   "on the same replays and write the comparison report")
    g.add_argument("--compare-specs", nargs="+", type=Path, metavar="SPEC",
                   help="spec files, one per N_h (default: the built-in spec with N_h = 5, 10, 20, 30)")
    g.add_argument("--compare-humans", nargs="+", type=int, default=[5, 10, 20, 30], metavar="N_H",
                   help="N_h of the built-in spec when no --compare-specs are given (default: 5 10 20 30)")
    g.add_argument("--compare-replays", nargs="+", type=Path, metavar="REPLAY.npz",
                   help="recorded replays, one per spec (default: synthetic random crowds)")
    g.add_argument("--compare-steps", type=int, default=100, help="steps of each synthetic replay (default 100)")
    g.add_argument("--compare-seed", type=non_negative_int, default=0, help="seed of the synthetic replays (default 0)")
    g.add_argument("--compare-out", type=output_dir, default=Path("out/compare"),
                   help="output folder (default out/compare)")
    g.add_argument("--compare-skip", nargs="+", default=[], choices=list(SOLVERS), metavar="SOLVER",
                   help=f"solvers to leave out: {', '.join(repr(s) for s in SOLVERS)}")
    g.add_argument("--acados-venv", type=Path, default=DEFAULT_ACADOS_VENV,
                   help="virtualenv for acados (Python 3.12; created when missing; default .venv-acados)")


def run_compare_from_args(args: argparse.Namespace) -> int:
    """Run ``compare`` from parsed arguments; 0 when humanmpc and every available reference ran."""
    if args.compare_specs:
        specs: list[Spec | str | Path] = list(args.compare_specs)
    else:
        specs = [resolve_spec({"humans": {"max": int(n)}}) for n in args.compare_humans]
    command = " ".join(["humanmpc-gen" if Path(sys.argv[0]).name == "humanmpc-gen" else "python -m humanmpc.compare",
                        *sys.argv[1:]])
    report = compare(specs, args.compare_replays, args.compare_out, steps=args.compare_steps,
                     seed=args.compare_seed, acados_venv=args.acados_venv, skip=args.compare_skip,
                     command=command.strip())
    print((Path(args.compare_out) / "benchmarks.md").read_text())
    errors = [r for r in report["rows"] if r["error"] and r["solver"] == "humanmpc"]
    return 1 if errors else 0


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m humanmpc.compare [options]``: the comparison without the humanmpc-gen hook."""
    parser = argparse.ArgumentParser(prog="python -m humanmpc.compare",
                                     description="Compare humanmpc with acados and Ipopt on the same replays.")
    add_compare_arguments(parser)
    return run_compare_from_args(parser.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
