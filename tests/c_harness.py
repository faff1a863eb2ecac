"""The C harnesses of tests/c/ compiled over a generated solver: one compile line for all of them."""

from __future__ import annotations

import subprocess
from collections.abc import Sequence
from pathlib import Path

from .conftest import require_tool

C_DIR = Path(__file__).resolve().parent / "c"
STRICT = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer", "-g"]


def build_harness(harness: str, solver_dir: Path, exe: Path, cc: str, flags: Sequence[str]) -> Path:
    """tests/c/``harness`` linked with the generated solver in ``solver_dir`` (its folder's name is the
    solver's), strict C99 warnings as errors plus ``flags``, by the compiler ``cc``; the compiler's
    messages in the assertion when it fails."""
    name = solver_dir.name
    cmd = [require_tool(cc), *STRICT, *flags, f'-DSOLVER_HEADER="{name}.h"', f"-DSOLVER_PREFIX={name}_",
           f"-DSOLVER_UPREFIX={name.upper()}_", "-I", str(solver_dir), str(C_DIR / harness),
           str(solver_dir / f"{name}.c"), str(solver_dir / f"{name}_model.c"), "-lm", "-o", str(exe)]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr
    return exe
