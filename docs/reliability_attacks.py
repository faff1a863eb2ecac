"""The attacks of issue 22 on the solver of the paper's configuration, counted: prints the table of
docs/reliability.md (attack, trials, failures, what guards it).

A failure is what the issue found: a command that leaves the bounds without a stop, a stop that does not
brake at the configured rate, a bad input or clock without its stop, a late solve without one, a
recovery that differs from a fresh solver. Run from the repository root after `make venv`:

    .venv/bin/python docs/reliability_attacks.py
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import humanmpc
from humanmpc.codegen.build import build
from humanmpc.codegen.generate import generate
from humanmpc.codegen.spec import SpecError, resolve_spec

N, DT = 50, 0.1


def clean_inputs(rng: np.random.Generator | None = None) -> dict[str, Any]:
    humans_now = np.array([[3.0, 1.5], [5.0, -2.0], [6.0, 0.3]])
    vel = np.array([[0.0, -0.3], [0.2, 0.4], [-0.5, 0.0]])
    x0 = np.array([0.0, 0.0, 0.1, 0.6])
    if rng is not None:
        x0 = np.array([0.0, 0.0, rng.uniform(-3, 3), rng.uniform(0, 1)])
    return {"x0": x0, "goal": np.array([8.0, 0.0, 0.0, 0.8]), "humans_now": humans_now,
            "humans_pred": np.stack([humans_now + vel * DT * n for n in range(N + 1)]),
            "obstacle": np.array([4.0, -0.8])}


def in_bounds(r: humanmpc.StepResult, p: dict[str, Any]) -> bool:
    """Within the bounds to the command guard's tolerance, 1e-6 (1 + |bound|) (HM_MONITOR_COMMAND_TOL)."""
    def within(x: float, b: tuple[float, float]) -> bool:
        return b[0] - 1e-6 * (1 + abs(b[0])) <= x <= b[1] + 1e-6 * (1 + abs(b[1]))

    return bool(within(r.command[0], p["v_bounds"]) and within(r.command[1], p["omega_bounds"])
                and within(r.u0[0], p["a_bounds"]) and np.all(np.isfinite(r.command)))


def brakes(r: humanmpc.StepResult, p: dict[str, Any], v0: float) -> bool:
    a_min, a_max = p["a_bounds"]
    return bool(r.stop and r.u0[1] == 0.0 and r.command[1] == 0.0
                and abs(r.u0[0] - min(max(-v0 / DT, a_min), a_max)) <= 1e-9)


Row = tuple[str, int, int, str]


def attack_braking(d: Path) -> Row:
    fails = trials = 0
    for a_min in (0.0, -1e-300, -1e-3, -0.05, -0.0999):
        for how in ("spec", "c", "python"):
            trials += 1
            s = humanmpc.load(d)
            if how == "spec":
                try:
                    resolve_spec({"bounds": {"a": [a_min, 1.0]}})
                    fails += 1
                except SpecError:
                    pass
            elif how == "python":
                try:
                    s.set_params(a_bounds=[a_min, 1.0])
                    fails += 1
                except ValueError:
                    pass
            else:
                s._params.a_bounds = [a_min, 1.0]
                r = s.step([0, 0, 0, 1.0], [5, 0, 0, 0.8], [[0.3, 0.0]], np.tile([[0.3, 0.0]], (N + 1, 1, 1)))
                fails += int(not (r.stop and r.u0[0] <= -0.1))
    return ("a_min of 0, -1e-300 ... -0.0999 (spec, C struct, set_params), a person 0.3 m ahead at 1 m/s",
            trials, fails, "the parameter table's rule a_min <= -0.1 (spec, C check, Python); a stop brakes at "
            "a_bounds")


def attack_solve_qp_limit(d: Path) -> Row:
    s = humanmpc.load(d)
    fails = trials = 0
    rng = np.random.default_rng(1)
    for it in range(1, 9):
        for _ in range(25):
            s.reset()
            s.set_params(qp_max_iter=it, deadline_ms=1e4)
            r = s.solve(**clean_inputs(rng))
            trials += 1
            fails += int(not r.stop and (r.qp_status_name != "solved" or not in_bounds(r, s.params)))
    return ("solve() with qp_max_iter = 1..8", trials, fails,
            "solve(): every QP must be solved (an iterate cut at its limit ends the SQP in a stop, qp_failed)")


def attack_solve_deadline(d: Path) -> Row:
    s = humanmpc.load(d)
    s.set_params(deadline_ms=0.001)
    fails = trials = 0
    for _ in range(100):
        s.reset()
        r = s.solve(**clean_inputs(), max_iter=100, tol=1e-9)
        trials += 1
        fails += int(not (r.stop and r.reason == "deadline") or r.time_total_ms > 2.0)
    return ("solve() under a 1 us deadline", trials, fails, "solve() under the deadline (polled in the QPs)")


def attack_solve_no_iterations(d: Path) -> Row:
    s = humanmpc.load(d)
    fails = trials = 0
    for max_iter, tol in ((0, 1e-8), (-1, 1e-8), (-2**31, 1e-8), (5, float("nan")), (5, 0.0), (5, -1.0),
                          (5, float("inf"))):
        s._load_inputs(*clean_inputs().values())
        s._c_solve(s._solver, s._in, s._out, max_iter, tol)
        trials += 1
        fails += int(not s._result().stop)
    return ("solve() from C with max_iter <= 0 or tol NaN / 0 / < 0 / inf", trials, fails,
            "solve(): an invalid input, nothing solved")


def attack_extreme_params(d: Path) -> Row:
    s = humanmpc.load(d)
    rng = np.random.default_rng(0)
    fails = trials = 0
    for _ in range(300):
        s.reset()
        s.set_params(qp_tol=float(rng.choice([1e-6, 1e-2, 0.5, 1.0])), qp_max_iter=int(rng.choice([1, 2, 3, 5, 50])),
                     line_search=int(rng.integers(0, 2)), exact_hessian=int(rng.integers(0, 2)),
                     human_slack_l1=float(rng.choice([1e4, 1e9, 0.0])), q=float(rng.choice([2.0, 1e6])),
                     d_th=float(rng.uniform(0, 30)), regularization=float(rng.choice([1e-6, 1e3, 0.0])))
        inp = clean_inputs(rng)
        for _ in range(5):
            r = s.step(**inp)
            trials += 1
            fails += int(not (in_bounds(r, s.params) if not r.stop else brakes(r, s.params, inp["x0"][3])))
    return ("spec-valid extreme parameters (qp_tol, qp_max_iter, q, d_th, slacks, regularisation, line search), "
            "5 steps each", trials, fails, "the command guard (stop command_bounds) and the QP status")


def attack_bounds_between_phases(d: Path) -> Row:
    s = humanmpc.load(d)
    rng = np.random.default_rng(2)
    fails = trials = 0
    for _ in range(400):
        s.reset()
        inp = clean_inputs(rng)
        s.step(**inp)
        s.prepare(inp["goal"], inp["humans_now"], inp["humans_pred"], inp["obstacle"])
        hi = float(rng.uniform(0.05, 1.0))
        s.set_params(v_bounds=[0.0, hi], omega_bounds=[-hi, hi])
        r = s.feedback(inp["x0"])
        trials += 1
        fails += int(not (in_bounds(r, s.params) if not r.stop else r.command[1] == 0.0))
        s.set_params(v_bounds=[0.0, 1.0], omega_bounds=[-1.5, 1.5])
    return ("bounds of v and omega changed between prepare and feedback", trials, fails,
            "feedback linearises again under changed parameters; the command guard")


def attack_jump(d: Path) -> Row:
    s = humanmpc.load(d)
    rng = np.random.default_rng(3)
    fails = trials = 0
    for _ in range(100):
        s.reset()
        inp = clean_inputs(rng)
        s.step(**inp)
        dx = float(rng.choice([1.0, 10.0, 1e3, 9e4]))
        jumped = dict(inp, x0=inp["x0"] + [dx, 0, 0, 0])
        r = s.step(**jumped)
        trials += 1
        fails += int(not (r.stop and r.reason == "state_jump"))
        again = s.step(**jumped)
        trials += 1
        fails += int(not (again.stop or in_bounds(again, s.params)))
    return ("the measured position jumps by 1 m .. 9e4 m between steps (the jump, and the step after)", trials, fails,
            "the state jump test (stop state_jump), then a cold start")


def attack_clock(d: Path) -> Row:
    fails = trials = 0
    for kind in ("stuck", "raises", "backwards"):
        s = humanmpc.load(d)
        ffi, lib = s._ffi, s._lib
        t = [10**15]

        def read(kind: str = kind, t: list[int] = t) -> int:
            if kind == "raises":
                raise RuntimeError("clock")
            if kind == "backwards":
                t[0] -= 1000
            return t[0]

        cb = ffi.callback(f"{s.name}_clock_fn", lambda _ctx, read=read: read(), onerror=lambda *_a: None)
        getattr(lib, f"{s.name}_solver_set_clock")(s._solver, cb, ffi.NULL)
        s.set_params(deadline_ms=0.001)
        for k in range(100):
            r = s.solve(**clean_inputs()) if k % 4 == 3 else s.step(**clean_inputs())
            trials += 1
            fails += int(not (r.stop and r.reason == "clock"))
    return ("a clock that stands still, raises (reads 0) or runs backwards, 1 us deadline", trials, fails,
            "the clock monitor (stop clock)")


def attack_recovery(d: Path) -> Row:
    fails = trials = 0
    inp = clean_inputs()
    ref = humanmpc.load(d).step(**inp)
    for kind in ("invalid_input", "invalid_params", "deadline", "qp_failed", "state_jump"):
        for _ in range(10):
            s = humanmpc.load(d)
            for _ in range(3):
                s.step(**inp)
            if kind == "invalid_input":
                s.step(**dict(inp, goal=np.array([np.nan, 0, 0, 0.8])))
            elif kind == "invalid_params":
                s._params.d_h = 150.0
                s.step(**inp)
                s._params.d_h = 0.5
            elif kind == "deadline":
                s.set_params(deadline_ms=0.001)
                s.step(**inp)
                s.set_params(deadline_ms=20.0)
            elif kind == "qp_failed":
                s.set_params(qp_max_iter=1)
                s.step(**inp)
                s.set_params(qp_max_iter=50)
            else:
                s.step(**dict(inp, x0=inp["x0"] + [3.0, 0, 0, 0]))
            r = s.step(**inp)
            trials += 1
            fails += int(not (np.array_equal(r.x, ref.x) and np.array_equal(r.u0, ref.u0)))
    return ("the next clean step after a failure stop (5 kinds) against a fresh solver's, bit for bit", trials, fails,
            "every failure stop starts the next step cold (C2 stops keep their plan by design)")


def attack_prepare_step(d: Path) -> Row:
    fails = trials = 0
    inp = clean_inputs()
    for k in range(20):
        a, b = humanmpc.load(d), humanmpc.load(d)
        for _ in range(1 + k % 4):
            a.step(**inp)
            b.step(**inp)
        b.prepare(inp["goal"], inp["humans_now"], inp["humans_pred"], inp["obstacle"])
        ra, rb = a.step(**inp), b.step(**inp)
        trials += 1
        fails += int(not np.array_equal(ra.x, rb.x))
    return ("prepare() then step() against step() alone", trials, fails, "a second preparation does not shift again")


def attack_line_search(d: Path) -> Row:
    s = humanmpc.load(d)
    s.set_params(line_search=1)
    rng = np.random.default_rng(3)
    fails = trials = 0
    inp = clean_inputs()
    for _ in range(8):
        s.reset()
        x = np.array([0.0, 0.0, rng.uniform(-0.5, 0.5), rng.uniform(0.0, 1.0)])
        for _ in range(40):
            r = s.step(**dict(inp, x0=x))
            if not r.stop:
                trials += 1
                fails += int(np.max(r.x[1:, 3]) > 1.0 + 1e-9 or np.min(r.x[1:, 3]) < -1e-9)
            x = x + DT * np.array([x[3] * np.cos(x[2]), x[3] * np.sin(x[2]), r.u0[1], r.u0[0]])
    return ("line_search = 1: plans (nodes 1..N) with a speed outside [0, 1]", trials, fails,
            "the line search starts from a guess within the bounds")


def attack_truncated_library(d: Path, work: Path) -> Row:
    import shutil

    fails = trials = 0
    code = ("import sys, humanmpc\ntry:\n    humanmpc.load(sys.argv[1], build_if_needed=False)\n"
            "except humanmpc.LoadError:\n    sys.exit(3)\n")
    for keep in (0.1, 0.5, 0.9, 0.99):
        t = work / f"trunc{keep}"
        shutil.copytree(d, t)
        lib = next((t / "build").glob("*.so"))
        lib.write_bytes(lib.read_bytes()[: int(lib.stat().st_size * keep)])
        for recorded in (True, False):
            if not recorded:
                for rec in (t / "build").glob("*.record.json"):
                    rec.unlink()
            proc = subprocess.run([sys.executable, "-c", code, str(t)], capture_output=True, timeout=120, check=False)
            trials += 1
            fails += int(proc.returncode != 3)
    return ("load() of a library cut to 10 .. 99 % (with and without build()'s record)", trials, fails,
            "load() checks the ELF file and build()'s size and SHA-256 before dlopen")


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        d = generate(resolve_spec({"name": "attack", "preset": "paper"}), work / "attack", log=lambda _m: None)
        build(d, log=lambda _m: None)
        attacks: list[Callable[[Path], Row]] = [
            attack_braking, attack_solve_qp_limit, attack_solve_deadline, attack_solve_no_iterations,
            attack_extreme_params, attack_bounds_between_phases, attack_jump, attack_clock, attack_recovery,
            attack_prepare_step, attack_line_search]
        rows = [a(d) for a in attacks] + [attack_truncated_library(d, work)]
    print("| attack | trials | failures | guarded by |")
    print("|---|---:|---:|---|")
    for what, trials, fails, guard in rows:
        print(f"| {what} | {trials} | {fails} | {guard} |")


if __name__ == "__main__":
    main()
