"""The navigation controller as firmware: a recorded closed loop of the host controller replayed on a
Cortex-M under QEMU (``<name>_controller_step`` per recorded period), compared with the host.

The replay is open loop in its inputs, like the solver's (image.py): the host library drives a
scripted scene (people walking at constant velocity, obstacle points, a path to a goal) through
:class:`humanmpc.controller.Controller`; what the controller was given in every period (time,
odometry, path, goal, tracks with ids and covariances, obstacle points) is recorded and embedded in
the image as constants (exact hexadecimal literals); the firmware calls ``<name>_controller_step``
with them, one period after the other from one controller (its warm start and its progress
history kept, as in use), and prints what it decided. The host library replays the same inputs with
a fresh controller; both sides start from the spec's parameters with the replay's changes applied.

The clock: the firmware installs one with ``<name>_controller_set_clock`` that reads SysTick, i.e.
QEMU's virtual time (1 ns per executed instruction under ``-icount shift=0``), so the controller's
own timings count instructions. The replay runs with ``deadline_ms`` at its largest value on both
sides: a deadline is a decision about time, and the host's time is not the target's; the arithmetic
is what is compared. After the replay the program runs one more period with a deadline of a few
thousand instructions, which must end in the deadline's protective stop: the hook is in force.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..bindings import load
from ..codegen import __version__
from ..codegen.build import read_manifest
from ..codegen.params import PARAMS
from ..codegen.render import make_environment
from .image import (
    CPUS,
    FIRMWARE_TEMPLATES,
    INSN_PER_TICK,
    FirmwareError,
    build_firmware,
    check_calibration,
    hex_real,
    package_spec,
    print_progress,
    require_tools,
    run_qemu,
)

if TYPE_CHECKING:
    from ..controller import Controller
    from ..results import ControllerResult
    from ..solver import Solver

# Rendered into DIR/firmware/ with the shared files of FIRMWARE_TEMPLATES (start-up, linker script,
# console, Makefile): template -> file.
CONTROLLER_TEMPLATES = {
    "firmware/controller_main.c.j2": "controller_main.c",
    "firmware/controller_footprint_main.c.j2": "controller_footprint_main.c",
    "firmware/controller_data.h.j2": "controller_data.h",
    "firmware/controller_data.c.j2": "controller_data.c",
}
SHARED_TEMPLATES = ("firmware/Makefile.j2", "firmware/mps2.ld.j2", "firmware/fw.h.j2", "firmware/startup.c.j2")

# The replay's changes to the spec's parameters, on both sides: no deadline can fire (1e5 ms is the
# largest deadline_ms the parameter's rule allows: 1e11 instructions of QEMU's virtual time).
REPLAY_PARAMS: dict[str, Any] = {"deadline_ms": 1e5}
# The deadline of the period after the replay that shows the clock hook in force [ms]: 5,000 ns, i.e.
# 5,000 instructions of QEMU's virtual time, far below any real-time iteration.
DEADLINE_PROBE_MS = 0.005

DT = 0.1  # control period of the recorded loop [s]


# -- the recorded inputs ------------------------------------------------------------------------


@dataclass
class ControllerReplay:
    """Controller inputs of T periods; the variable-length parts packed over the periods.

    Row arrays hold the rows of every period one after the other; ``n_*`` says how many belong to
    period t. ``params`` are the runtime parameters that differ from the spec's (C field -> value).
    """

    name: str  # the package the loop was recorded with
    scenario: str
    seed: int
    params: dict[str, Any]
    time: np.ndarray  # (T,) [s]
    pose: np.ndarray  # (T, 3) [x, y, theta]
    v: np.ndarray  # (T,)
    omega: np.ndarray  # (T,)
    goal: np.ndarray  # (T, 3)
    has_goal: np.ndarray  # (T,) int
    n_path: np.ndarray  # (T,) int
    path: np.ndarray  # (sum n_path, 2)
    n_tracks: np.ndarray  # (T,) int
    track_ids: np.ndarray  # (sum n_tracks,) int
    tracks: np.ndarray  # (sum n_tracks, 4) [x, y, vx, vy]
    covariances: np.ndarray  # (sum n_tracks, 3) [sxx, sxy, syy]; NaN rows: no covariance
    n_obstacles: np.ndarray  # (T,) int
    obstacles: np.ndarray  # (sum n_obstacles, 2)

    @property
    def steps(self) -> int:
        return int(self.time.shape[0])

    @staticmethod
    def _slice(counts: np.ndarray, t: int) -> slice:
        start = int(np.sum(counts[:t]))
        return slice(start, start + int(counts[t]))

    def inputs(self, t: int) -> dict[str, Any]:
        """Period t as keyword arguments of Controller.step."""
        p, k, m = self._slice(self.n_path, t), self._slice(self.n_tracks, t), self._slice(self.n_obstacles, t)
        return {
            "t": float(self.time[t]), "pose": self.pose[t], "v": float(self.v[t]), "omega": float(self.omega[t]),
            "path": self.path[p] if self.n_path[t] else None,
            "goal": self.goal[t] if self.has_goal[t] else None,
            "people": self.tracks[k], "ids": self.track_ids[k].astype(np.int64),
            "covariances": self.covariances[k], "obstacles": self.obstacles[m],
        }

    def max_counts(self) -> dict[str, int]:
        return {"controller.max_path_points": int(np.max(self.n_path, initial=0)),
                "controller.max_tracks": int(np.max(self.n_tracks, initial=0)),
                "controller.max_obstacle_points": int(np.max(self.n_obstacles, initial=0))}


def _resample(points: np.ndarray, n: int) -> np.ndarray:
    """n points evenly spaced by arc length along a polyline (its ends kept)."""
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    at = np.linspace(0.0, s[-1], n)
    return np.stack([np.interp(at, s, points[:, 0]), np.interp(at, s, points[:, 1])], axis=1)


def record_controller_replay(solver: Solver, *, steps: int = 140, seed: int = 0, n_people: int | None = None,
                             params: dict[str, Any] | None = None) -> ControllerReplay:
    """A closed loop of the host controller of ``solver``'s package, recorded as a controller replay.

    The scene: the robot starts at rest at the origin and follows a path with a bend to (6, 1.5); a
    wall of obstacle points runs beside its first part. ``n_people`` tracked people (default: the
    solver's N_h + 3, at most the controller's track capacity; more than N_h, so the controller
    chooses) walk at constant velocity and bounce off the box [-1, 8] x [-3, 4]: the first walks
    head-on down the path and the second crosses it (close encounters, protective stops), the third
    stands on the way with a covariance, the rest wander (every other with a covariance). The robot
    moves by the simulation's model (humanmpc.sim.robot) under the controller's u; its measured
    turn rate is the one it applied.
    """
    from ..sim.robot import RobotModel
    from ..sim.robot import step as robot_step

    spec = package_spec(solver.path)
    cap = spec.controller
    if steps < 1:
        raise ValueError(f"steps = {steps} must be >= 1")
    k = min(spec.humans.max + 3, cap.max_tracks) if n_people is None else n_people
    if not 0 <= k <= cap.max_tracks:
        raise ValueError(f"n_people = {k} must be in [0, controller.max_tracks = {cap.max_tracks}]")
    rng = np.random.default_rng(seed)
    path = _resample(np.array([[0.0, 0.0], [3.0, 0.0], [6.0, 1.5]]), min(cap.max_path_points, 16))
    goal = np.array([6.0, 1.5, math.atan2(1.5, 3.0)])
    wall = np.stack([np.linspace(1.0, 3.5, 11), np.full(11, -0.9)], axis=1)
    block = np.array([[4.6, -0.2], [4.8, -0.2], [4.6, 0.0], [4.8, 0.0]])  # beside the path after the bend
    obstacles = np.concatenate([wall, block])[: cap.max_obstacle_points]
    lo, hi = np.array([-1.0, -3.0]), np.array([8.0, 4.0])
    people = np.zeros((k, 4))
    for i in range(k):
        for _ in range(10_000):
            people[i, :2] = rng.uniform(lo, hi)
            if np.linalg.norm(people[i, :2]) >= 1.5:
                break
        heading, speed = rng.uniform(-np.pi, np.pi), rng.uniform(0.2, 0.9)
        people[i, 2:] = speed * np.cos(heading), speed * np.sin(heading)
    scripted = [(3.5, 0.1, -0.7, 0.0), (2.0, -2.5, 0.0, 0.6), (4.3, 0.9, 0.0, 0.0)]
    for i, row in enumerate(scripted[:k]):
        people[i] = row
    cov = np.full((k, 3), np.nan)
    for i in range(2, k, 2):
        cov[i] = (0.01 * (1 + i % 3), 0.002, 0.015)
    ids = np.arange(100, 100 + k, dtype=np.int64)

    ctl = solver.controller()
    changes = {**REPLAY_PARAMS, **(params or {})}
    ctl.set_params(**changes)
    model = RobotModel()
    x = np.zeros(4)
    rec: dict[str, list[Any]] = {key: [] for key in (
        "time", "pose", "v", "omega", "goal", "path", "tracks", "ids", "cov", "obstacles")}
    omega = 0.0
    for n in range(steps):
        t = round(n * DT, 10)
        rec["time"].append(t)
        rec["pose"].append(x[:3].copy())
        rec["v"].append(x[3])
        rec["omega"].append(omega)
        rec["goal"].append(goal)
        rec["path"].append(path)
        rec["tracks"].append(people.copy())
        rec["ids"].append(ids)
        rec["cov"].append(cov)
        rec["obstacles"].append(obstacles)
        r = ctl.step(t, pose=x[:3], v=float(x[3]), omega=omega, path=path, goal=goal, people=people, ids=ids,
                     covariances=cov, obstacles=obstacles)
        u = model.limits.clip_control(r.u)
        omega = float(u[1])
        x = robot_step(model, x, u, DT)
        people[:, :2] += DT * people[:, 2:]
        out = (people[:, :2] < lo) | (people[:, :2] > hi)
        people[:, 2:] = np.where(out, -people[:, 2:], people[:, 2:])
        people[:, :2] = np.clip(people[:, :2], lo, hi)
    T = len(rec["time"])
    return ControllerReplay(
        name=solver.name, scenario=f"firmware-controller-{k}-people", seed=seed, params=changes,
        time=np.array(rec["time"]), pose=np.array(rec["pose"]), v=np.array(rec["v"]),
        omega=np.array(rec["omega"]), goal=np.array(rec["goal"]), has_goal=np.ones(T, dtype=int),
        n_path=np.array([len(p) for p in rec["path"]]), path=np.concatenate(rec["path"]),
        n_tracks=np.full(T, k), track_ids=np.concatenate(rec["ids"]),
        tracks=np.concatenate(rec["tracks"]).reshape(-1, 4), covariances=np.concatenate(rec["cov"]).reshape(-1, 3),
        n_obstacles=np.array([len(o) for o in rec["obstacles"]]),
        obstacles=np.concatenate(rec["obstacles"]).reshape(-1, 2),
    )


# -- the host ------------------------------------------------------------------------------------


def host_controller(solver: Solver, replay: ControllerReplay) -> Controller:
    """A fresh controller of solver's package with the replay's parameters."""
    ctl = solver.controller()
    ctl.set_params(**replay.params)
    return ctl


def host_controller_results(solver: Solver, replay: ControllerReplay, *, cold: bool = False) -> \
        list[ControllerResult]:
    """The host library's controller on the replay's inputs, one period after the other; cold: reset
    before every period, as the firmware does with cold=True."""
    ctl = host_controller(solver, replay)
    out = []
    for t in range(replay.steps):
        if cold:
            ctl.reset()
        out.append(ctl.step(**replay.inputs(t)))
    return out


# -- writing and building -----------------------------------------------------------------------


def _literal(v: float, real: str) -> str:
    """An exact C99 hexadecimal floating literal of v in the solver's real type."""
    if not math.isfinite(v):
        raise FirmwareError(f"{v!r} cannot be embedded in the firmware: not finite")
    return float(np.float32(v)).hex() + "f" if real == "float" else float(v).hex()


def _table(rows: np.ndarray, real: str | None, columns: int) -> str:
    """C initializer lines of a (rows, columns) array (real literals, or ints for real=None); C has
    no empty arrays, so no rows give one row of zeros that nothing reads."""
    flat = np.asarray(rows).reshape(len(rows), -1) if len(rows) else np.zeros((1, columns))

    def cell(v: Any) -> str:
        return str(int(v)) if real is None else _literal(float(v), real)

    if columns == 1:
        return ",\n".join("    " + ", ".join(cell(v) for v in flat[i:i + 8, 0]) for i in range(0, len(flat), 8))
    return ",\n".join("    {" + ", ".join(cell(v) for v in row) + "}" for row in flat)


def _packed(counts: np.ndarray, rows: np.ndarray) -> tuple[list[int], np.ndarray]:
    """Offsets per period into a row table without repeats: a period whose rows equal the previous
    period's points at the same rows (a path or obstacle points that do not change cost nothing)."""
    offsets: list[int] = []
    kept: list[np.ndarray] = []
    start, stored, prev = 0, 0, None
    for c in (int(c) for c in counts):
        block = rows[start:start + c]
        if prev is not None and c and block.shape == prev[1].shape and np.array_equal(block, prev[1]):
            offsets.append(prev[0])
        else:
            offsets.append(stored)
            kept.append(block)
            stored += c
            prev = (offsets[-1], block)
        start += c
    table = np.concatenate(kept) if kept else rows[:0]
    return offsets, table


def _param_lines(params: dict[str, Any], real: str) -> list[str]:
    rows = {p.name: p for p in PARAMS}
    lines: list[str] = []
    for key, value in params.items():
        if key not in rows:
            raise FirmwareError(f"unknown runtime parameter {key!r} in the controller replay")
        row = rows[key]
        values = list(value) if row.size > 1 else [value]
        for i, v in enumerate(values):
            struct = "own" if row.controller else "params"   # creplay_set_params(params, own)
            target = f"{struct}->{key}[{i}]" if row.size > 1 else f"{struct}->{key}"
            text = str(int(v)) if row.ctype == "int" else _literal(float(v), real)
            lines.append(f"{target} = {text};")
    return lines


def controller_context(replay: ControllerReplay, real: str) -> dict[str, Any]:
    """What controller_data.c/h need: per-period scalars, the packed row tables and the parameters."""
    path_off, path = _packed(replay.n_path, replay.path)
    obs_off, obstacles = _packed(replay.n_obstacles, replay.obstacles)
    track_off = [int(v) for v in np.concatenate([[0], np.cumsum(replay.n_tracks)[:-1]])]
    has_cov = np.all(np.isfinite(replay.covariances), axis=1) if len(replay.covariances) else np.zeros(0, bool)
    cov = np.where(has_cov[:, None], replay.covariances, 0.0) if len(replay.covariances) else replay.covariances

    def ints(values: Sequence[int] | np.ndarray) -> str:
        return ", ".join(str(int(v)) for v in values)

    return {
        "steps": replay.steps,
        "scenario": replay.scenario,
        "path_rows": max(1, len(path)),
        "track_rows": max(1, len(replay.tracks)),
        "obstacle_rows": max(1, len(obstacles)),
        "time": _table(replay.time[:, None], real, 1),
        "pose": _table(replay.pose, real, 3),
        "v": _table(replay.v[:, None], real, 1),
        "omega": _table(replay.omega[:, None], real, 1),
        "has_goal": ints(replay.has_goal),
        "goal": _table(replay.goal, real, 3),
        "n_path": ints(replay.n_path),
        "path_offset": ints(path_off),
        "path": _table(path, real, 2),
        "n_tracks": ints(replay.n_tracks),
        "track_offset": ints(track_off),
        "track_ids": _table(replay.track_ids[:, None], None, 1),
        "tracks": _table(replay.tracks, real, 4),
        "track_has_covariance": _table(has_cov.astype(int)[:, None], None, 1),
        "track_covariances": _table(cov, real, 3),
        "n_obstacles": ints(replay.n_obstacles),
        "obstacle_offset": ints(obs_off),
        "obstacles": _table(obstacles, real, 2),
        "params": _param_lines(replay.params, real),
        "probe_deadline": _literal(DEADLINE_PROBE_MS, real),
    }


def check_controller_replay_fits(replay: ControllerReplay, solver_dir: Path) -> None:
    spec = package_spec(solver_dir)
    caps = {"controller.max_path_points": spec.controller.max_path_points,
            "controller.max_tracks": spec.controller.max_tracks,
            "controller.max_obstacle_points": spec.controller.max_obstacle_points}
    problems = [f"up to {n} rows where {key} is {caps[key]}" for key, n in replay.max_counts().items()
                if n > caps[key]]
    if problems:
        raise FirmwareError(f"the controller replay does not fit the package in {solver_dir}: "
                            + "; ".join(problems))


def write_controller_firmware(solver_dir: str | Path, replay: ControllerReplay, *, cold: bool = False) -> Path:
    """Render the controller programs (and the shared files) into DIR/firmware/; return its path.

    cold: the controller is reset before every period (each then depends on its own inputs only)."""
    d = Path(solver_dir).resolve()
    m = read_manifest(d)
    check_controller_replay_fits(replay, d)
    name, real = m.name, m.real
    context = {"name": name, "NAME": name.upper(), "version": __version__, "real": real, "cold": cold,
               **controller_context(replay, real)}
    out = d / "firmware"
    out.mkdir(exist_ok=True)
    env = make_environment()
    files = {**{t: FIRMWARE_TEMPLATES[t] for t in SHARED_TEMPLATES}, **CONTROLLER_TEMPLATES}
    for tpl, filename in files.items():
        text = env.get_template(tpl).render(**context)
        path = out / filename
        if not path.exists() or path.read_text() != text:  # keep mtimes: make rebuilds only what changed
            path.write_text(text)
    return out


# -- what the firmware printed ------------------------------------------------------------------


@dataclass(frozen=True)
class ControllerLine:
    """One controller period as the firmware reported it."""

    t: int
    outcome: int
    stop: int
    stop_reason: int
    status: int
    qp_status: int
    qp_iterations: int
    sqp_iterations: int
    goal_reached: int
    stalled: int
    recovered: int
    loop_detected: int
    people_index: tuple[int, ...]
    command: tuple[float, float]
    u: tuple[float, float]
    ocp_goal: tuple[float, float, float, float]
    plan_end: tuple[float, float]
    distance_to_goal: float
    time_total_ms: float  # the controller's own clock: QEMU's virtual time
    ticks: int  # SysTick ticks of the step, measured around it
    candidate: int  # the plan applied: 0 the main one, k the k-th candidate

    @property
    def instructions(self) -> int:
        return self.ticks * INSN_PER_TICK

    @property
    def decision(self) -> tuple[int, ...]:
        return (self.outcome, self.stop, self.stop_reason, self.status, self.qp_status, self.goal_reached,
                self.stalled, self.recovered, self.loop_detected, self.candidate)


@dataclass
class ControllerRun:
    """What the controller replay program printed."""

    name: str
    cpu: str
    real: str
    controller_bytes: int  # sizeof(<name>_controller)
    calib_instructions: int
    calib_ticks: int
    steps: list[ControllerLine] = field(default_factory=list)
    probe_stop_reason: int = -1  # the deadline probe's stop reason
    probe_time_ms: float = math.nan
    stack_bytes: int = -1  # the stack's high-water mark over the whole run

    @property
    def instructions(self) -> np.ndarray:
        return np.array([s.instructions for s in self.steps], dtype=np.int64)


def parse_controller_output(text: str) -> ControllerRun:
    """Parse the controller replay's console output; FirmwareError when incomplete or inconsistent."""
    lines = text.splitlines()
    begin = [ln.split() for ln in lines if ln.startswith("cbegin ")]
    calib = [ln.split() for ln in lines if ln.startswith("calib ")]
    probe = [ln.split() for ln in lines if ln.startswith("probe ")]
    stack = [ln.split() for ln in lines if ln.startswith("stack ")]
    if not begin or not calib or not probe or not stack or "end" not in lines:
        raise FirmwareError("the controller firmware's output is incomplete (no cbegin/calib/probe/stack/end "
                            "line):\n" + text[-2000:])
    _, name, cpu, real, n_steps, nbytes = begin[0]
    run = ControllerRun(name, cpu, real, int(nbytes), int(calib[0][1]), int(calib[0][2]))
    check_calibration(run.calib_instructions, run.calib_ticks)
    for ln in lines:
        if not ln.startswith("cstep "):
            continue
        f = ln.split()
        ints = [int(v) for v in f[1:14]]
        n_people = ints[12]
        people = tuple(int(v) for v in f[14:14 + n_people])
        reals = [hex_real(v, real) for v in f[14 + n_people:26 + n_people]]
        i = ints
        run.steps.append(ControllerLine(
            i[0], i[1], i[2], i[3], i[4], i[5], i[6], i[7], i[8], i[9], i[10], i[11], people,
            (reals[0], reals[1]), (reals[2], reals[3]), (reals[4], reals[5], reals[6], reals[7]),
            (reals[8], reals[9]), reals[10], reals[11], int(f[26 + n_people]), int(f[27 + n_people])))
    if len(run.steps) != int(n_steps):
        raise FirmwareError(f"the controller firmware reported {len(run.steps)} periods of {n_steps}")
    run.probe_stop_reason = int(probe[0][1])
    run.probe_time_ms = hex_real(probe[0][2], real)
    run.stack_bytes = int(stack[0][1])
    return run


# -- against the host ----------------------------------------------------------------------------


def host_decision(r: ControllerResult) -> tuple[int, ...]:
    return (r.outcome, int(r.stop), r.stop_reason, r.status, r.qp_status, int(r.goal_reached), int(r.stalled),
            int(r.recovered), int(r.loop_detected), r.candidate)


@dataclass(frozen=True)
class ControllerAgreement:
    """The firmware's controller against the host's on one replay.

    Relative differences are per component, divided by the width of its bounds in the parameters in
    force (v: v_bounds, omega: omega_bounds, a: a_bounds), the larger of command's and u's."""

    steps: int
    max_command_diff: float  # max over periods of |command_fw - command_host| (inf-norm)
    max_u_diff: float  # the same for u = [a, omega]
    max_rel: float  # max over periods of the relative difference
    max_rel_same: float  # ... over the periods whose decisions agree
    median_rel: float
    mismatched_periods: tuple[int, ...]  # periods whose decisions (outcome, stop, statuses, flags, plan) differ
    people_mismatches: int  # periods whose chosen people differ
    first_mismatch: str

    @property
    def outcome_mismatches(self) -> int:
        return len(self.mismatched_periods)

    @property
    def same_decisions(self) -> bool:
        return not self.mismatched_periods


def relative_diffs(run: ControllerRun, host: Sequence[ControllerResult], params: dict[str, Any]) -> np.ndarray:
    """Per period: the largest difference of command and u, each component divided by its bound width."""
    span = lambda key: float(params[key][1] - params[key][0])  # noqa: E731
    cmd_scale = np.array([span("v_bounds"), span("omega_bounds")])
    u_scale = np.array([span("a_bounds"), span("omega_bounds")])
    return np.array([max(float(np.max(np.abs(np.asarray(s.command) - h.command) / cmd_scale)),
                         float(np.max(np.abs(np.asarray(s.u) - h.u) / u_scale)))
                     for s, h in zip(run.steps, host, strict=True)])


def compare_controller(run: ControllerRun, host: Sequence[ControllerResult], params: dict[str, Any]) -> \
        ControllerAgreement:
    """Per-period differences; ``params``: the parameters in force (their bounds scale the relative ones)."""
    if len(host) != len(run.steps):
        raise FirmwareError(f"host has {len(host)} periods, firmware {len(run.steps)}")
    rel = relative_diffs(run, host, params)
    pairs = list(zip(run.steps, host, strict=True))
    dc = max((float(np.max(np.abs(np.asarray(s.command) - h.command))) for s, h in pairs), default=0.0)
    du = max((float(np.max(np.abs(np.asarray(s.u) - h.u))) for s, h in pairs), default=0.0)
    mismatched = tuple(s.t for s, h in pairs if s.decision != host_decision(h))
    first = ""
    if mismatched:
        s, h = run.steps[mismatched[0]], host[mismatched[0]]
        first = (f"period {s.t}: firmware (outcome, stop, reason, status, qp_status, goal_reached, stalled, "
                 f"recovered, loop_detected, candidate) = {s.decision}, host {host_decision(h)}")
    same = [r for r, s in zip(rel, run.steps, strict=True) if s.t not in mismatched]
    people = sum(s.people_index != tuple(int(i) for i in h.people_index) for s, h in pairs)
    return ControllerAgreement(len(host), dc, du, float(rel.max(initial=0.0)), float(max(same, default=0.0)),
                               float(np.median(rel)) if len(rel) else 0.0, mismatched, people, first)


# -- the command ----------------------------------------------------------------------------------


def run_controller_firmware(solver_dir: str | Path, cpu: str, replay: ControllerReplay | None = None, *,
                            steps: int = 140, seed: int = 0, cold: bool = False, timeout: float = 600.0,
                            ram_bytes: int | None = None, log: Callable[[str], None] | None = None) -> \
        tuple[ControllerRun, ControllerAgreement, Path, ControllerReplay]:
    """Record (or take) a controller replay, build and run it on cpu, compare with the host library of
    the same package; (run, agreement, elf, replay). ram_bytes: the image linked into that much RAM
    (build_firmware)."""
    say = log or print_progress
    d = Path(solver_dir).resolve()
    require_tools()
    host = load(d)
    if replay is None:
        say(f"[humanmpc] recording {steps} controller periods with the host library (seed {seed})")
        replay = record_controller_replay(host, steps=steps, seed=seed)
    fw = write_controller_firmware(d, replay, cold=cold)
    say(f"[humanmpc] cross-compiling the controller replay in {fw} for {cpu}")
    elf = build_firmware(fw, cpu, "controller", ram_bytes=ram_bytes)
    say(f"[humanmpc] running {elf.name} under qemu-system-arm -M {CPUS[cpu].machine} -icount shift=0")
    t0 = time.perf_counter()
    run = parse_controller_output(run_qemu(elf, cpu, timeout=timeout))
    say(f"[humanmpc] {len(run.steps)} periods in {time.perf_counter() - t0:.1f} s of QEMU")
    host_steps = host_controller_results(host, replay, cold=cold)
    params = host_controller(host, replay).params
    return run, compare_controller(run, host_steps, params), elf, replay
