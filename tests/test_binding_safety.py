"""The Python binding under misuse: a solver shared between threads, a tampered package."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import humanmpc

from .conftest import make_solver


@pytest.fixture(scope="module")
def small_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_solver(tmp_path_factory.mktemp("safety"), {"name": "safety", "humans": {"max": 3}})


def test_two_threads_stepping_one_solver_are_serialised(small_dir: Path) -> None:
    """cffi releases the GIL inside C: without the solver's lock two threads crashed it (SIGSEGV)."""
    solver = humanmpc.load(small_dir)
    n = solver.dims.N
    results: dict[int, list[humanmpc.StepResult]] = {0: [], 1: []}
    errors: list[BaseException] = []

    def run(k: int) -> None:
        try:
            for t in range(300):
                now = np.array([[3.0 + 0.01 * t, 0.5 * (-1) ** k]])
                pred = np.repeat(now[None], n + 1, axis=0)
                results[k].append(solver.step([0.02 * t, 0, 0, 0.5], [8, 0, 0, 0.8], now, pred, obstacle=[4.0, 1.5]))
                if t % 50 == 0:
                    solver.set_params(q=2.0 + k)
        except BaseException as err:  # reported in the main thread
            errors.append(err)

    threads = [threading.Thread(target=run, args=(k,)) for k in (0, 1)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(timeout=300)
    assert not errors, errors
    assert all(len(r) == 300 for r in results.values())
    for r in results[0] + results[1]:
        assert np.all(np.isfinite(r.u0)) and np.all(np.isfinite(r.command))


def tampered_copy(src: Path, dest: Path) -> Path:
    shutil.copytree(src, dest)
    return dest


def test_a_manifest_pointing_outside_its_package_is_refused(small_dir: Path, tmp_path: Path) -> None:
    d = tampered_copy(small_dir, tmp_path / "outside")
    manifest = json.loads((d / "manifest.json").read_text())
    manifest["library"] = "../../../../../../usr/lib/x86_64-linux-gnu/libm.so.6"
    (d / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(humanmpc.LoadError, match=r"not a \.so inside the package"):
        humanmpc.load(d)


def test_cffi_declarations_that_differ_from_the_compiled_structs_are_refused(small_dir: Path,
                                                                            tmp_path: Path) -> None:
    """A shortened declaration would let cffi allocate a struct smaller than the one C writes."""
    d = tampered_copy(small_dir, tmp_path / "short")
    header = d / "safety_cffi.h"
    text = header.read_text()
    line = next(x for x in text.splitlines() if "time_total_ms;" in x)
    header.write_text(text.replace(line + "\n", ""))
    with pytest.raises(humanmpc.LoadError, match="was compiled with"):
        humanmpc.load(d)


def test_a_manifest_that_is_not_json_is_a_load_error(small_dir: Path, tmp_path: Path) -> None:
    d = tampered_copy(small_dir, tmp_path / "garbled")
    (d / "manifest.json").write_text("{not json")
    with pytest.raises(humanmpc.LoadError, match="not a humanmpc manifest"):
        humanmpc.load(d)
    (d / "manifest.json").write_text(json.dumps({"name": "x; system()"}))
    with pytest.raises(humanmpc.LoadError, match="not a C identifier"):
        humanmpc.load(d)


def _load_in_a_child(solver_dir: Path) -> subprocess.CompletedProcess[str]:
    """load() in another process: on the old binding a truncated library killed it with SIGBUS."""
    code = ("import sys, humanmpc\n"
            "try:\n    humanmpc.load(sys.argv[1], build_if_needed=False)\n"
            "except humanmpc.LoadError as err:\n    print(err); sys.exit(3)\n")
    return subprocess.run([sys.executable, "-c", code, str(solver_dir)], capture_output=True, text=True,
                          timeout=120, check=False)


@pytest.mark.parametrize("keep", [0.5, 0.95])
def test_a_truncated_library_is_refused_before_dlopen(small_dir: Path, tmp_path: Path, keep: float) -> None:
    """A library cut short (a full disk, an interrupted copy) gave SIGBUS inside dlopen: now a LoadError
    that names it, whoever built it (the ELF file's own segments), and before that build()'s record."""
    d = tmp_path / "safety"
    shutil.copytree(small_dir, d)
    lib = d / "build" / "libsafety.so"
    data = lib.read_bytes()
    for recorded in (True, False):
        if not recorded:
            (d / "build" / "libsafety.so.record.json").unlink()
        lib.write_bytes(data[: int(len(data) * keep)])
        proc = _load_in_a_child(d)
        assert proc.returncode == 3, (proc.returncode, proc.stderr[-2000:])
        assert "libsafety.so" in proc.stdout and ("cut short" in proc.stdout or "not the library" in proc.stdout)


def test_an_altered_library_of_the_same_size_is_refused(small_dir: Path, tmp_path: Path) -> None:
    d = tmp_path / "safety"
    shutil.copytree(small_dir, d)
    lib = d / "build" / "libsafety.so"
    data = bytearray(lib.read_bytes())
    data[-10] ^= 0xFF
    lib.write_bytes(bytes(data))
    proc = _load_in_a_child(d)
    assert proc.returncode == 3 and "is not the library that was built" in proc.stdout, proc.stdout + proc.stderr
    lib.write_bytes(bytes(data[:-10]) + bytes([data[-10] ^ 0xFF]) + bytes(data[-9:]))
    assert _load_in_a_child(d).returncode == 0
