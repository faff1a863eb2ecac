"""Issue 22's findings, one test each: the full SQP under the monitors of the real-time iteration, the
command guard, the clock monitor, the state jump, recovery after every kind of stop, prepare() before
step(), and the line search's plans within the bounds (docs/reliability.md)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import humanmpc

from .test_monitor import assert_braking, assert_same, clean_inputs


@pytest.fixture()
def fresh(paper_dir: Path) -> humanmpc.Solver:
    return humanmpc.load(paper_dir)


def within_bounds(r: humanmpc.StepResult, params: dict[str, Any], tol: float = 1e-6) -> bool:
    (v_lo, v_hi), (w_lo, w_hi), (a_lo, a_hi) = params["v_bounds"], params["omega_bounds"], params["a_bounds"]
    return bool(v_lo - tol <= r.command[0] <= v_hi + tol and w_lo - tol <= r.command[1] <= w_hi + tol
                and a_lo - tol <= r.u0[0] <= a_hi + tol)


# -- the full SQP under the monitors (item 2) ---------------------------------------------------------


def test_solve_does_not_apply_qp_iterates_stopped_at_their_iteration_limit(fresh: humanmpc.Solver) -> None:
    """With qp_max_iter <= 8 every solve() applied QP iterates cut at their limit, and with q = 1e6,
    d_th = 24.74, qp_max_iter = 7 it commanded omega at 2.1 x its bound: now a stop, reason qp_failed."""
    inp = clean_inputs()
    fresh.set_params(qp_max_iter=3, deadline_ms=1e4)
    r = fresh.solve(**inp)
    assert r.stop and r.reason == "qp_failed" and r.qp_status_name == "max_iter"
    assert_braking(r, fresh, v0=inp["x0"][3])
    fresh.reset()
    fresh.set_params(qp_max_iter=7, q=1e6, d_th=24.74)
    r = fresh.solve(**inp)
    assert r.stop or within_bounds(r, fresh.params)


def test_solve_keeps_the_deadline(fresh: humanmpc.Solver) -> None:
    """solve() ignored the deadline (478 of 500 calls past 1 us, up to 4.5 ms): now a stop, reason deadline."""
    inp = clean_inputs()
    fresh.set_params(deadline_ms=0.001)
    r = fresh.solve(**inp, max_iter=100, tol=1e-9)
    assert r.stop and r.reason == "deadline"
    assert_braking(r, fresh, v0=inp["x0"][3])
    assert r.time_total_ms < 2.0  # stopped inside the first QP, not after the whole SQP


@pytest.mark.parametrize(("max_iter", "tol"), [(0, 1e-8), (-1, 1e-8), (5, float("nan")), (5, 0.0), (5, -1.0)])
def test_solve_from_c_without_iterations_or_a_tolerance_is_an_invalid_input(fresh: humanmpc.Solver, max_iter: int,
                                                                              tol: float) -> None:
    """From C, max_iter <= 0 returned the unoptimised guess as a valid command."""
    fresh._load_inputs(*clean_inputs().values())
    fresh._c_solve(fresh._solver, fresh._in, fresh._out, max_iter, tol)
    r = fresh._result()
    assert r.stop and r.reason == "invalid_input" and r.status_name == "skipped"
    assert_braking(r, fresh, v0=clean_inputs()["x0"][3])


# -- the command guard (items 2 and 3) ----------------------------------------------------------------


def test_a_command_outside_the_bounds_is_a_protective_stop_of_its_own(fresh: humanmpc.Solver) -> None:
    """Spec-valid parameters (a loose QP tolerance under a huge collision potential) gave a plan whose
    command is v = 0.5 with v in [0, 1] but an acceleration beyond its bound: every command that is
    handed out keeps the bounds, or is a braking stop with reason command_bounds."""
    fresh.set_params(qp_tol=0.01, q=1e6, d_th=20.0, human_slack_l1=0.0, regularization=0.0, exact_hessian=1)
    inp = clean_inputs()
    reasons = []
    for _ in range(3):
        r = fresh.step(**inp)
        reasons.append(r.reason)
        assert np.all(np.isfinite(r.command)) and np.all(np.isfinite(r.u0))
        if r.stop:
            assert_braking(r, fresh, v0=inp["x0"][3])
        else:
            assert within_bounds(r, fresh.params), (r.u0, r.command)
    assert "command_bounds" in reasons


# -- the clock monitor (item 8) -----------------------------------------------------------------------


@pytest.fixture()
def install_clock(fresh: humanmpc.Solver) -> Iterator[Callable[[Callable[[], int]], None]]:
    """Installs a Python clock (nanoseconds) into fresh, kept alive for the test."""
    kept: list[Any] = []
    ffi, lib, name = fresh._ffi, fresh._lib, fresh.name

    def install(read: Callable[[], int]) -> None:
        # a clock that raises reads 0 (cffi's default for a failing callback), as a broken hook would
        cb = ffi.callback(f"{name}_clock_fn", lambda _ctx: read(), onerror=lambda *_exc: None)
        kept.append(cb)
        getattr(lib, f"{name}_solver_set_clock")(fresh._solver, cb, ffi.NULL)

    yield install
    kept.clear()


def test_a_stuck_clock_is_a_clock_fault_not_a_silent_deadline(fresh: humanmpc.Solver,
                                                             install_clock: Callable[..., None]) -> None:
    """A clock that stood still (or raised: cffi reads 0) turned the deadline monitor silently off: a 1 us
    deadline never stopped. Now every step that solved is a stop, reason clock."""
    fresh.set_params(deadline_ms=0.001)
    for read in (lambda: 123456789, lambda: 1 // 0):
        install_clock(read)
        for _ in range(3):
            r = fresh.step(**clean_inputs())
            assert r.stop and r.reason == "clock", r.reason
            assert_braking(r, fresh, v0=clean_inputs()["x0"][3])


def test_a_clock_that_runs_backwards_is_a_clock_fault(fresh: humanmpc.Solver,
                                                      install_clock: Callable[..., None]) -> None:
    """A clock running backwards stopped every step as 'deadline' with a time of 1.8e13 ms."""
    t = [10**15]

    def backwards() -> int:
        t[0] -= 1000
        return t[0]

    install_clock(backwards)
    for solve in (False, True):
        r = fresh.solve(**clean_inputs()) if solve else fresh.step(**clean_inputs())
        assert r.stop and r.reason == "clock", r.reason
        assert_braking(r, fresh, v0=clean_inputs()["x0"][3])
        # its times read 0, not the unsigned difference's 1.8e13 ms
        assert r.time_total_ms == r.time_feedback_ms == r.time_prepare_ms == 0.0


def test_a_clock_that_runs_forwards_keeps_the_deadline_monitor(fresh: humanmpc.Solver,
                                                               install_clock: Callable[..., None]) -> None:
    t = [0]

    def forwards() -> int:
        t[0] += 1000  # 1 us a reading
        return t[0]

    install_clock(forwards)
    assert not fresh.step(**clean_inputs()).stop
    fresh.set_params(deadline_ms=0.01)
    assert fresh.step(**clean_inputs()).reason == "deadline"


# -- a state that jumps (item 4) ----------------------------------------------------------------------


def test_a_state_that_jumps_between_steps_is_a_stop_and_the_next_step_starts_cold(fresh: humanmpc.Solver) -> None:
    """A position that jumped by 1e5 m between steps was accepted, and the warm start from the old place
    then gave commands beyond the bounds."""
    inp = clean_inputs()
    for dx, dv in ((5.0, 0.0), (0.0, 0.9), (-9e4, 0.0)):
        fresh.reset()
        assert not fresh.step(**inp).stop
        jumped = dict(inp, x0=inp["x0"] + np.array([dx, 0.0, 0.0, dv]),
                      humans_now=inp["humans_now"] + [dx, 0.0], humans_pred=inp["humans_pred"] + [dx, 0.0],
                      goal=inp["goal"] + [dx, 0, 0, 0], obstacle=inp["obstacle"] + [dx, 0.0])
        r = fresh.step(**jumped)
        assert r.stop and r.reason == "state_jump", (dx, dv, r.reason)
        assert_braking(r, fresh, v0=jumped["x0"][3])
        # handled: the next step from there starts cold, as a fresh solver
        assert_same(fresh.step(**jumped), humanmpc.load(fresh.path).step(**jumped))
    fresh.reset()
    fresh.step(**inp)
    # what the bounds allow in an interval (and a missed one) is no jump
    moved = dict(inp, x0=inp["x0"] + np.array([0.6 * 0.1, 0.0, 0.05, 0.05]))
    assert fresh.step(**moved).reason is None


# -- recovery after every kind of stop (item 9) ------------------------------------------------------


def _stop_by(kind: str, solver: humanmpc.Solver, inp: dict[str, Any]) -> humanmpc.StepResult:
    if kind == "invalid_input":
        return solver.step(**dict(inp, goal=np.array([np.nan, 0, 0, 0.8])))
    if kind == "invalid_params":
        saved = solver._params.d_h
        solver._params.d_h = 150.0
        r = solver.step(**inp)
        solver._params.d_h = saved
        return r
    if kind == "deadline":
        solver.set_params(deadline_ms=0.001)
        r = solver.step(**inp)
        solver.set_params(deadline_ms=20.0)
        return r
    if kind == "qp_failed":
        solver.set_params(qp_max_iter=1)
        r = solver.step(**inp)
        solver.set_params(qp_max_iter=50)
        return r
    if kind == "state_jump":
        return solver.step(**dict(inp, x0=inp["x0"] + np.array([3.0, 0.0, 0.0, 0.0])))
    if kind == "command_bounds":
        before = solver.params
        solver.set_params(qp_tol=0.01, q=1e6, d_th=20.0, human_slack_l1=0.0, regularization=0.0, exact_hessian=1)
        for _ in range(5):
            r = solver.step(**inp)
            if r.reason == "command_bounds":
                break
        solver.set_params(**before)
        return r
    raise AssertionError(kind)


@pytest.mark.parametrize("kind", ["invalid_input", "invalid_params", "deadline", "qp_failed", "state_jump",
                                  "command_bounds"])
def test_after_every_failure_stop_the_next_clean_step_equals_a_fresh_solvers(fresh: humanmpc.Solver,
                                                                            kind: str) -> None:
    """After a failure (C1, unusable data, the command guard, the clock, a state jump) nothing of the
    failed step is left: the next clean step is bit for bit a fresh solver's. The C2 stops (a person too
    close, an unsafe plan) keep their plan on purpose (docs/reliability.md)."""
    inp = clean_inputs()
    for _ in range(3):
        fresh.step(**inp)
    r = _stop_by(kind, fresh, inp)
    assert r.stop and r.reason == kind
    assert_same(fresh.step(**inp), humanmpc.load(fresh.path).step(**inp))


def test_prepare_then_step_shifts_the_plan_once(paper_dir: Path) -> None:
    """prepare() followed by step() shifted the plan twice: now the step linearises the preparation's
    shifted plan again, and gives what step() alone gives."""
    a, b = humanmpc.load(paper_dir), humanmpc.load(paper_dir)
    inp = clean_inputs()
    for _ in range(3):
        assert_same(a.step(**inp), b.step(**inp))
    b.prepare(inp["goal"], inp["humans_now"], inp["humans_pred"], inp["obstacle"])
    assert_same(a.step(**inp), b.step(**inp))
    assert_same(a.step(**inp), b.step(**inp))


# -- the line search's plans (item 10) -----------------------------------------------------------------


def test_line_search_plans_keep_the_speed_bounds(paper_dir: Path) -> None:
    """With line_search = 1, 254 of 320 plans had speeds up to 1.6 m/s with v_max = 1: the line search
    moved only part of the way from a shifted plan outside the bounds. Now it starts within them."""
    solver = humanmpc.load(paper_dir)
    solver.set_params(line_search=1)
    rng = np.random.default_rng(3)
    inp = clean_inputs()
    worst, plans = 0.0, 0
    for _ in range(8):
        solver.reset()
        x = np.array([0.0, 0.0, rng.uniform(-0.5, 0.5), rng.uniform(0.0, 1.0)])
        for _ in range(40):
            r = solver.step(**dict(inp, x0=x))
            if not r.stop:
                plans += 1
                worst = max(worst, float(np.max(r.x[1:, 3])) - 1.0, float(-np.min(r.x[1:, 3])))
            x = x + 0.1 * np.array([x[3] * np.cos(x[2]), x[3] * np.sin(x[2]), r.u0[1], r.u0[0]])
    assert plans > 200
    assert worst <= 1e-9, worst
