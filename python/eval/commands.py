"""``simulate``, ``evaluate`` and ``demo``: the evaluation's sub-commands of ``humanmpc-gen``.

Hook them into the CLI's sub-parsers::

    sub = parser.add_subparsers(dest="command", required=True)
    add_simulate_parser(sub)
    add_evaluate_parser(sub)
    args = parser.parse_args()
    return args.func(args)

Each ``func`` returns a process exit code: 0 on success, 2 for unknown names (with the valid
ones listed on stderr).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..codegen.cli import non_negative_int, positive_int
from ..planners.registry import planner_names
from ..sim.scenarios import RECORDED_CROSSINGS, RECORDED_SCENARIOS, SCENARIOS, SIMULATED_SCENARIOS


def _simulate(args: argparse.Namespace) -> int:
    from ..planners.registry import make_planner
    from ..sim.scenarios import make_scenario
    from .episode import run_episode
    from .metrics import compute_metrics
    from .plots import animate_episode, animation_path, figure_path, plot_episodes

    try:
        # the output names first: a typo must not cost the episode
        if args.plot:
            figure_path(args.plot)
        if args.animate:
            animation_path(args.animate)
        scenario = make_scenario(args.scenario, args.seed)
        planner = make_planner(args.planner)
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    log = run_episode(scenario, planner)
    metrics = compute_metrics(log)
    print(f"{args.scenario} seed {args.seed} with {args.planner}: ended by {log.ended_by} at t = {log.times[-1]:.1f} s")
    for key, value in metrics.as_row().items():
        print(f"  {key}: {value:.4g}" if isinstance(value, float) else f"  {key}: {value}")
    if args.plot:
        print(f"plot: {plot_episodes([log], args.plot)}")
    if args.animate:
        try:
            print(f"animation: {animate_episode(log, args.animate)}")
        except ValueError as err:
            print(f"error: {err}", file=sys.stderr)
            return 2
    return 0


def _evaluate(args: argparse.Namespace) -> int:
    from .evaluate import evaluate, markdown_table, validate_names

    scenarios = args.scenarios or list(SIMULATED_SCENARIOS)
    planners = args.planners or planner_names()
    try:
        validate_names(scenarios, planners, range(args.first_seed, args.first_seed + args.seeds))
        if args.seeds < 1 or args.workers < 1:
            raise ValueError("--seeds and --workers must be >= 1")
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    result = evaluate(
        scenarios, planners, list(range(args.first_seed, args.first_seed + args.seeds)), args.out,
        workers=args.workers, figures=not args.no_figures, progress=not args.quiet,
    )
    print(markdown_table(result.summary))
    print(f"tables and figures in {result.out_dir}")
    return 0


_RECORDED_SEEDS = (f"the recorded scenes ({', '.join(RECORDED_SCENARIOS)}) have seeds 0..{RECORDED_CROSSINGS - 1}, "
                   "one per crossing")


def add_simulate_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``simulate --scenario NAME --planner NAME --seed S [--plot FILE] [--animate FILE.gif]``."""
    p = subparsers.add_parser("simulate", help="run one closed-loop episode and print its metrics")
    p.add_argument("--scenario", required=True, help=f"one of: {', '.join(sorted(SCENARIOS))}")
    p.add_argument("--planner", required=True, help=f"a registered planner (now: {', '.join(planner_names())})")
    p.add_argument("--seed", type=non_negative_int, default=0, help=f"scenario seed (default 0); {_RECORDED_SEEDS}")
    p.add_argument("--plot", type=Path, help="write the paths figure to this file (.png/.svg/.pdf)")
    p.add_argument("--animate", type=Path, help="write an animated GIF of the episode to this file")
    p.set_defaults(func=_simulate)
    return p


def add_evaluate_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``evaluate [--scenarios ...] [--planners ...] [--seeds N] [--workers W] [--out DIR]``."""
    p = subparsers.add_parser("evaluate", help="run scenarios x planners x seeds and tabulate the metrics")
    p.add_argument("--scenarios", nargs="+", help=f"any of {', '.join(sorted(SCENARIOS))}; default: the simulated "
                   f"ones, {', '.join(SIMULATED_SCENARIOS)}")
    p.add_argument("--planners", nargs="+", help="default: every registered planner")
    p.add_argument("--seeds", type=positive_int, default=10,
                   help=f"number of seeds per scenario (default 10); {_RECORDED_SEEDS}")
    p.add_argument("--first-seed", type=non_negative_int, default=0, help="first seed (default 0)")
    p.add_argument("--workers", type=positive_int, default=2, help="parallel worker processes (default 2)")
    p.add_argument("--out", type=Path, default=Path("out/evaluation"), help="output folder (default out/evaluation)")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_evaluate)
    return p


def _demo(args: argparse.Namespace) -> int:
    from ..sim.scenarios import make_scenario
    from .demo import run_demo

    try:
        make_scenario(args.scenario, args.seed)  # a wrong name or seed is told before the solver is built
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    run_demo(seed=args.seed, out_dir=args.out, scenario_name=args.scenario)
    return 0


def add_demo_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``demo [--scenario NAME] [--seed S] [--out DIR]``: what ``make demo`` runs."""
    p = subparsers.add_parser("demo", help="the main job: both planners in the crossing-group scenario",
                              description="Generate the default solver, run the crossing-group scenario with the MPC "
                              "and the DWB baseline, print their metrics side by side and the timing summary, "
                              "and write the figure.")
    p.add_argument("--scenario", default="crossing_group",
                   help=f"the scenario (default crossing_group); one of: {', '.join(sorted(SCENARIOS))}")
    p.add_argument("--seed", type=non_negative_int, default=0, help=f"scenario seed (default 0); {_RECORDED_SEEDS}")
    p.add_argument("--out", type=Path, default=Path("out/demo"), help="output folder (default out/demo)")
    p.set_defaults(func=_demo)
    return p
