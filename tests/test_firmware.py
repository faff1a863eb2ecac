"""The generated solver as Cortex-M firmware under QEMU (humanmpc.firmware, templates/firmware/).

Real parts only: Debian's arm-none-eabi-gcc and newlib, qemu-system-arm on the MPS2 boards
(mps2-an500: Cortex-M7 with a double-precision FPU; mps2-an386: Cortex-M4F, single precision),
semihosting for the console, SysTick under -icount for instruction counts.

What is compared, and why so:

* cold replays (the solver reset before every step) make each step depend on its own inputs only:
  there the Cortex-M7 double build must reproduce the x86-64 host to 1e-9 (in practice the two
  agree bit for bit on most steps; the differences come from newlib's sin/cos/exp against glibc's,
  which differ in the last bit for some arguments).
* warm replays (the warm start kept, as in use) feed those last-bit differences back through the
  real-time iteration. With the paper's zero control weights the full-step RTI amplifies a 1e-15
  perturbation of x0 to 1e-2 in u0 within 40 steps on the host alone, so no two builds agree
  to 1e-9 over a long warm replay; what must agree there are the decisions (status, protective
  stop and its reason, QP status) at every step.
* single precision: the float builds are compared with FLOAT_U0_TOL (see test_float_precision.py).
"""

from __future__ import annotations

import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.compare.replay import Replay
from humanmpc.firmware import image as fw

from .conftest import make_solver, require_tool

STEPS = 60
SEED = 1  # a crowd whose replay holds both solved steps and protective stops (checked below)
# Single precision against double, per step of a cold replay: u0 within 0.05 (2.5 % of the
# acceleration range, 1.7 % of the turn-rate range: over one 0.1 s interval at most 2.5 mm and 0.3
# degrees of difference in the robot's motion, against d_h = 0.5 m), and half of the steps within
# 1e-5. The QP is solved to qp_tol = 1e-6 and its Hessian has almost no curvature in omega (zero
# control weight, 1e-6 regularization), so a float-sized perturbation may move omega far more than
# 1e-7 on the few steps where the cost is flat in it; the median shows the typical agreement.
FLOAT_U0_TOL = 0.05
FLOAT_U0_MEDIAN_TOL = 1e-5


@dataclass
class FwResult:
    run: fw.FirmwareRun
    elf: Path  # a copy: later builds of the same folder overwrite the original
    host: list  # the host library of the same package on the same replay
    host_double: list  # the double host library on the same replay


@pytest.fixture(scope="session")
def tools() -> None:
    for t in fw.TOOLS:
        require_tool(t)


@pytest.fixture(scope="session")
def fw_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("firmware")


@pytest.fixture(scope="session")
def double_dir(fw_root: Path) -> Path:
    """The paper's spec, double precision."""
    return make_solver(fw_root, {"name": "fwd"})


@pytest.fixture(scope="session")
def float_dir(fw_root: Path) -> Path:
    """The paper's spec in single precision."""
    return make_solver(fw_root, {"name": "fwf", "precision": "float"})


@pytest.fixture(scope="session")
def replay(double_dir: Path) -> Replay:
    return fw.record_replay(humanmpc.load(double_dir), steps=STEPS, seed=SEED)


def _firmware(solver_dir: Path, double_dir: Path, cpu: str, replay: Replay, cold: bool, out: Path) -> FwResult:
    fw_dir = fw.write_firmware(solver_dir, replay, cold=cold)
    elf = fw.build_firmware(fw_dir, cpu, "replay")
    kept = out / f"{solver_dir.name}_{cpu}_{'cold' if cold else 'warm'}.elf"
    shutil.copy2(elf, kept)
    run = fw.parse_replay_output(fw.run_qemu(kept, cpu, timeout=300))
    host = fw.host_results(humanmpc.load(solver_dir), replay, cold=cold)
    host_double = host if solver_dir == double_dir else fw.host_results(humanmpc.load(double_dir), replay, cold=cold)
    return FwResult(run, kept, host, host_double)


@pytest.fixture(scope="session")
def m7_double(tools: None, double_dir: Path, replay: Replay, fw_root: Path) -> dict[str, FwResult]:
    return {mode: _firmware(double_dir, double_dir, "cortex-m7", replay, mode == "cold", fw_root)
            for mode in ("cold", "warm")}


@pytest.fixture(scope="session")
def m4_float(tools: None, float_dir: Path, double_dir: Path, replay: Replay, fw_root: Path) -> dict[str, FwResult]:
    return {mode: _firmware(float_dir, double_dir, "cortex-m4", replay, mode == "cold", fw_root)
            for mode in ("cold", "warm")}


def _decisions(steps: list) -> list[tuple[int, int, int, int]]:
    return [(int(s.status), int(s.stop), int(s.stop_reason), int(s.qp_status)) for s in steps]


def _stops(steps: list) -> list[tuple[int, int]]:
    """The stop decisions: protective stop or not, and its reason."""
    return [(int(s.stop), int(s.stop_reason)) for s in steps]


def _u0_diff(run: fw.FirmwareRun, host: list) -> np.ndarray:
    return np.array([np.max(np.abs(np.asarray(s.u0) - h.u0)) for s, h in zip(run.steps, host, strict=True)])


# -- the replay itself --------------------------------------------------------------------------


def test_replay_holds_solved_steps_and_protective_stops(double_dir: Path, replay: Replay) -> None:
    host = fw.host_results(humanmpc.load(double_dir), replay)
    stops = [h.stop_reason for h in host if h.stop]
    assert replay.steps == STEPS and int(np.max(replay.n_humans)) == 10
    assert len(stops) >= 3, "the replay should exercise the protective stop"
    assert sum(h.status == 0 and not h.stop for h in host) >= 20, "the replay should mostly solve"
    assert {6} <= set(stops), "a human within d_h of the robot (C2) is part of the replay"


# -- Cortex-M7, double precision ----------------------------------------------------------------


def test_m7_double_reproduces_the_host_to_1e9_on_a_cold_replay(m7_double: dict[str, FwResult]) -> None:
    r = m7_double["cold"]
    assert len(r.run.steps) == STEPS >= 50
    assert _decisions(r.run.steps) == _decisions(r.host)
    assert [s.qp_iterations for s in r.run.steps] == [h.qp_iterations for h in r.host]
    for s, h in zip(r.run.steps, r.host, strict=True):
        assert np.max(np.abs(np.asarray(s.u0) - h.u0)) <= 1e-9, f"step {s.t}: u0 {s.u0} vs host {h.u0}"
        assert np.max(np.abs(np.asarray(s.command) - h.command)) <= 1e-9
        assert np.max(np.abs(np.asarray(s.x_end) - h.x[-1, :2])) <= 1e-9, f"step {s.t}: plan end differs"
        assert abs(s.cost - h.cost) <= 1e-9 * max(1.0, abs(h.cost))
        if np.isfinite(h.min_human_distance):
            assert abs(s.min_human_distance - h.min_human_distance) <= 1e-9


def test_m7_double_makes_the_hosts_decisions_on_a_warm_replay(m7_double: dict[str, FwResult]) -> None:
    r = m7_double["warm"]
    assert len(r.run.steps) == STEPS
    assert _decisions(r.run.steps) == _decisions(r.host)
    assert all(np.all(np.isfinite(s.u0)) for s in r.run.steps)


def test_instruction_counts_are_calibrated_and_repeatable(m7_double: dict[str, FwResult]) -> None:
    run = m7_double["cold"].run
    assert run.calib_instructions / run.calib_ticks == pytest.approx(fw.INSN_PER_TICK, abs=0.05)
    solved = [s.instructions for s in run.steps if s.status == 0]
    assert min(solved) > 100_000  # an RTI step is hundreds of thousands of instructions at least
    again = fw.parse_replay_output(fw.run_qemu(m7_double["cold"].elf, "cortex-m7", timeout=300))
    assert [s.ticks for s in again.steps] == [s.ticks for s in run.steps]  # -icount: deterministic


# -- Cortex-M4F, single precision ---------------------------------------------------------------


def test_m4_float_makes_the_float_hosts_decisions(m4_float: dict[str, FwResult]) -> None:
    for mode in ("cold", "warm"):
        r = m4_float[mode]
        assert r.run.real == "float" and len(r.run.steps) == STEPS
        assert _stops(r.run.steps) == _stops(r.host), mode


def test_m4_float_stays_within_the_float_tolerance_of_both_hosts(m4_float: dict[str, FwResult]) -> None:
    r = m4_float["cold"]
    assert _stops(r.run.steps) == _stops(r.host_double)
    for host in (r.host, r.host_double):
        du = _u0_diff(r.run, host)
        assert du.max() <= FLOAT_U0_TOL, f"step {int(du.argmax())}: |u0 diff| {du.max():.3g}"
        assert np.median(du) <= FLOAT_U0_MEDIAN_TOL


def test_float_image_links_no_heap_and_no_double_precision(m4_float: dict[str, FwResult], float_dir: Path) -> None:
    replay_elf = m4_float["warm"].elf
    footprint_elf = fw.build_firmware(float_dir / "firmware", "cortex-m4", "footprint")
    for elf in (replay_elf, footprint_elf):
        found = fw.forbidden_symbols(elf, "float")
        assert found == {"heap": [], "double_math": [], "soft_double": []}, f"{elf.name}: {found}"
        syms = fw.linked_symbols(elf)
        assert {"sinf", "cosf", "expf"} <= syms  # the single-precision math is there: the check is not vacuous
        assert "fwf_solver_step" in syms


def test_double_image_links_no_heap(m7_double: dict[str, FwResult]) -> None:
    assert fw.forbidden_symbols(m7_double["cold"].elf, "double") == {"heap": []}
    assert {"sin", "cos", "exp"} <= fw.linked_symbols(m7_double["cold"].elf)


# -- footprint ----------------------------------------------------------------------------------


@dataclass
class Footprint:
    size: fw.ImageSize
    solver_bytes: int
    line: str


@pytest.fixture(scope="session")
def footprints(tools: None, double_dir: Path, float_dir: Path, replay: Replay) -> dict[str, Footprint]:
    out = {}
    for key, d, cpu in (("double", double_dir, "cortex-m7"), ("float", float_dir, "cortex-m4")):
        elf = fw.build_firmware(fw.write_firmware(d, replay), cpu, "footprint")
        line = next(ln for ln in fw.run_qemu(elf, cpu, timeout=120).splitlines() if ln.startswith("footprint "))
        out[key] = Footprint(fw.image_size(elf), int(line.split()[4]), line)
    return out


def test_footprint_programs_solve_and_count_the_solver_in_ram(footprints: dict[str, Footprint]) -> None:
    for key, fp in footprints.items():
        f = fp.line.split()
        assert (int(f[5]), int(f[10])) == (0, 0), f"{key}: cold and warm step should solve: {fp.line}"
        assert fp.size.ram >= fp.solver_bytes > 100_000, key  # the static solver is in .bss
        assert fp.size.flash < 256 * 1024, f"{key}: the solver alone should fit a 256 KiB flash"
    # single precision halves the reals (ints and pointers aside)
    assert footprints["float"].solver_bytes < 0.55 * footprints["double"].solver_bytes


# -- command line and errors --------------------------------------------------------------------


def test_cli_firmware_runs_a_replay_and_compares(tools: None, fw_root: Path) -> None:
    d = make_solver(fw_root, {"name": "fwcli", "humans": {"max": 3}})
    gen = shutil.which("humanmpc-gen") or str(Path(__file__).resolve().parents[1] / ".venv/bin/humanmpc-gen")
    proc = subprocess.run([gen, "firmware", str(d), "--cpu", "cortex-m7", "--steps", "6", "--seed", "2"],
                          capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    assert "instructions per RTI step (QEMU icount, not cycles)" in proc.stdout
    assert "same status/stop decisions: True" in proc.stdout
    assert len([ln for ln in proc.stdout.splitlines() if ln.strip()[:1].isdigit()]) == 6


def test_missing_toolchain_is_reported_with_the_install_command(monkeypatch: pytest.MonkeyPatch) -> None:
    real_which = shutil.which
    monkeypatch.setattr(fw.shutil, "which", lambda t: None if t == "qemu-system-arm" else real_which(t))
    with pytest.raises(fw.FirmwareError, match=r"qemu-system-arm not found.*apt-get install --no-install-recommends"):
        fw.require_tools()


def test_unknown_cpu_is_refused(tools: None, double_dir: Path, replay: Replay) -> None:
    with pytest.raises(fw.FirmwareError, match="unknown CPU 'cortex-m3'"):
        fw.build_firmware(double_dir / "firmware", "cortex-m3")
    fw_dir = fw.write_firmware(double_dir, replay)
    proc = subprocess.run(["make", "-C", str(fw_dir), "CPU=cortex-m3"], capture_output=True, text=True, check=False)
    assert proc.returncode != 0 and "CPU must be cortex-m4 or cortex-m7" in proc.stderr


def test_a_replay_of_another_size_is_refused(double_dir: Path, fw_root: Path) -> None:
    small = make_solver(fw_root, {"name": "fwsmall", "humans": {"max": 2}}, built=False)
    other = fw.record_replay(humanmpc.load(double_dir), steps=2, seed=0)
    with pytest.raises(fw.FirmwareError, match=r"up to 10 humans; the solver handles N_h = 2"):
        fw.write_firmware(small, other)
