"""humanmpc-gen: the generator's commands (humanmpc.codegen.cli) and the tools built on the solver."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from .codegen.cli import GENERATOR_ERRORS, add_generator_commands, make_parser, run
from .compare.commands import add_bench_parser
from .eval.commands import add_demo_parser, add_evaluate_parser, add_report_parser, add_simulate_parser
from .firmware.commands import add_firmware_parser


def build_parser() -> argparse.ArgumentParser:
    """The whole command line: the generator's commands and the tools'."""
    parser = make_parser()
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    add_generator_commands(sub)
    add_bench_parser(sub)
    add_simulate_parser(sub)
    add_evaluate_parser(sub)
    add_report_parser(sub)
    add_firmware_parser(sub)
    add_demo_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    return run(build_parser(), argv, GENERATOR_ERRORS)


if __name__ == "__main__":
    sys.exit(main())
