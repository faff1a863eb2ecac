"""The ``bench`` command of humanmpc-gen: RTI step times in random crowds, or with --compare the same
problems with acados and Ipopt."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..codegen.cli import SPEC_HELP, output_dir, positive_int
from ..codegen.spec import SpecError, load_spec
from .report import add_compare_arguments


def _cmd_bench(args: argparse.Namespace) -> int:
    from .bench import markdown_table, run_bench

    if args.compare:
        from .report import run_compare_from_args

        return run_compare_from_args(args)
    if args.controller is not None:
        from .controller_bench import controller_markdown, run_controller_bench

        if args.controller > 1000:
            raise SpecError([f"--controller: {args.controller} tracks: at most 1000"], "bench")
        result = run_controller_bench(load_spec(args.spec), args.controller, seeds=args.seeds, steps=args.steps,
                                      out_dir=args.out)
        print(controller_markdown(result), end="")
        print(f"(written to {args.out / 'controller.json'} and {args.out / 'controller.md'})")
        return 0

    try:
        humans = [int(h) for h in args.humans.split(",")]
    except ValueError:
        raise SpecError([f"--humans: {args.humans!r} is not a comma-separated list of integers"], "bench") from None
    if any(h < 0 or h > 200 for h in humans):
        raise SpecError([f"--humans: {args.humans!r}: each count must be in 0..200"], "bench")
    results = run_bench(load_spec(args.spec), humans, seeds=args.seeds, steps=args.steps, out_dir=args.out)
    print(markdown_table(results), end="")
    print(f"(written to {args.out / 'bench.json'} and {args.out / 'bench.md'})")
    return 0


def add_bench_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="time the real-time iteration in random crowds",
                       description="Generate one solver per crowd size and time its RTI steps in seeded "
                       "closed loops (humans at constant velocity, one obstacle near the path).")
    p.add_argument("spec", nargs="?", help=SPEC_HELP)
    p.add_argument("--humans", default="5,10,20,30", help="crowd sizes N_h (default: 5,10,20,30)")
    p.add_argument("--seeds", type=positive_int, default=3, help="closed loops per crowd size (default: 3)")
    p.add_argument("--steps", type=positive_int, default=300, help="RTI steps per closed loop (default: 300)")
    p.add_argument("--out", type=output_dir, default=Path("out/bench"), help="output folder (default: out/bench)")
    p.add_argument("--controller", type=positive_int, metavar="TRACKS", nargs="?", const=30,
                   help="time the whole controller step (predictions, selection, OCP, monitors) with TRACKS "
                   "tracked people (default 30) instead of the RTI alone")
    add_compare_arguments(p)
    p.set_defaults(func=_cmd_bench)
