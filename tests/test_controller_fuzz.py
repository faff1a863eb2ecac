"""The navigation controller in C under a property fuzzer (tests/c/fuzz_controller.c): more tracks than the
OCP sees, covariances, people within d_h whatever the controller is doing, reversing robots, parameter
changes, missed deadlines and unusable inputs; its oracle holds at every step. Short runs here, with gcc
and clang under the address and undefined-behaviour sanitizers; a long run on demand:
``HUMANMPC_FUZZ_STEPS=200000 pytest tests/test_controller_fuzz.py -k long`` (docs/reliability.md).
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

from .c_harness import SANITIZE, build_harness
from .conftest import make_solver


@pytest.fixture(scope="module")
def fuzz_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The default spec (N_h = 10, 32 tracks) under another name."""
    return make_solver(tmp_path_factory.mktemp("cfuzz"), {"name": "cfuzz"}, built=False)


def build(solver_dir: Path, exe: Path, cc: str, flags: list[str]) -> Path:
    return build_harness("fuzz_controller.c", solver_dir, exe, cc, ["-D_DEFAULT_SOURCE", *flags])


def run(exe: Path, steps: int, seed: int, timeout: float) -> dict[str, int]:
    proc = subprocess.run([str(exe), str(steps), str(seed)], capture_output=True, text=True, timeout=timeout,
                          check=False)
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-4000:]}"
    print(proc.stdout)
    counts = {m[0]: int(m[1]) for m in re.findall(r"^doing (.+?)\s+steps\s+\d+\s+with someone within d_h\s+(\d+)",
                                                  proc.stdout, re.M)}
    counts["steps"] = int(re.search(r"^steps (\d+);", proc.stdout, re.M)[1])  # type: ignore[index]
    assert "violations 0" in proc.stdout
    return counts


@pytest.mark.parametrize("cc", ["gcc", "clang"])
def test_the_controller_keeps_its_guarantees_under_fuzzing_and_sanitizers(fuzz_dir: Path, tmp_path: Path,
                                                                         cc: str) -> None:
    exe = build(fuzz_dir, tmp_path / f"fuzz_{cc}", cc, ["-O1", *SANITIZE])
    counts = run(exe, 4000, 3 if cc == "gcc" else 4, timeout=900)
    assert counts["steps"] == 4000
    # someone within d_h while following, at the goal, turning there and without a goal: all stopped
    for doing in ("following", "at the goal", "turning at the goal", "no goal"):
        assert counts[doing] > 0, (doing, counts)


def test_the_fuzz_oracle_catches_someone_within_d_h_without_a_stop(fuzz_dir: Path, tmp_path: Path) -> None:
    """The oracle can fail: outputs whose stop is taken away while someone is within d_h are reported."""
    exe = build(fuzz_dir, tmp_path / "fuzz_tamper", "gcc", ["-O2"])
    proc = subprocess.run([str(exe), "20000", "1", "tamper"], capture_output=True, text=True, timeout=300,
                          check=False)
    assert proc.returncode == 1 and "someone within d_h and no stop" in proc.stderr, proc.stderr[-2000:]


@pytest.mark.skipif(not os.environ.get("HUMANMPC_FUZZ_STEPS"), reason="long run on demand: HUMANMPC_FUZZ_STEPS=N")
def test_long_fuzz_run_of_the_controller(fuzz_dir: Path, tmp_path: Path) -> None:
    exe = build(fuzz_dir, tmp_path / "fuzz_long", "gcc", ["-O2"])
    steps = int(os.environ["HUMANMPC_FUZZ_STEPS"])
    counts = run(exe, steps, int(os.environ.get("HUMANMPC_FUZZ_SEED", "1")), timeout=24 * 3600)
    assert counts["steps"] == steps
