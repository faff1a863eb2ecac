"""The generator's commands (check, generate, ros, build, info, keys), mounted by humanmpc-gen (humanmpc.cli)."""

from __future__ import annotations

import argparse
import ctypes
import sys
from collections.abc import Sequence
from pathlib import Path

from . import __version__
from .build import BuildError, build, read_manifest
from .generate import GenerateError, generate
from .ros import write_ros
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


def _cmd_ros(args: argparse.Namespace) -> int:
    print(write_ros(args.dir, args.output, force=args.force))
    return 0


def _cmd_build(args: argparse.Namespace) -> int:
    lib = build(args.dir, cc=args.cc, cflags=args.cflags)
    print(lib)
    return 0


def static_memory(lib: Path, name: str) -> list[tuple[str, int]]:
    """(what, bytes) of the solver's and the controller's structs, as the built library reports them."""
    c = ctypes.CDLL(str(lib.resolve()))
    sizes = [ctypes.c_size_t() for _ in range(5)]

    def call(fn: str, *args: object) -> int:
        f = getattr(c, f"{name}_{fn}")
        f.restype = ctypes.c_size_t if fn.endswith("memsize") else ctypes.c_int
        return int(f(*args))

    solver = call("solver_memsize")
    controller = call("controller_memsize")
    call("struct_sizes", *(ctypes.byref(x) for x in sizes[:3]))
    call("controller_struct_sizes", *(ctypes.byref(x) for x in sizes[3:]))
    return [
        (f"{name}_solver", solver),
        (f"{name}_controller (holds its solver)", controller),
        (f"{name}_params", sizes[0].value),
        (f"{name}_input / {name}_output", sizes[1].value + sizes[2].value),
        (f"{name}_controller_input", sizes[3].value),
        (f"{name}_controller_output", sizes[4].value),
    ]


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
    if lib.exists():
        print("  static memory (the structs a caller declares; nothing is allocated at run time)")
        for what, size in static_memory(lib, str(m["name"])):
            print(f"    {what:<34} {size:>11,} B")
    functions = m["functions"]
    assert isinstance(functions, list)
    print("  model functions (C and Python)")
    for f in functions:
        ins = ", ".join(n for n, _, _ in f["inputs"])
        outs = ", ".join(n for n, _, _ in f["outputs"])
        print(f"    {m['name']}_{f['name']}({ins}) -> {outs}")
    return 0


def _cmd_keys(args: argparse.Namespace) -> int:
    width = max(len(k) for k, _, _ in describe_schema())
    for key, doc, default in describe_schema():
        print(f"{key:<{width}}  {default!s:<24}  {doc}")
    return 0


def add_generator_commands(sub: argparse._SubParsersAction) -> None:
    """The generator's subcommands: check, generate, ros, build, info, keys."""
    p = sub.add_parser("check", help="validate a spec and print it resolved (defaults filled in)",
                       description="Validate SPEC (or the built-in default spec) and print the resolved spec.")
    p.add_argument("spec", nargs="?", help="YAML spec file (default: the built-in paper spec)")
    p.set_defaults(func=_cmd_check)

    p = sub.add_parser("generate", help="generate the C solver package of a spec",
                       description="Generate the C solver package of SPEC (or of the built-in default spec). "
                       "The folder is written atomically: on failure nothing is left behind.")
    p.add_argument("spec", nargs="?", help="YAML spec file (default: the built-in paper spec)")
    p.add_argument("-o", "--output", type=output_dir, help="output folder (default: generated/<name>)")
    p.add_argument("--force", action="store_true", help="replace an existing generated folder")
    p.set_defaults(func=_cmd_generate)

    p = sub.add_parser("ros", help="write the ROS 1 node (catkin packages) of a generated solver",
                       description="Write the catkin packages of the ROS 1 node over the controller of DIR (a "
                       "generated solver): humanmpc_msgs and <name>_ros, into a folder for a workspace's src/ "
                       "(docs/ros.md). Written atomically.")
    p.add_argument("dir", type=Path, help="generated solver folder (humanmpc-gen generate's)")
    p.add_argument("-o", "--output", type=Path,
                   help="output folder (default: <name>_ros_src beside DIR)")
    p.add_argument("--force", action="store_true", help="replace an existing folder written by humanmpc-gen ros")
    p.set_defaults(func=_cmd_ros)

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

    p = sub.add_parser("keys", help="list every spec key with its default and meaning",
                       description="List every spec key with its default value and meaning.")
    p.set_defaults(func=_cmd_keys)


def non_negative_int(text: str) -> int:
    """argparse type: a seed or an index (argparse names the option in its message)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} is negative: it must be an integer >= 0")
    return value


def positive_int(text: str) -> int:
    """argparse type: a count of seeds, steps or workers."""
    value = non_negative_int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be an integer >= 1")
    return value


def output_dir(text: str) -> Path:
    """argparse type: a folder to write into, checked before any work: it is a folder or can become one
    (no part of it is a file). A file in the way raised a traceback once the command got to writing."""
    path = Path(text)
    for part in (path, *path.parents):
        if part.exists():
            if not part.is_dir():
                what = "is a file" if part == path else f"lies under {str(part)!r}, which is a file"
                raise argparse.ArgumentTypeError(f"{text!r} {what}: it must be a folder, or a path that can become one")
            break
    return path


# What the generator's commands raise for a user's mistake or a failed tool: reported in one line.
GENERATOR_ERRORS: tuple[type[Exception], ...] = (GenerateError, BuildError, FileNotFoundError)


def make_parser(prog: str = "humanmpc-gen") -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Generate fixed-size, malloc-free C solvers for human-aware navigation MPC from a YAML spec.",
    )
    parser.add_argument("--version", action="version", version=f"humanmpc {__version__}")
    return parser


def run(parser: argparse.ArgumentParser, argv: Sequence[str] | None,
        errors: tuple[type[Exception], ...] = GENERATOR_ERRORS) -> int:
    """Parse argv, run the chosen command; a spec error exits 2, another known error 1, both in one line."""
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except SpecError as err:
        print(f"{parser.prog}: {err}", file=sys.stderr)
        return 2
    except errors as err:
        print(f"{parser.prog}: {err}", file=sys.stderr)
        return 1


def main(argv: Sequence[str] | None = None) -> int:
    """The generator alone (python -m humanmpc.codegen): the full tool is humanmpc-gen (humanmpc.cli)."""
    parser = make_parser("python -m humanmpc.codegen")
    add_generator_commands(parser.add_subparsers(dest="command", required=True, metavar="COMMAND"))
    return run(parser, argv)


if __name__ == "__main__":
    sys.exit(main())
