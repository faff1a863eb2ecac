"""Compile a generated solver package into its static and shared libraries (with its own Makefile)."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import struct
import subprocess
import sys
from collections.abc import Callable, Mapping
from pathlib import Path

from .manifest import Manifest, ManifestError


class BuildError(RuntimeError):
    """The C compiler or make failed; the message carries the end of their output."""


def read_manifest(solver_dir: Path) -> Manifest:
    try:
        return Manifest.read(solver_dir)
    except ManifestError as err:
        raise BuildError(str(err)) from None


def library_path(solver_dir: str | Path) -> Path:
    d = Path(solver_dir)
    return d / read_manifest(d).library


def is_stale(solver_dir: Path) -> bool:
    """True when the shared library is missing or older than any source of the package."""
    lib = library_path(solver_dir)
    if not lib.exists():
        return True
    sources = [*solver_dir.glob("*.c"), *solver_dir.glob("*.h"), *(solver_dir / "runtime").glob("*")]
    newest = max(p.stat().st_mtime for p in sources)
    return lib.stat().st_mtime < newest


# One flag policy for `humanmpc-gen build`, the package's Makefile and its CMakeLists: portable by
# default (the library runs on any CPU of the architecture: it may be copied to the robot), tuned to
# this machine's CPU on request (`build --native`, `make NATIVE=1`, `cmake -DHUMANMPC_NATIVE=ON`,
# $HUMANMPC_NATIVE=1 for the Python callers: SIMD of the fixed-size kernels, measured 25 % less time per
# RTI step). Both keep IEEE arithmetic (no fused multiply-add contraction), so a native build computes
# the same bits as a portable one and as the firmware (tested).
PORTABLE_CFLAGS = "-O2 -ffp-contract=off"
NATIVE_FLAGS = "-march=native -funroll-loops"  # added on request, after the portable ones
NATIVE_CFLAGS = f"{PORTABLE_CFLAGS} {NATIVE_FLAGS}"
HOST_CFLAGS = NATIVE_CFLAGS  # the former name
NATIVE_ENV = "HUMANMPC_NATIVE"
# What the package's Makefile writes beside the library: the compile command its objects were built with.
FLAGS_FILE = "cflags.txt"
_native_ok: dict[str, bool] = {}


def native_supported(compiler: str) -> bool:
    """Whether the compiler accepts NATIVE_FLAGS (checked once per compiler)."""
    if compiler not in _native_ok:
        try:
            proc = subprocess.run([*compiler.split(), *NATIVE_CFLAGS.split(), "-x", "c", "-c", "-o", os.devnull, "-"],
                                  input="int x;\n", capture_output=True, text=True, timeout=60, check=False)
            _native_ok[compiler] = proc.returncode == 0
        except (OSError, subprocess.TimeoutExpired):
            _native_ok[compiler] = False
    return _native_ok[compiler]


def host_cflags(compiler: str) -> str:
    """NATIVE_CFLAGS if the compiler accepts them, else PORTABLE_CFLAGS."""
    return NATIVE_CFLAGS if native_supported(compiler) else PORTABLE_CFLAGS


def wants_native(env: Mapping[str, str] | None = None) -> bool:
    """$HUMANMPC_NATIVE is 1 (or yes, true, on)."""
    e = os.environ if env is None else env
    return e.get(NATIVE_ENV, "").strip().lower() in ("1", "yes", "true", "on")


def compiler_and_flags(env: Mapping[str, str] | None = None, native: bool | None = None) -> tuple[str, str]:
    """The C compiler and flags a build uses: $CC (default cc); $CFLAGS or PORTABLE_CFLAGS, followed by
    NATIVE_FLAGS when native (default: $HUMANMPC_NATIVE) and the compiler takes them."""
    e = os.environ if env is None else env
    compiler = e.get("CC", "cc")
    flags = e.get("CFLAGS") or PORTABLE_CFLAGS
    if (wants_native(e) if native is None else native) and native_supported(compiler):
        flags = f"{flags} {NATIVE_FLAGS}"
    return compiler, flags


def build(solver_dir: str | Path, *, cc: str | None = None, cflags: str | None = None, native: bool | None = None,
          log: Callable[[str], None] | None = None) -> Path:
    """Run the package's Makefile; return the path of the shared library.

    Compiler flags: ``cflags``, else $CFLAGS, else PORTABLE_CFLAGS; with ``native`` (default:
    $HUMANMPC_NATIVE) followed by NATIVE_FLAGS. The Makefile rebuilds when the flags change."""
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
    want = wants_native(env) if native is None else native
    if want and not native_supported(compiler):
        raise BuildError(f"C compiler {compiler!r} does not take {NATIVE_FLAGS}: build without --native "
                         f"(and without {NATIVE_ENV}=1)")
    env["CFLAGS"] = env.get("CFLAGS") or PORTABLE_CFLAGS
    env["NATIVE"] = "1" if want else "0"
    shown = f"{env['CFLAGS']} {NATIVE_FLAGS}" if want else env["CFLAGS"]
    kind = "tuned to this machine's CPU" if want else "portable"
    say(f"[humanmpc] building {d.name} with {compiler} ({shown}; {kind})")
    proc = subprocess.run([make, "-C", str(d), "--no-print-directory", "all"], env=env,
                          capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-40:])
        raise BuildError(f"building {d} failed (make exit {proc.returncode}):\n{tail}")
    lib = library_path(d)
    record_library(lib)
    say(f"[humanmpc] built {lib}")
    return lib


def built_flags(solver_dir: Path) -> str | None:
    """The compile command of the package's library as its Makefile recorded it (build/cflags.txt), or None
    (not built, or built by a Makefile of an older humanmpc)."""
    path = library_path(solver_dir).parent / FLAGS_FILE
    try:
        return path.read_text().strip() or None
    except OSError:
        return None


# -- the library's integrity, checked by humanmpc.load before dlopen ---------------------------------------
# A truncated library mapped by dlopen crashes the process with SIGBUS when a page past its end is touched
# (issue 22, item 6). build() records the size and SHA-256 of what it built next to it; load() compares,
# and checks the ELF file's own structure (its segments and section table lie inside the file) whoever
# built it.


def record_path(lib: Path) -> Path:
    return lib.with_name(lib.name + ".record.json")


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def record_library(lib: Path) -> None:
    """Write the size and SHA-256 of the library build() just made (build/lib<name>.so.record.json)."""
    record_path(lib).write_text(json.dumps({"size": lib.stat().st_size, "sha256": _sha256(lib)}) + "\n")


class LibraryIntegrityError(RuntimeError):
    """A library that is not the one that was built, or not a whole ELF file: never handed to dlopen."""


def check_elf(lib: Path) -> None:
    """The ELF header, every loaded segment and the section table lie inside the file (a truncated .so fails)."""
    data = lib.read_bytes()
    size = len(data)
    if size < 64 or data[:4] != b"\x7fELF" or data[4] not in (1, 2) or data[5] not in (1, 2):
        raise LibraryIntegrityError(f"{lib} is not an ELF shared library ({size} bytes)")
    wide, order = data[4] == 2, "<" if data[5] == 1 else ">"
    if wide:
        phoff, shoff = struct.unpack_from(order + "QQ", data, 32)
        phentsize, phnum, shentsize, shnum = struct.unpack_from(order + "HHHH", data, 54)
    else:
        phoff, shoff = struct.unpack_from(order + "II", data, 28)
        phentsize, phnum, shentsize, shnum = struct.unpack_from(order + "HHHH", data, 42)
    if phoff + phentsize * phnum > size or shoff + shentsize * shnum > size:
        raise LibraryIntegrityError(f"{lib} is cut short: its headers reach beyond its {size} bytes")
    for k in range(phnum):
        at = phoff + k * phentsize
        if wide:
            p_type, = struct.unpack_from(order + "I", data, at)
            p_offset, = struct.unpack_from(order + "Q", data, at + 8)
            p_filesz, = struct.unpack_from(order + "Q", data, at + 32)
        else:
            p_type, p_offset = struct.unpack_from(order + "II", data, at)
            p_filesz, = struct.unpack_from(order + "I", data, at + 16)
        if p_type == 1 and p_offset + p_filesz > size:  # PT_LOAD
            raise LibraryIntegrityError(f"{lib} is cut short: a loaded segment ends at byte {p_offset + p_filesz}, "
                                        f"the file at {size}")


def check_library(lib: Path) -> None:
    """What load() checks before dlopen: the ELF structure, and the size and hash build() recorded, if it did."""
    check_elf(lib)
    rec = record_path(lib)
    if not rec.is_file():
        return
    try:
        expected = json.loads(rec.read_text())
        want_size, want_hash = int(expected["size"]), str(expected["sha256"])
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise LibraryIntegrityError(f"{rec} is not a library record ({err!r}); rebuild the package") from None
    got_size = lib.stat().st_size
    if got_size != want_size or _sha256(lib) != want_hash:
        raise LibraryIntegrityError(
            f"{lib} is not the library that was built ({got_size} bytes, recorded {want_size}, or another "
            f"SHA-256): rebuild it with `humanmpc-gen build {lib.parent.parent}`")
