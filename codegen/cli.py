"""The humanmpc-gen command line: check, generate, build."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from . import __version__
from .build import BuildError, build, read_manifest
from .generate import GenerateError, generate
from .spec import SpecError, describe_schema, load_spec


def _cmd_check(args: argparse.Namespace) -> int:
    spec = load_spec(args.spec)
    print(f"# {args.spec or 'built-in default spec'}: valid (sha256 {spec.digest()})")
    print(spec.to_yaml(), end="")
    return 0


def _cmd_generate(args: argparse.Namespace) -> int:
    spec = load_spec(args.spec)
    out = generate(spec, args.output or Path("generated") / spec.name, force=args.force)
    print(out)
    return 0


def _cmd_build(args: argparse.Namespace) -> int:
    lib = build(args.dir, cc=args.cc, cflags=args.cflags)
    print(lib)
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    d: Path = args.dir
    m = read_manifest(d)
    dims = m["dims"]
    assert isinstance(dims, dict)
    print(f"solver '{m['name']}'  (humanmpc {m['generator_version']}, CasADi {m['casadi_version']}, {m['real']})")
    print(f"  spec sha256  {m['spec_hash']}")
    print(f"  sizes        N={dims['N']} intervals of dt={dims['dt']:g} s (T={dims['T']:g} s), "
          f"N_h={dims['nh']} humans, {dims['ng']} distance rows/node, nx={dims['nx']}, nu={dims['nu']}")
    print("  files")
    for p in sorted(d.rglob("*")):
        if p.is_file() and "build" not in p.relative_to(d).parts[:-1]:
            print(f"    {p.relative_to(d)!s:<28} {p.stat().st_size:>9,} B")
    lib = d / str(m["library"])
    print(f"  library      {lib} ({lib.stat().st_size:,} B)" if lib.exists() else "  library      not built")
    functions = m["functions"]
    assert isinstance(functions, list)
    print("  model functions (C and Python)")
    for f in functions:
        ins = ", ".join(n for n, _, _ in f["inputs"])
        outs = ", ".join(n for n, _, _ in f["outputs"])
        print(f"    {m['name']}_{f['name']}({ins}) -> {outs}")
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from humanmpc.bench import markdown_table, run_bench

    if args.compare:
        from humanmpc.compare import run_compare_from_args

        return run_compare_from_args(args)

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


def _cmd_demo(args: argparse.Namespace) -> int:
    from humanmpc.demo import run_demo

    run_demo(seed=args.seed, out_dir=args.out)
    return 0


def _cmd_keys(args: argparse.Namespace) -> int:
    width = max(len(k) for k, _, _ in describe_schema())
    for key, doc, default in describe_schema():
        print(f"{key:<{width}}  {default!s:<24}  {doc}")
    return 0


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="humanmpc-gen",
        description="Generate fixed-size, malloc-free C solvers for human-aware navigation MPC from a YAML spec.",
    )
    parser.add_argument("--version", action="version", version=f"humanmpc {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("check", help="validate a spec and print it resolved (defaults filled in)",
                       description="Validate SPEC (or the built-in default spec) and print the resolved spec.")
    p.add_argument("spec", nargs="?", help="YAML spec file (default: the built-in paper spec)")
    p.set_defaults(func=_cmd_check)

    p = sub.add_parser("generate", help="generate the C solver package of a spec",
                       description="Generate the C solver package of SPEC (or of the built-in default spec). "
                       "The folder is written atomically: on failure nothing is left behind.")
    p.add_argument("spec", nargs="?", help="YAML spec file (default: the built-in paper spec)")
    p.add_argument("-o", "--output", type=Path, help="output folder (default: generated/<name>)")
    p.add_argument("--force", action="store_true", help="replace an existing generated folder")
    p.set_defaults(func=_cmd_generate)

    p = sub.add_parser("build", help="compile a generated package into its libraries",
                       description="Compile DIR (a generated package) with its Makefile into "
                       "DIR/build/lib<name>.so and .a.")
    p.add_argument("dir", type=Path, help="generated solver folder")
    p.add_argument("--cc", help="C compiler (default: $CC or cc)")
    p.add_argument("--cflags", help="compiler flags (default: $CFLAGS, or tuned to this machine: "
                   "-O2 -march=native -funroll-loops -ffp-contract=off)")
    p.set_defaults(func=_cmd_build)

    p = sub.add_parser("info", help="describe a generated package: sizes, files, functions",
                       description="Describe the generated package DIR: its spec hash, sizes, files and functions.")
    p.add_argument("dir", type=Path, help="generated solver folder")
    p.set_defaults(func=_cmd_info)

    p = sub.add_parser("bench", help="time the real-time iteration in random crowds",
                       description="Generate one solver per crowd size and time its RTI steps in seeded "
                       "closed loops (humans at constant velocity, one obstacle near the path).")
    p.add_argument("spec", nargs="?", help="YAML spec file (default: the built-in paper spec)")
    p.add_argument("--humans", default="5,10,20,30", help="crowd sizes N_h (default: 5,10,20,30)")
    p.add_argument("--seeds", type=int, default=3, help="closed loops per crowd size (default: 3)")
    p.add_argument("--steps", type=int, default=300, help="RTI steps per closed loop (default: 300)")
    p.add_argument("--out", type=Path, default=Path("out/bench"), help="output folder (default: out/bench)")
    from humanmpc.compare import add_compare_arguments  # the Python package depends on codegen, not back

    add_compare_arguments(p)
    p.set_defaults(func=_cmd_bench)

    from humanmpc.sim_commands import add_evaluate_parser, add_simulate_parser

    add_simulate_parser(sub)
    add_evaluate_parser(sub)
    from .firmware import add_firmware_parser

    add_firmware_parser(sub)

    p = sub.add_parser("demo", help="the main job: both planners in the crossing-group scenario",
                       description="Generate the default solver, run the crossing-group scenario with the MPC "
                       "and the DWB baseline, print their metrics side by side and the timing summary, "
                       "and write the figure.")
    p.add_argument("--seed", type=int, default=0, help="scenario seed (default 0)")
    p.add_argument("--out", type=Path, default=Path("out/demo"), help="output folder (default out/demo)")
    p.set_defaults(func=_cmd_demo)

    p = sub.add_parser("keys", help="list every spec key with its default and meaning",
                       description="List every spec key with its default value and meaning.")
    p.set_defaults(func=_cmd_keys)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = make_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except SpecError as err:
        print(f"humanmpc-gen: {err}", file=sys.stderr)
        return 2
    except (GenerateError, BuildError, FileNotFoundError) as err:
        print(f"humanmpc-gen: {err}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
