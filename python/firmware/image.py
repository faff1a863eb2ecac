"""The generated solver as firmware: Cortex-M4/M7 builds run under QEMU, footprint and instruction counts.

``humanmpc-gen firmware DIR --cpu cortex-m4|cortex-m7`` writes ``DIR/firmware/`` (start-up code,
linker script, a replay program with a recorded input sequence embedded as constant arrays, a
footprint program, a Makefile), cross-compiles it with Debian's ``arm-none-eabi-gcc`` (hard float;
no start files, no syscalls, so nothing that needs malloc or stdio can link), runs it under
``qemu-system-arm`` on an MPS2 board with semihosting and ``-icount shift=0``, and compares what
the firmware computed with the host library on the same inputs.

Instruction counts: under ``-icount shift=0`` QEMU advances its virtual clock by 1 ns per guest
instruction, and the MPS2 SysTick counts at 25 MHz, so one SysTick tick is 40 instructions; the
firmware measures this ratio itself (a loop of known length) and the parser checks it. These are
counts of executed instructions, not cycles: QEMU models no pipeline, no flash wait states and no
FPU latencies.

``humanmpc-gen firmware-report`` builds the table of docs/firmware.md: flash and RAM for several
N_h on both CPUs and both precisions, and the instructions per RTI step on a replay.
"""

from __future__ import annotations

import math
import shutil
import struct
import subprocess
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..bindings import load
from ..codegen import __version__
from ..codegen.build import read_manifest
from ..codegen.render import make_environment
from ..codegen.spec import Spec, load_spec
from ..solver import implied_velocities

if TYPE_CHECKING:
    from ..compare.replay import Replay
    from ..solver import Solver, StepResult

# -- targets ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CpuTarget:
    cpu: str
    machine: str  # qemu-system-arm -M
    fpu: str
    description: str


CPUS: dict[str, CpuTarget] = {
    "cortex-m4": CpuTarget("cortex-m4", "mps2-an386", "fpv4-sp-d16",
                           "Cortex-M4F: single-precision FPU; double is soft-float (libgcc __aeabi_d*)"),
    "cortex-m7": CpuTarget("cortex-m7", "mps2-an500", "fpv5-d16", "Cortex-M7: double-precision FPU"),
}

# -icount shift=0: 1 ns of virtual time per instruction; MPS2 SysTick: 25 MHz, 40 ns per tick.
INSN_PER_TICK = 40
APT_HINT = ("install them with: apt-get install --no-install-recommends gcc-arm-none-eabi "
            "libnewlib-arm-none-eabi qemu-system-arm (or `make test`, which does it)")
TOOLS = ("arm-none-eabi-gcc", "arm-none-eabi-size", "arm-none-eabi-nm", "qemu-system-arm", "make")

# Rendered into DIR/firmware/: template -> file.
FIRMWARE_TEMPLATES = {
    "firmware/Makefile.j2": "Makefile",
    "firmware/mps2.ld.j2": "mps2.ld",
    "firmware/fw.h.j2": "fw.h",
    "firmware/startup.c.j2": "startup.c",
    "firmware/replay_main.c.j2": "replay_main.c",
    "firmware/footprint_main.c.j2": "footprint_main.c",
    "firmware/replay_data.h.j2": "replay_data.h",
    "firmware/replay_data.c.j2": "replay_data.c",
}

# Symbols that must not be in a float image: heap, double-precision libm, soft-float double helpers.
HEAP_SYMBOLS = frozenset({"malloc", "free", "calloc", "realloc", "_malloc_r", "_free_r", "_sbrk", "_sbrk_r"})
DOUBLE_MATH_SYMBOLS = frozenset({
    "sin", "cos", "tan", "sincos", "exp", "log", "sqrt", "pow", "fabs", "fmax", "fmin", "atan2", "tanh",
    "floor", "ceil", "__ieee754_sqrt", "__ieee754_exp", "__ieee754_log", "__ieee754_pow", "__kernel_sin",
    "__kernel_cos", "__ieee754_rem_pio2",
})


class FirmwareError(RuntimeError):
    """The cross build or the QEMU run failed; the message says what to do."""


def require_tools() -> dict[str, str]:
    """The path of every tool the firmware build needs, or FirmwareError naming the missing ones."""
    found = {t: shutil.which(t) for t in TOOLS}
    missing = [t for t, p in found.items() if p is None]
    if missing:
        raise FirmwareError(f"{', '.join(missing)} not found on PATH: {APT_HINT}")
    return {t: str(p) for t, p in found.items()}


def cpu_target(cpu: str) -> CpuTarget:
    if cpu not in CPUS:
        raise FirmwareError(f"unknown CPU {cpu!r}: choose one of {', '.join(CPUS)}")
    return CPUS[cpu]


# -- a recorded input sequence ------------------------------------------------------------------


def package_spec(solver_dir: Path) -> Spec:
    """The resolved spec a generated package was made from (its spec.yaml)."""
    return load_spec(Path(solver_dir) / "spec.yaml")


# A replay compares arithmetic, not time: the host runs with the deadline at its largest (as the
# controller replay, firmware/controller.py REPLAY_PARAMS), so that a loaded machine cannot turn a
# slow step into a deadline stop that the other side (or the firmware, which has no clock) never makes.
REPLAY_DEADLINE_MS = 1e5


@contextmanager
def without_deadline(solver: Solver) -> Iterator[Solver]:
    """The solver with deadline_ms at REPLAY_DEADLINE_MS inside the block, its own value after."""
    before = solver.params["deadline_ms"]
    solver.set_params(deadline_ms=REPLAY_DEADLINE_MS)
    try:
        yield solver
    finally:
        solver.set_params(deadline_ms=before)


def record_replay(solver: Solver, *, steps: int = 60, seed: int = 0, n_humans: int | None = None,
                  goal_distance: float = 8.0) -> Replay:
    """A closed loop driven by ``solver`` (the host library), recorded as a replay.

    The robot starts at rest at the origin, heading to (goal_distance, 0) at 0.8 m/s. ``n_humans``
    people (default: the solver's N_h) walk at constant velocity and bounce off the box
    [1, goal_distance + 1] x [-3, 3]; the first walks head-on at the robot, so the loop holds close
    encounters and protective stops. A disc of radius 0.3 m lies beside the way; the obstacle input
    is its closest point. Predictions are constant-velocity, the robot moves by the model itself
    under u0.
    """
    from ..compare.replay import Replay

    spec = package_spec(solver.path)
    nh = spec.humans.max if n_humans is None else n_humans
    if not 0 <= nh <= spec.humans.max:
        raise ValueError(f"n_humans = {nh} must be in [0, N_h = {spec.humans.max}]")
    if steps < 1:
        raise ValueError(f"steps = {steps} must be >= 1")
    rng = np.random.default_rng(seed)
    N, dt = spec.horizon.N, spec.dt
    lo, hi = np.array([1.0, -3.0]), np.array([goal_distance + 1.0, 3.0])
    pos = np.zeros((nh, 2))
    for i in range(nh):
        for _ in range(10_000):
            pos[i] = rng.uniform(lo, hi)
            if np.linalg.norm(pos[i]) >= 1.5:
                break
    heading = rng.uniform(-np.pi, np.pi, nh)
    vel = np.stack([np.cos(heading), np.sin(heading)], axis=1) * rng.uniform(0.3, 1.0, nh)[:, None]
    if nh:
        pos[0], vel[0] = (0.45 * goal_distance, 0.05), (-0.6, 0.0)
    centre, radius = np.array([0.5 * goal_distance, -1.0]), 0.3
    x = np.zeros(4)
    goal = np.array([goal_distance, 0.0, 0.0, 0.8])
    solver.reset()
    records: list[dict[str, Any]] = []
    with without_deadline(solver):
        for _ in range(steps):
            pred = pos[None] + vel[None] * (dt * np.arange(N + 1))[:, None, None]
            d = x[:2] - centre
            obstacle = centre + radius * d / max(float(np.linalg.norm(d)), 1e-9)
            rec = {"x0": x.copy(), "goal": goal.copy(), "humans_now": pos.copy(), "humans_pred": pred,
                   "obstacle": obstacle}
            records.append(rec)
            r = solver.step(**rec)
            x = np.asarray(solver.model.dynamics(x, r.u0).x_next, dtype=np.float64)
            pos = pos + vel * dt
            out = (pos < lo) | (pos > hi)
            vel = np.where(out, -vel, vel)
            pos = np.clip(pos, lo, hi)
    solver.reset()
    return Replay.from_steps(records, spec, scenario=f"firmware-crowd-{nh}-humans", seed=seed)


# -- writing and building -----------------------------------------------------------------------


def _hex(v: float, real: str) -> str:
    """An exact C99 hexadecimal floating literal of v in the solver's real type."""
    if not math.isfinite(v):
        raise FirmwareError(f"{v!r} cannot be embedded in the firmware: not finite")
    if real == "float":
        return float(np.float32(v)).hex() + "f"
    return float(v).hex()


def _rows(values: np.ndarray, real: str, per_row: int) -> str:
    """Nested C initializer of a (rows, ...) array, one row per line."""
    flat = values.reshape(values.shape[0], -1)
    if flat.shape[0] == 0:
        return "    {" + ", ".join(["0"] * per_row) + "}"  # C has no empty arrays: one unused row
    lines = []
    for row in flat:
        lines.append("    {" + ", ".join(_hex(float(v), real) for v in row) + "}")
    return ",\n".join(lines)


def _pred_rows(pred: np.ndarray, real: str) -> str:
    """(rows, N+1, 2) -> { {x, y}, ... } per row."""
    if pred.shape[0] == 0:
        return "    {{0}}"
    return ",\n".join(
        "    {" + ", ".join("{" + _hex(float(p[0]), real) + ", " + _hex(float(p[1]), real) + "}" for p in row) + "}"
        for row in pred
    )


def replay_context(replay: Replay, real: str) -> dict[str, Any]:
    """What replay_data.c/h need: the present humans only, packed step after step."""
    T = replay.steps
    ks = [int(k) for k in replay.n_humans]
    offsets = np.concatenate([[0], np.cumsum(ks)[:-1]]).astype(int) if T else np.zeros(0, int)
    now = np.concatenate([replay.humans_now[t, :k] for t, k in enumerate(ks)]) if sum(ks) else np.zeros((0, 2))
    pred = (np.concatenate([replay.humans_pred[t, :, :k].transpose(1, 0, 2) for t, k in enumerate(ks)])
            if sum(ks) else np.zeros((0, replay.N + 1, 2)))
    # the replay holds predictions only: the velocities the host's Solver.step derives from them
    vel = (np.concatenate([implied_velocities(replay.humans_pred[t, :, :k], replay.dt) for t, k in enumerate(ks)])
           if sum(ks) else np.zeros((0, 2)))
    params = []
    for key, value in replay.params.items():
        if isinstance(value, list | tuple):
            params += [f"params->{key}[{i}] = {_hex(float(v), real)};" for i, v in enumerate(value)]
        else:
            params.append(f"params->{key} = {_hex(float(value), real)};")
    return {
        "steps": T,
        "scenario": replay.scenario or "recorded",
        "human_rows": max(1, sum(ks)),
        "n_humans": ", ".join(str(k) for k in ks),
        "human_offset": ", ".join(str(int(o)) for o in offsets),
        "has_obstacle": ", ".join("1" if h else "0" for h in replay.has_obstacle),
        "x0": _rows(replay.x0, real, 4),
        "goal": _rows(replay.goal, real, 4),
        "obstacle": _rows(replay.obstacle, real, 2),
        "humans_now": _rows(now, real, 2),
        "humans_vel": _rows(vel, real, 2),
        "humans_pred": _pred_rows(pred, real),
        "params": params,
    }


def check_replay_fits(replay: Replay, solver_dir: Path) -> None:
    dims = read_manifest(solver_dir).dims
    problems = []
    if dims.N != replay.N or abs(replay.dt - dims.dt) > 1e-12:
        problems.append(f"the replay has N={replay.N}, dt={replay.dt:g}; the solver N={dims.N}, dt={dims.dt:g}")
    if int(np.max(replay.n_humans, initial=0)) > dims.nh:
        problems.append(f"the replay has up to {int(np.max(replay.n_humans))} humans; the solver handles "
                        f"N_h = {dims.nh}")
    if problems:
        raise FirmwareError(f"the replay does not fit the solver in {solver_dir}: " + "; ".join(problems))


def write_firmware(solver_dir: str | Path, replay: Replay, *, cold: bool = False) -> Path:
    """Render DIR/firmware/ for the package in solver_dir and the given replay; return its path.

    cold: every step starts from a reset solver (each step depends on its own inputs only)."""
    d = Path(solver_dir).resolve()
    m = read_manifest(d)
    check_replay_fits(replay, d)
    name, real = m.name, m.real
    context = {"name": name, "NAME": name.upper(), "version": __version__, "real": real, "cold": cold,
               **replay_context(replay, real)}
    out = d / "firmware"
    out.mkdir(exist_ok=True)
    env = make_environment()
    for tpl, filename in FIRMWARE_TEMPLATES.items():
        text = env.get_template(tpl).render(**context)
        path = out / filename
        if not path.exists() or path.read_text() != text:  # keep mtimes: make rebuilds only what changed
            path.write_text(text)
    return out


def build_firmware(fw_dir: Path, cpu: str, target: str = "replay", *, ram_bytes: int | None = None) -> Path:
    """Cross-compile one program ("replay" or "footprint") of fw_dir for cpu; return the ELF. ram_bytes:
    link it into that much RAM (the stack at its top) instead of the board's 4 MiB; an image that does
    not fit fails with the linker's message."""
    cpu_target(cpu)
    tools = require_tools()
    ram = [f"RAM_BYTES={ram_bytes}"] if ram_bytes else []
    proc = subprocess.run([tools["make"], "-C", str(fw_dir), "--no-print-directory", f"CPU={cpu}", *ram, target],
                          capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-40:])
        raise FirmwareError(f"cross-compiling {fw_dir} for {cpu} failed (make exit {proc.returncode}):\n{tail}")
    return fw_dir / "build" / (f"{cpu}-ram{ram_bytes}" if ram_bytes else cpu) / f"{target}.elf"


def run_qemu(elf: Path, cpu: str, *, timeout: float = 600.0) -> str:
    """Run an ELF on the MPS2 board of cpu with semihosting and instruction counting; return stdout."""
    target = cpu_target(cpu)
    tools = require_tools()
    cmd = [tools["qemu-system-arm"], "-M", target.machine, "-nographic", "-monitor", "none", "-serial", "none",
           "-semihosting-config", "enable=on,target=native", "-icount", "shift=0", "-kernel", str(elf)]
    try:
        # QEMU writes the semihosting console to its stderr: take both streams, in order.
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=timeout,
                              check=False)
    except subprocess.TimeoutExpired as err:
        raise FirmwareError(f"{elf.name} on {cpu} did not finish within {timeout:g} s under QEMU "
                            f"({' '.join(cmd)})") from err
    if proc.returncode != 0:
        raise FirmwareError(f"{elf.name} on {cpu} exited with status {proc.returncode} under QEMU:\n"
                            f"{proc.stdout.strip()[-2000:]}")
    return proc.stdout


# -- results ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class StepLine:
    """One RTI step as the firmware reported it."""

    t: int
    status: int
    stop: int
    stop_reason: int
    qp_status: int
    qp_iterations: int
    sqp_iterations: int
    u0: tuple[float, float]
    command: tuple[float, float]
    cost: float
    min_human_distance: float
    x_end: tuple[float, float]
    ticks: int

    @property
    def instructions(self) -> int:
        return self.ticks * INSN_PER_TICK


@dataclass
class FirmwareRun:
    """What a replay program printed."""

    name: str
    cpu: str
    real: str
    solver_bytes: int  # sizeof(<name>_solver)
    calib_instructions: int
    calib_ticks: int
    steps: list[StepLine] = field(default_factory=list)

    @property
    def instructions(self) -> np.ndarray:
        return np.array([s.instructions for s in self.steps], dtype=np.int64)

    def u0(self) -> np.ndarray:
        return np.array([s.u0 for s in self.steps])


def hex_real(text: str, real: str) -> float:
    """A real printed by the firmware as the hex of its big-endian bytes (exact, no decimal rounding)."""
    raw = bytes.fromhex(text)
    return float(struct.unpack(">f" if real == "float" else ">d", raw)[0])


def check_calibration(instructions: int, ticks: int) -> None:
    """FirmwareError unless the firmware's SysTick counted INSN_PER_TICK instructions per tick."""
    ratio = instructions / max(ticks, 1)
    if abs(ratio - INSN_PER_TICK) > 0.5:
        raise FirmwareError(f"SysTick calibration: {ratio:.3f} instructions per tick, expected {INSN_PER_TICK} "
                            "(is QEMU running with -icount shift=0?)")


def parse_replay_output(text: str) -> FirmwareRun:
    """Parse the replay program's console output; FirmwareError when it is incomplete or inconsistent."""
    lines = text.splitlines()
    begin = [ln.split() for ln in lines if ln.startswith("begin ")]
    calib = [ln.split() for ln in lines if ln.startswith("calib ")]
    if not begin or not calib or "end" not in lines:
        raise FirmwareError("the firmware output is incomplete (no begin/calib/end line):\n" + text[-2000:])
    _, name, cpu, real, n_steps, solver_bytes = begin[0]
    run = FirmwareRun(name, cpu, real, int(solver_bytes), int(calib[0][1]), int(calib[0][2]))
    check_calibration(run.calib_instructions, run.calib_ticks)
    for ln in lines:
        if not ln.startswith("step "):
            continue
        f = ln.split()
        ints = [int(v) for v in f[1:8]]
        reals = [hex_real(v, real) for v in f[8:16]]
        run.steps.append(StepLine(ints[0], ints[1], ints[2], ints[3], ints[4], ints[5], ints[6],
                                  (reals[0], reals[1]), (reals[2], reals[3]), reals[4], reals[5],
                                  (reals[6], reals[7]), int(f[16])))
    if len(run.steps) != int(n_steps):
        raise FirmwareError(f"the firmware reported {len(run.steps)} steps of {n_steps}")
    return run


@dataclass(frozen=True)
class ImageSize:
    text: int
    data: int
    bss: int

    @property
    def flash(self) -> int:
        return self.text + self.data

    @property
    def ram(self) -> int:
        return self.data + self.bss


def image_size(elf: Path) -> ImageSize:
    """Berkeley sizes of an ELF (arm-none-eabi-size): text (code + constants), data, bss."""
    out = subprocess.run([require_tools()["arm-none-eabi-size"], str(elf)], capture_output=True, text=True,
                         check=True).stdout.splitlines()
    text, data, bss = (int(v) for v in out[1].split()[:3])
    return ImageSize(text, data, bss)


def linked_symbols(elf: Path) -> set[str]:
    """Names of the symbols defined in an ELF (arm-none-eabi-nm)."""
    out = subprocess.run([require_tools()["arm-none-eabi-nm"], str(elf)], capture_output=True, text=True,
                         check=True).stdout
    return {f[-1] for f in (ln.split() for ln in out.splitlines()) if len(f) >= 2 and f[-2] not in ("U", "w")}


def forbidden_symbols(elf: Path, real: str) -> dict[str, list[str]]:
    """Heap symbols, and for a float image double-precision libm and soft-double helpers, found in elf."""
    syms = linked_symbols(elf)
    found = {"heap": sorted(syms & HEAP_SYMBOLS)}
    if real == "float":
        found["double_math"] = sorted(syms & DOUBLE_MATH_SYMBOLS)
        found["soft_double"] = sorted(s for s in syms if s.startswith("__aeabi_d") or s in (
            "__aeabi_f2d", "__aeabi_d2f", "__adddf3", "__muldf3", "__divdf3", "__subdf3", "__extendsfdf2"))
    return found


# -- host comparison ----------------------------------------------------------------------------


def host_results(solver: Solver, replay: Replay, *, cold: bool = False) -> list[StepResult]:
    """The host library on the same replay (fresh start, the replay's parameters); cold: reset before
    every step, as the firmware does with cold=True."""
    from ..compare.replay import replay_solver

    with without_deadline(solver):
        if not cold:
            return list(replay_solver(solver, replay, keep_results=True).results)
        solver.set_params(**replay.params)
        results = []
        for t in range(replay.steps):
            solver.reset()
            results.append(solver.step(**replay.inputs(t)))
        return results


@dataclass(frozen=True)
class Agreement:
    """Firmware against host on one replay."""

    steps: int
    max_u0_diff: float  # max over steps of |u0_fw - u0_host| (inf-norm)
    max_cost_rel_diff: float
    same_decisions: bool  # status, stop, stop_reason and qp_status equal at every step
    same_qp_iterations: bool
    first_mismatch: str


def compare_with_host(run: FirmwareRun, host: Sequence[StepResult]) -> Agreement:
    if len(host) != len(run.steps):
        raise FirmwareError(f"host has {len(host)} steps, firmware {len(run.steps)}")
    du, dc, same, same_it, first = 0.0, 0.0, True, True, ""
    for s, h in zip(run.steps, host, strict=True):
        du = max(du, float(np.max(np.abs(np.asarray(s.u0) - h.u0))))
        dc = max(dc, abs(s.cost - h.cost) / max(1.0, abs(h.cost)))
        decision = (s.status, s.stop, s.stop_reason, s.qp_status)
        if decision != (h.status, int(h.stop), h.stop_reason, h.qp_status):
            if same:
                first = (f"step {s.t}: firmware (status, stop, reason, qp_status) = {decision}, host "
                         f"{(h.status, int(h.stop), h.stop_reason, h.qp_status)}")
            same = False
        same_it = same_it and s.qp_iterations == h.qp_iterations
    return Agreement(len(host), du, dc, same, same_it, first)


# -- the commands -------------------------------------------------------------------------------


def print_progress(msg: str) -> None:
    print(msg, file=sys.stderr)


def run_firmware(solver_dir: str | Path, cpu: str, replay: Replay | None = None, *, steps: int = 60, seed: int = 0,
                 n_humans: int | None = None, cold: bool = False, timeout: float = 600.0,
                 log: Callable[[str], None] | None = None) -> tuple[FirmwareRun, Agreement, Path]:
    """Record (or take) a replay, build and run it on cpu, compare with the host; (run, agreement, elf)."""
    say = log or print_progress
    d = Path(solver_dir).resolve()
    require_tools()
    host = load(d)
    if replay is None:
        say(f"[humanmpc] recording {steps} steps with the host solver (seed {seed})")
        replay = record_replay(host, steps=steps, seed=seed, n_humans=n_humans)
    fw = write_firmware(d, replay, cold=cold)
    say(f"[humanmpc] cross-compiling {fw} for {cpu}")
    elf = build_firmware(fw, cpu, "replay")
    say(f"[humanmpc] running {elf.name} under qemu-system-arm -M {CPUS[cpu].machine} -icount shift=0")
    t0 = time.perf_counter()
    run = parse_replay_output(run_qemu(elf, cpu, timeout=timeout))
    say(f"[humanmpc] {len(run.steps)} steps in {time.perf_counter() - t0:.1f} s of QEMU")
    return run, compare_with_host(run, host_results(host, replay, cold=cold)), elf


def load_replay_file(path: Path | None) -> Replay | None:
    if path is None:
        return None
    from ..compare.replay import Replay

    return Replay.load(path)
