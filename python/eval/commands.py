"""``simulate``, ``evaluate``, ``report`` and ``demo``: the evaluation's sub-commands of ``humanmpc-gen``.

Hook them into the CLI's sub-parsers::

    sub = parser.add_subparsers(dest="command", required=True)
    add_simulate_parser(sub)
    add_evaluate_parser(sub)
    args = parser.parse_args()
    return args.func(args)

Each ``func`` returns a process exit code: 0 on success, 2 for unknown names (with the valid
ones listed on stderr), an invalid ``--spec`` (every problem with its key) or a solver folder that
cannot be used (named, with what to do); all of these are checked before any episode runs.

The three commands take ``--spec FILE`` and ``--solver-dir DIR`` for the solver of the MPC planners
(``mpc``, ``mpc_paper``): ``--spec`` alone has the tools generate and build that spec's solver into
their cache, ``generated/.cache/<name>-<hash>/`` (reused while the spec is unchanged); ``--solver-dir``
uses a generated and built package as it is, never regenerating or rebuilding it (with ``--spec`` as
well, it must hold that spec's solver); neither, the built-in default spec's solver in the cache
(:mod:`humanmpc.planners.solver_cache`). The solver's interval T / N must be the simulation's control
period, 0.1 s (its N is its own: the episodes hand the planners tracks, which the controller predicts).
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from dataclasses import replace
from pathlib import Path

from ..codegen.cli import non_negative_int, output_dir, positive_int
from ..codegen.spec import Spec, load_spec
from ..planners.registry import planner_names
from ..planners.solver_cache import CACHE_DIR, SolverDirError, check_solver_dir, select_solver
from ..sim.scenarios import CROWD_MODELS, RECORDED_CROSSINGS, RECORDED_SCENARIOS, SCENARIOS, SIMULATED_SCENARIOS
from .episode import EpisodeConfig
from .extras import require


def choose_solver(spec_file: Path | None, solver_dir: Path | None) -> EpisodeConfig:
    """Select the MPC planners' solver from ``--spec`` / ``--solver-dir`` (checked now; a spec's solver
    is generated only when a planner first needs it) and return the episode settings that fit it.

    ``SpecError`` for an invalid spec, ``SolverDirError`` for a folder that cannot be used,
    ``ValueError`` for a solver whose interval is not the simulation's control period."""
    spec = load_spec(spec_file) if spec_file is not None else None
    source = str(spec_file) if spec_file is not None else None
    if solver_dir is not None:
        dims = check_solver_dir(solver_dir, spec, source).dims
        N, dt, where = dims.N, dims.dt, f"the solver in {solver_dir}"
    else:
        resolved = spec or Spec()
        N, dt, where = resolved.horizon.N, resolved.dt, str(spec_file or "the built-in spec")
    base = EpisodeConfig()
    if abs(dt - base.dt) > 1e-9:
        raise ValueError(f"{where}: horizon.T / horizon.N = {dt:g} s, but the simulation's control period is "
                         f"{base.dt:g} s: give horizon.T = {base.dt:g} * horizon.N (T: {base.dt * N:g} for N: {N})")
    select_solver(spec, solver_dir, source)
    return base


def _print_solver(planner: object) -> None:
    solver = getattr(planner, "solver", None)
    if solver is not None and hasattr(solver, "spec_hash"):
        d = solver.dims
        print(f"solver: {solver.path} ('{solver.name}', spec sha256 {solver.spec_hash}, N={d.N}, N_h={d.nh}, "
              f"dt={d.dt:g} s)")


def _simulate(args: argparse.Namespace) -> int:
    from ..planners.registry import make_planner
    from ..sim.scenarios import make_scenario
    from .episode import run_episode
    from .metrics import compute_metrics, with_unit
    from .plots import animate_episode, animation_path, figure_path, plot_episodes

    try:
        # the output names first: a typo must not cost the episode
        if args.plot:
            figure_path(args.plot)
        if args.animate:
            animation_path(args.animate)
        scenario = make_scenario(args.scenario, args.seed)
        config = replace(choose_solver(args.spec, args.solver_dir), crowd_model=args.crowd)
        if args.crowd == "orca" and args.scenario not in RECORDED_SCENARIOS:
            require("pyrvo", "the ORCA crowd model (--crowd orca)")  # before the solver is built
        planner = make_planner(args.planner)  # an MPC planner generates and builds a --spec's solver here
    except (ValueError, ImportError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    _print_solver(planner)
    log = run_episode(scenario, planner, config)
    metrics = compute_metrics(log)
    print(f"{args.scenario} seed {args.seed} with {args.planner}: ended by {log.ended_by} at t = {log.times[-1]:.1f} s")
    for key, value in metrics.as_row().items():
        shown = f"{value:.4g}" if isinstance(value, float) else ("yes" if value else "no") \
            if isinstance(value, bool) else str(value)
        print(f"  {with_unit(key)}: {shown}")
    if args.plot:
        crowd = "recorded people" if args.scenario in RECORDED_SCENARIOS else f"{args.crowd} crowd"
        title = f"{args.scenario}, {crowd}, seed {args.seed}: {args.planner}"
        print(f"plot: {plot_episodes([log], args.plot, title=title)}")
    if args.animate:
        try:
            print(f"animation: {animate_episode(log, args.animate)}")
        except ValueError as err:
            print(f"error: {err}", file=sys.stderr)
            return 2
    return 0


def _evaluate(args: argparse.Namespace) -> int:
    from .campaign import parse_grid
    from .engines import CampaignEngineError, TaskFailedError
    from .evaluate import evaluate, markdown_table, validate_names
    from .store import CampaignFolderError

    scenarios = args.scenarios or list(SIMULATED_SCENARIOS)
    planners = args.planners or planner_names()
    try:
        validate_names(scenarios, planners, range(args.first_seed, args.first_seed + args.seeds))
        if args.seeds < 1:
            raise ValueError("--seeds must be >= 1")
        if "orca" in args.crowds and any(s not in RECORDED_SCENARIOS for s in scenarios):
            require("pyrvo", "the ORCA crowd model (--crowds orca)")
        grid = parse_grid(args.grid or [])
        config = choose_solver(args.spec, args.solver_dir)
    except (ValueError, ImportError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2

    def terminated(signum: int, frame: object) -> None:
        raise KeyboardInterrupt  # SIGTERM (a batch system's notice) stops like Ctrl-C: the finished rows are written

    previous = signal.signal(signal.SIGTERM, terminated) if threading.current_thread() is threading.main_thread() \
        else None
    try:
        # makes each planner once before any episode: the MPC's solver is generated here if needed
        result = evaluate(
            scenarios, planners, list(range(args.first_seed, args.first_seed + args.seeds)), args.out,
            workers=args.workers, figures=not args.no_figures, progress=not args.quiet, config=config,
            crowds=args.crowds, grid=grid, scheduler=args.scheduler, traces=args.traces, fresh=args.fresh,
            flush_every=args.flush_every,
        )
    except (SolverDirError, CampaignFolderError, CampaignEngineError, TaskFailedError, ValueError, KeyError,
            ImportError) as err:
        print(f"error: {str(err).strip(chr(34))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"interrupted: the episodes finished so far are in {args.out}; run the same command again to "
              "resume", file=sys.stderr)
        return 130
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    print(markdown_table(result.summary))
    print(f"tables, report (report.md) and figures in {result.out_dir}")
    return 0


def _report(args: argparse.Namespace) -> int:
    from .report import write_report

    try:
        path = write_report(args.folder, args.out, figures=not args.no_figures)
    except (ValueError, ImportError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(f"report: {path}")
    return 0


def add_report_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``report DIR [--out FILE.md] [--no-figures]``: the report of a campaign's results folder."""
    p = subparsers.add_parser("report", help="write the Markdown report (and figures) of an evaluation's results",
                              description="Read the results folder of humanmpc-gen evaluate and write its report: "
                              "rates with 95 %% Wilson intervals, means with 95 %% t intervals, units in every "
                              "header, stops by reason, and the figures (DIR/report.md, DIR/figures/).")
    p.add_argument("folder", type=Path, metavar="DIR", help="the --out folder of humanmpc-gen evaluate")
    p.add_argument("--out", type=Path, metavar="FILE", help="the Markdown file (default DIR/report.md; the figures "
                   "go to figures/ beside it)")
    p.add_argument("--no-figures", action="store_true", help="tables only")
    p.set_defaults(func=_report)
    return p


_RECORDED_SEEDS = (f"the recorded scenes ({', '.join(RECORDED_SCENARIOS)}) have seeds 0..{RECORDED_CROSSINGS - 1}, "
                   "one per crossing")


def add_solver_options(p: argparse.ArgumentParser) -> None:
    """``--spec FILE`` and ``--solver-dir DIR``: the solver of the MPC planners."""
    g = p.add_argument_group("the MPC planners' solver (default: the built-in default spec's, generated and built "
                             f"into the tools' cache, {CACHE_DIR}/, when it is not there yet)")
    g.add_argument("--spec", type=Path, metavar="FILE",
                   help=f"YAML spec: its solver is generated and built into {CACHE_DIR}/<name>-<hash>/ and reused "
                   "while the spec is unchanged; no other folder is written")
    g.add_argument("--solver-dir", type=Path, metavar="DIR",
                   help="an already generated and built solver package (humanmpc-gen generate + build), used as it "
                   "is: never regenerated or rebuilt; with --spec it must hold that spec's solver")


def add_simulate_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``simulate --scenario NAME --planner NAME --seed S [--crowd MODEL] [--plot FILE] [--animate FILE.gif]
    [--spec FILE] [--solver-dir DIR]``."""
    p = subparsers.add_parser("simulate", help="run one closed-loop episode and print its metrics")
    p.add_argument("--scenario", required=True, help=f"one of: {', '.join(sorted(SCENARIOS))}")
    p.add_argument("--planner", required=True, help=f"a registered planner (now: {', '.join(planner_names())})")
    p.add_argument("--seed", type=non_negative_int, default=0, help=f"scenario seed (default 0); {_RECORDED_SEEDS}")
    p.add_argument("--crowd", choices=CROWD_MODELS, default="social_force",
                   help="how simulated people move (default social_force); recorded scenes replay theirs")
    p.add_argument("--plot", type=Path, help="write the paths figure to this file (.png/.svg/.pdf)")
    p.add_argument("--animate", type=Path, help="write an animated GIF of the episode to this file")
    add_solver_options(p)
    p.set_defaults(func=_simulate)
    return p


def add_evaluate_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``evaluate [--scenarios ...] [--crowds ...] [--planners ...] [--grid NAME=V,...] [--seeds N] [--workers W |
    --scheduler ADDRESS] [--traces first|all|none] [--out DIR] [--fresh] [--spec FILE] [--solver-dir DIR]``."""
    p = subparsers.add_parser(
        "evaluate", help="run scenarios x crowd models x planners x seeds (on Dask) and report the metrics",
        description="An evaluation campaign: every scenario with every crowd model, every planner (the MPC "
        "planners with every point of --grid), every seed; the episodes run on a local Dask cluster (--workers), "
        "an existing one (--scheduler) or in this process (--workers 0), their rows stream to Parquet in --out, "
        "and an interrupted campaign resumes where it stopped when run again. Writes runs.csv, summary.md, "
        "safety.md, report.md (with confidence intervals) and figures/.")
    p.add_argument("--scenarios", nargs="+", help=f"any of {', '.join(SCENARIOS)}; default: the simulated "
                   f"ones, {', '.join(SIMULATED_SCENARIOS)}")
    p.add_argument("--planners", nargs="+", help="default: every registered planner")
    p.add_argument("--seeds", type=positive_int, default=10,
                   help=f"number of seeds per scenario (default 10); {_RECORDED_SEEDS}")
    p.add_argument("--first-seed", type=non_negative_int, default=0, help="first seed (default 0)")
    p.add_argument("--crowds", nargs="+", choices=CROWD_MODELS, default=["social_force"],
                   help="crowd models of the simulated scenarios (default social_force); recorded scenes replay "
                   "their people")
    p.add_argument("--grid", action="append", metavar="NAME=V1,V2,...",
                   help="a runtime parameter's values (humanmpc-gen keys; vectors as a:b:c:d), repeatable: the MPC "
                   "planners run every combination, e.g. --grid q=10,50 --grid reaction_time=0.3,0.5")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=non_negative_int, default=2,
                       help="worker processes of a local Dask cluster (default 2); 0: every episode in this process")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run on an existing Dask cluster, e.g. tcp://10.0.0.5:8786 (its workers need humanmpc "
                       "with its campaign extra; each builds the solver into its own generated/.cache/)")
    p.add_argument("--traces", choices=("first", "all", "none"), default="first",
                   help="which episodes keep their per-step trace (traces/*.parquet): the first seed of every cell "
                   "(default; the figures draw them), all, none")
    p.add_argument("--out", type=output_dir, default=Path("out/evaluation"),
                   help="results folder (default out/evaluation); the same campaign run into it again runs only the "
                   "episodes it lacks")
    p.add_argument("--flush-every", type=positive_int, default=50, metavar="N",
                   help="write the results every N episodes (default 50; and every 10 s): what an interruption "
                   "can cost")
    p.add_argument("--fresh", action="store_true",
                   help="delete the results of another campaign in --out first (without it, that is an error)")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_solver_options(p)
    p.set_defaults(func=_evaluate)
    return p


def _demo(args: argparse.Namespace) -> int:
    from ..sim.scenarios import make_scenario
    from .demo import run_demo

    try:
        make_scenario(args.scenario, args.seed)  # a wrong name or seed is told before the solver is built
        config = choose_solver(args.spec, args.solver_dir)
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    try:
        run_demo(seed=args.seed, out_dir=args.out, scenario_name=args.scenario, config=config)
    except SolverDirError as err:  # raised by its first step, before any episode
        print(f"error: {err}", file=sys.stderr)
        return 2
    return 0


def add_demo_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``demo [--scenario NAME] [--seed S] [--out DIR] [--spec FILE | --solver-dir DIR]``: what ``make demo`` runs."""
    p = subparsers.add_parser("demo", help="the main job: both planners in the crossing-group scenario",
                              description="Generate and build the default solver (or that of --spec) into the "
                              f"tools' cache ({CACHE_DIR}/) when it is not there yet, run the crossing-group "
                              "scenario (or --scenario) with the MPC and the DWB baseline, print their metrics side "
                              "by side and the timing summary, and write the figure.")
    p.add_argument("--scenario", default="crossing_group",
                   help=f"the scenario (default crossing_group); one of: {', '.join(sorted(SCENARIOS))}")
    p.add_argument("--seed", type=non_negative_int, default=0, help=f"scenario seed (default 0); {_RECORDED_SEEDS}")
    p.add_argument("--out", type=output_dir, default=Path("out/demo"), help="output folder (default out/demo)")
    add_solver_options(p)
    p.set_defaults(func=_demo)
    return p
