"""The stage-structured QP solver of the C runtime (c_runtime/ocp_qp*.c) against an independent
solver (Clarabel) and against the KKT conditions evaluated here from the problem statement.

The runtime is built by the fixtures from tests/c/qp_harness.c with the project's strict flags
(both compilers, both precisions) and driven through cffi. Random problems come from
tests/qp_harness.py; hypothesis draws their seeds and structure, derandomised so that CI is
reproducible.

Tolerances. Our solver runs at tol 1e-9 (scaled residuals and gap) and Clarabel at 1e-10. Interior-
point errors are norm-wise, proportional to the size of the solution rather than per component, so
primal solutions are compared with |ours - ref| <= 1e-6 * max(1, ||ref||_inf): relative for large
solutions, absolute near zero. KKT errors are each divided by max(1, largest term of the sum they
come from) and must be below 1e-7; complementarity is allowed the solver's gap, relative to the
objective.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from tests.qp_harness import (
    CDIR,
    HM_INF,
    INFEASIBLE,
    MAX_ITER,
    NONFINITE,
    NUMERICAL,
    NX,
    QP,
    SOL_FIELDS,
    SOLVED,
    TIMEOUT,
    Array,
    Harness,
    RefSolution,
    Shape,
    Sol,
    certificate_errors,
    clarabel_solve,
    compile_c,
    conic_form,
    kkt_errors,
    make_infeasible,
    present,
    random_qp,
)

N, NG = 6, 3
TOL = 1e-9
PRIMAL_TOL = 1e-6
KKT_TOL = 1e-7

# Derandomised, no example database, no deadline: the same examples on every machine and run.
QP_SETTINGS = settings(
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


@pytest.fixture(scope="session")
def build_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("qp_build")


@pytest.fixture(scope="session")
def hq(build_dir: Path) -> Harness:
    return Harness.build(build_dir, N, NG)


@pytest.fixture(scope="session")
def hq_big(build_dir: Path) -> Harness:
    return Harness.build(build_dir, 20, 6)


@pytest.fixture(scope="session")
def hq_float(build_dir: Path) -> Harness:
    return Harness.build(build_dir, N, NG, real="float")


shapes = st.builds(
    Shape,
    hessian=st.sampled_from(["pd", "singular_q", "lp_like"]),
    bound_density=st.sampled_from([0.0, 0.3, 0.7]),
    soft_fraction=st.sampled_from([0.0, 0.5, 1.0]),
    l1_only=st.booleans(),
    duplicate_rows=st.booleans(),
    scale=st.sampled_from([0.1, 1.0, 10.0]),
    dynamics=st.sampled_from(["general", "position_free", "integrators"]),
)
seeds = st.integers(min_value=0, max_value=2**32 - 1)


def primal_error(qp: QP, ours: Sol, ref: RefSolution) -> float:
    """max |ours - ref| over x, u and soft slacks, relative to max(1, ||ref||_inf)."""
    a = np.concatenate([ours.x.ravel(), ours.u.ravel(), _soft(qp, ours.s)])
    b = np.concatenate([ref.x.ravel(), ref.u.ravel(), _soft(qp, ref.s)])
    return float(np.max(np.abs(a - b)) / max(1.0, float(np.max(np.abs(b)))))


def _soft(qp: QP, s: Array) -> Array:
    mask = np.zeros_like(s, dtype=bool)
    for n in range(1, qp.horizon + 1):
        mask[n, : qp.ng[n]] = qp.soft[n, : qp.ng[n]] != 0
    return s[mask]


def assert_kkt(qp: QP, sol: Sol, obj: float, tol: float = KKT_TOL) -> None:
    err = kkt_errors(qp, sol)
    for key in ("stat", "eq", "ineq", "sign"):
        assert err[key] <= tol, (key, err)
    assert err["comp"] <= 10 * TOL * max(1.0, abs(obj)), err
    assert err["absent"] == 0.0, err


# ------------------------------------------------------------------------------------------------
# The Newton system: Riccati recursion == dense solve
# ------------------------------------------------------------------------------------------------


@settings(QP_SETTINGS, max_examples=40)
@given(seed=seeds, shape=shapes, log_w=st.sampled_from([0.0, 2.0, 6.0]))
def test_riccati_solve_equals_dense_solve_of_the_newton_system(hq: Harness, seed: int, shape: Shape,
                                                               log_w: float) -> None:
    """The stage-wise elimination and Riccati recursion solve the full Newton system K d = rhs (dense,
    numpy) to a backward error of rounding size, for row weights spread as late in a solve."""
    rng = np.random.default_rng(seed)
    qp, _, _ = random_qp(rng, N, NG, shape)
    m, cost_scale, stages = hq.kkt_map(qp)
    # the path the data's structure calls for: so every path of the recursion is under test
    eye = np.eye(NX)
    pos_free = [np.array_equal(qp.A[n][:, :2], eye[:, :2]) for n in range(N)]
    integ = [pos_free[n] and np.array_equal(qp.A[n][2:], eye[2:]) and qp.B[n][2, 0] == 0 and qp.B[n][3, 1] == 0
             for n in range(N)]
    want = [2 if i else 1 if p else 0 for p, i in zip(pos_free, integ, strict=True)]
    assert stages["kernel"] == [0, *want[1:], 0]  # stages 0 and N take the general path
    cf = conic_form(qp)
    assert m == cf.Ain.shape[0]  # the C solver packs the same rows
    w = 10.0 ** rng.uniform(-log_w, log_w, m)
    nv, me = cf.P.shape[0], cf.Aeq.shape[0]
    K = np.block([
        [cost_scale * cf.P, cf.Aeq.T, cf.Ain.T],
        [cf.Aeq, np.zeros((me, me)), np.zeros((me, m))],
        [cf.Ain, np.zeros((m, me)), -np.diag(1.0 / w)],
    ])
    rhs = rng.standard_normal(nv + me + m)
    # scatter rhs into the C vector layout (ux, s, y, z) and gather the solution back
    off_y = (N + 1) * 6 + (N + 1) * NG
    off_z = off_y + N * NX
    vec = np.zeros(hq.vec_len)
    vec[cf.vec_idx] = rhs[:nv]
    vec[off_y : off_y + me] = rhs[nv : nv + me]
    vec[off_z : off_z + m] = rhs[nv + me :]
    status, out = hq.kkt_solve(qp, w, vec)
    assert status == 0
    got = np.concatenate([out[cf.vec_idx], out[off_y : off_y + me], out[off_z : off_z + m]])
    backward = np.max(np.abs(K @ got - rhs)) / (np.max(np.abs(K)) * np.max(np.abs(got)) + np.max(np.abs(rhs)))
    assert backward <= 1e-13
    dense = np.linalg.solve(K, rhs)
    assert np.max(np.abs(got - dense)) <= 1e-15 * np.linalg.cond(K) * np.max(np.abs(dense)) + 1e-12


# ------------------------------------------------------------------------------------------------
# Feasible QPs
# ------------------------------------------------------------------------------------------------


@settings(QP_SETTINGS, max_examples=250)
@given(seed=seeds, shape=shapes)
def test_random_qps_match_clarabel_and_satisfy_kkt(hq: Harness, seed: int, shape: Shape) -> None:
    qp, _, _ = random_qp(np.random.default_rng(seed), N, NG, shape)
    r = hq.solve(qp, tol=TOL)
    ref = clarabel_solve(qp)
    assert ref.status == "Solved"
    assert r.status == SOLVED, hq.status_message(r.status)
    assert r.iter <= 30
    assert primal_error(qp, r.sol, ref) <= PRIMAL_TOL
    assert_kkt(qp, r.sol, r.res["obj"])
    # the workspace reports the residuals of what it returned
    assert r.res["eq"] <= 1e-9 and r.res["dual"] == 0.0


@settings(QP_SETTINGS, max_examples=30)
@given(seed=seeds, shape=shapes)
def test_longer_horizon_with_more_rows_matches_clarabel(hq_big: Harness, seed: int, shape: Shape) -> None:
    qp, _, _ = random_qp(np.random.default_rng(seed), 20, 6, shape)
    r = hq_big.solve(qp, tol=TOL)
    ref = clarabel_solve(qp)
    assert r.status == SOLVED and ref.status == "Solved"
    assert primal_error(qp, r.sol, ref) <= PRIMAL_TOL
    assert_kkt(qp, r.sol, r.res["obj"])


def _shifted(qp: QP) -> QP:
    """The QP a stage on, as the real-time iteration's next one: stage n takes stage n + 1's data, the
    last stage keeps its own."""
    out = qp.copy()
    for name in ("A", "B", "b", "Q", "S", "R", "q", "r", "lbx", "ubx", "lbu", "ubu", "ng", "D", "lg", "soft",
                 "zl", "Zl"):
        v = getattr(out, name)
        v[:-1] = v[1:].copy()
    return out


def _perturbed(qp: QP, rng: np.random.Generator, size: float) -> QP:
    """The same QP with its gradients and right-hand sides moved by about size (relative; absent
    rows stay absent)."""
    out = qp.copy()
    for name in ("q", "r", "b", "lg"):
        v = getattr(out, name)
        finite = np.isfinite(v)
        v[finite] += size * (np.abs(v[finite]) + 0.1) * rng.standard_normal(np.count_nonzero(finite))
    return out


@settings(QP_SETTINGS, max_examples=60)
@given(seed=seeds, shape=shapes, shifted=st.booleans())
def test_warm_start_from_the_last_solves_iterate_solves_the_next_qp(hq: Harness, seed: int, shape: Shape,
                                                                    shifted: bool) -> None:
    """A solve keeps an early iterate (warm_mu); the next QP (the same with moved data, or its stages
    shifted by one as in the real-time iteration) starts from it and is solved as accurately as from
    the cold start, wherever the two QPs' inequalities differ."""
    rng = np.random.default_rng(seed)
    qp, _, _ = random_qp(rng, N, NG, shape)
    first = hq.solve(qp, tol=TOL, warm_mu=0.1)
    assume(first.status == SOLVED)
    nxt = _shifted(qp) if shifted else _perturbed(qp, rng, 0.05)
    ref = clarabel_solve(nxt)
    assume(ref.status == "Solved")
    r = hq.solve(nxt, tol=TOL, warm_start=1 if shifted else 2, warm_mu=0.1)
    assert r.status == SOLVED, hq.status_message(r.status)
    assert primal_error(nxt, r.sol, ref) <= PRIMAL_TOL
    assert_kkt(nxt, r.sol, r.res["obj"])


def test_warm_start_takes_fewer_iterations_on_slightly_moved_qps(hq: Harness) -> None:
    """The point of keeping an iterate: over QPs whose data moved by 1 %, fewer iterations than from
    the cold start, the same solutions."""
    cold = warm = 0
    for seed in range(30):
        rng = np.random.default_rng(1000 + seed)
        qp, _, _ = random_qp(rng, N, NG, Shape())
        assert hq.solve(qp, tol=TOL, warm_mu=0.1).status == SOLVED
        nxt = _perturbed(qp, rng, 0.01)
        w = hq.solve(nxt, tol=TOL, warm_start=2)
        c = hq.solve(nxt, tol=TOL)
        assert w.status == SOLVED and c.status == SOLVED
        assert np.max(np.abs(w.sol.u - c.sol.u)) <= 1e-5
        cold, warm = cold + c.iter, warm + w.iter
    assert warm < cold, (warm, cold)


def test_a_kept_iterate_serves_one_solve_and_cold_solves_keep_none(hq: Harness) -> None:
    """warm_start without a kept iterate, or a second time, is the cold start: the same iterates."""
    qp, _, _ = random_qp(np.random.default_rng(7), N, NG, Shape())
    cold = hq.solve(qp, tol=TOL)
    again = hq.solve(qp, tol=TOL, warm_start=2)   # the cold solve kept nothing (warm_mu = 0)
    assert again.iter == cold.iter and np.array_equal(again.sol.u, cold.sol.u)
    hq.solve(qp, tol=TOL, warm_mu=0.1)
    hq.solve(qp, tol=TOL, warm_start=2)           # uses it up
    third = hq.solve(qp, tol=TOL, warm_start=2)
    assert third.iter == cold.iter and np.array_equal(third.sol.u, cold.sol.u)


@settings(QP_SETTINGS, max_examples=60)
@given(seed=seeds, shape=shapes)
def test_constraints_active_with_zero_multiplier_change_nothing(hq: Harness, seed: int, shape: Shape) -> None:
    """Degenerate QPs: a state bound, an input bound and a hard row put at the optimum of the
    problem without them are active there with a zero multiplier (no strict complementarity, where
    an interior-point iterate keeps slacks of ~sqrt(tol)); the optimum must stay where it was. They
    sit 1e-9 (relative) on the feasible side of the reference optimum, which is below what either
    solver resolves but keeps the problem strictly feasible despite the reference's own rounding."""
    rng = np.random.default_rng(seed)
    qp, _, _ = random_qp(rng, N, NG, shape)
    ref0 = clarabel_solve(qp)
    assert ref0.status == "Solved"
    eps = 1e-9 * max(1.0, float(np.max(np.abs(ref0.x))), float(np.max(np.abs(ref0.u))))
    deg = qp.copy()
    n, j = int(rng.integers(1, N + 1)), int(rng.integers(0, NX))
    if abs(deg.lbx[n, j]) >= HM_INF:
        deg.lbx[n, j] = ref0.x[n, j] - eps
    n, j = int(rng.integers(0, N)), int(rng.integers(0, 2))
    if abs(deg.ubu[n, j]) >= HM_INF:
        deg.ubu[n, j] = ref0.u[n, j] + eps
    n = int(rng.integers(1, N + 1))
    if deg.ng[n] < NG:
        i = int(deg.ng[n])
        deg.ng[n] += 1
        ang = rng.uniform(0, 2 * np.pi)
        deg.D[n, i] = (np.cos(ang), np.sin(ang))
        deg.lg[n, i] = deg.D[n, i] @ ref0.x[n, :2] - eps
        deg.soft[n, i] = 0
    # The slacks of ~sqrt(tol) would leave errors of ~1e-5 at tol 1e-9 (measured); the active-set
    # polish removes them, which is what it is for.
    r = hq.solve(deg, tol=TOL, polish=1)
    assert r.status == SOLVED
    assert primal_error(deg, r.sol, ref0) <= PRIMAL_TOL
    assert_kkt(deg, r.sol, r.res["obj"])


@settings(QP_SETTINGS, max_examples=30)
@given(seed=seeds)
def test_soft_rows_never_make_a_problem_infeasible(hq: Harness, seed: int) -> None:
    rng = np.random.default_rng(seed)
    qp, _, _ = random_qp(rng, N, NG, Shape())
    bad = make_infeasible(rng, qp, "rows")
    n = int(np.flatnonzero((bad.D[:, 1] == -bad.D[:, 0]).all(axis=1) & (bad.ng >= 2))[0])
    bad.soft[n, :2] = 1
    bad.zl[n, :2] = 1.0 + rng.random(2)
    bad.Zl[n, :2] = rng.choice([0.0, 1.0], 2)
    r = hq.solve(bad, tol=TOL)
    ref = clarabel_solve(bad)
    assert r.status == SOLVED and ref.status == "Solved"
    assert primal_error(bad, r.sol, ref) <= PRIMAL_TOL
    # the two contradicting rows cannot both hold: some slack is positive at the optimum
    assert r.sol.s[n, 0] + r.sol.s[n, 1] > 0.1


# ------------------------------------------------------------------------------------------------
# Infeasible and unbounded QPs
# ------------------------------------------------------------------------------------------------


@settings(QP_SETTINGS, max_examples=90)
@given(seed=seeds, shape=shapes, kind=st.sampled_from(["rows", "unreachable_row", "unreachable_state"]))
def test_infeasible_qps_are_certified_in_bounded_iterations(hq: Harness, seed: int, shape: Shape,
                                                           kind: str) -> None:
    rng = np.random.default_rng(seed)
    qp, _, _ = random_qp(rng, N, NG, shape)
    bad = make_infeasible(rng, qp, kind)
    r = hq.solve(bad)  # default options: max_iter 50
    assert r.status == INFEASIBLE, hq.status_message(r.status)
    assert r.iter <= 35
    stat, neg, value = certificate_errors(bad, r.sol)
    assert value == pytest.approx(1.0, abs=1e-9)
    assert neg == 0.0
    assert stat <= 1e-7
    assert np.all(r.sol.u == 0) and np.all(r.sol.x[1:] == 0)
    assert clarabel_solve(bad).status == "PrimalInfeasible"


def test_crossing_bounds_are_reported_before_any_iteration(hq: Harness) -> None:
    qp, _, _ = random_qp(np.random.default_rng(1), N, NG, Shape())
    qp.lbu[2, 1], qp.ubu[2, 1] = 0.5, 0.4
    r = hq.solve(qp)
    assert r.status == INFEASIBLE and r.iter == 0
    stat, neg, value = certificate_errors(qp, r.sol)
    assert (stat, neg) == (0.0, 0.0) and value == pytest.approx(1.0)


def test_unbounded_qp_is_a_numerical_failure_flagged_unbounded(hq: Harness) -> None:
    qp, _, _ = random_qp(np.random.default_rng(2), N, NG, Shape())
    # u_3[0]: no effect on the state, no curvature, bounded below only, cost falling as it grows
    qp.B[3][:, 0] = 0.0
    qp.R[3][0, :] = qp.R[3][:, 0] = 0.0
    qp.S[3][0] = 0.0
    qp.r[3, 0] = -1.0
    qp.lbu[3, 0], qp.ubu[3, 0] = -1.0, HM_INF
    r = hq.solve(qp)
    assert r.status == NUMERICAL and r.unbounded == 1
    assert clarabel_solve(qp).status == "DualInfeasible"


# ------------------------------------------------------------------------------------------------
# Data validation, absent rows, options
# ------------------------------------------------------------------------------------------------


NONFINITE_EDITS = [
    ("A", (2, 1, 3), np.nan), ("B", (0, 3, 1), np.inf), ("b", (4, 0), np.nan), ("Q", (6, 2, 2), np.inf),
    ("S", (1, 1, 3), np.nan), ("R", (5, 0, 1), -np.inf), ("q", (3, 1), np.nan), ("r", (0, 0), np.inf),
    ("x0", (2,), np.nan), ("lbu", (1, 0), np.nan), ("ubx", (4, 3), np.nan), ("D", (2, 0, 1), np.inf),
    ("lg", (2, 0), np.nan), ("zl", (2, 0), np.inf), ("Zl", (2, 0), np.nan),
]


@pytest.mark.parametrize(("field", "index", "value"), NONFINITE_EDITS, ids=[e[0] for e in NONFINITE_EDITS])
def test_nonfinite_data_is_rejected_before_any_work(hq: Harness, field: str, index: tuple[int, ...],
                                                    value: float) -> None:
    qp, _, _ = random_qp(np.random.default_rng(3), N, NG, Shape(soft_fraction=1.0))
    qp.ng[2] = max(qp.ng[2], 1)
    qp.soft[2, 0] = 1
    qp.lg[2, 0] = 0.0
    getattr(qp, field)[index] = value
    assert hq.check(qp) == NONFINITE
    r = hq.solve(qp)
    assert r.status == NONFINITE and r.iter == 0
    assert np.all(r.sol.u == 0) and np.all(r.sol.lam_lbx == 0)


@pytest.mark.parametrize("ng", [-1, NG + 1])
def test_row_count_out_of_range_is_invalid_data(hq: Harness, ng: int) -> None:
    qp, _, _ = random_qp(np.random.default_rng(4), N, NG, Shape())
    qp.ng[3] = ng
    assert hq.solve(qp).status == NONFINITE


def test_infinite_bounds_are_absent_not_invalid(hq: Harness) -> None:
    qp, _, _ = random_qp(np.random.default_rng(5), N, NG, Shape())
    ref = hq.solve(qp, tol=TOL)
    qp2 = qp.copy()
    for arr in (qp2.lbx, qp2.lbu):
        arr[np.abs(arr) >= HM_INF] = -np.inf
    for arr in (qp2.ubx, qp2.ubu):
        arr[np.abs(arr) >= HM_INF] = np.inf
    r = hq.solve(qp2, tol=TOL)
    assert r.status == SOLVED
    assert np.array_equal(r.sol.x, ref.sol.x) and np.array_equal(r.sol.u, ref.sol.u)


@settings(QP_SETTINGS, max_examples=40)
@given(seed=seeds, shape=shapes)
def test_absent_rows_and_ignored_data_change_nothing(hq: Harness, seed: int, shape: Shape) -> None:
    """Rows i >= ng, stage-0 rows and state bounds, and soft weights of hard rows may hold anything
    (random_qp fills them with NaN, Inf and junk): the solve is bit for bit that of clean data."""
    qp, _, _ = random_qp(np.random.default_rng(seed), N, NG, shape)
    clean = qp.copy()
    for n in range(N + 1):
        for i in range(NG):
            if n == 0 or i >= clean.ng[n]:
                clean.D[n, i] = 0.0
                clean.lg[n, i] = 0.0
                clean.soft[n, i] = 0
                clean.zl[n, i] = clean.Zl[n, i] = 0.0
            elif not clean.soft[n, i]:
                clean.zl[n, i] = clean.Zl[n, i] = 0.0
    clean.lbx[0], clean.ubx[0], clean.ng[0] = -HM_INF, HM_INF, 0
    a = hq.solve(qp, tol=TOL)
    b = hq.solve(clean, tol=TOL)
    assert a.status == b.status == SOLVED
    assert a.iter == b.iter
    for field in ("x", "u", "s", "pi", "lam_lbx", "lam_ubx", "lam_lbu", "lam_ubu", "lam_lg", "lam_ls"):
        assert np.array_equal(getattr(a.sol, field), getattr(b.sol, field)), field


@pytest.mark.parametrize("stop_after", [0, 1, 3])
def test_stop_hook_ends_the_solve_with_timeout(hq: Harness, stop_after: int) -> None:
    qp, _, _ = random_qp(np.random.default_rng(6), N, NG, Shape())
    r = hq.solve(qp, stop_after=stop_after)
    assert r.status == TIMEOUT
    assert r.iter == stop_after  # polled once per iteration, before its work
    assert r.polls == stop_after + 1


def test_stop_hook_that_never_fires_is_polled_once_per_iteration(hq: Harness) -> None:
    qp, _, _ = random_qp(np.random.default_rng(6), N, NG, Shape())
    r = hq.solve(qp, stop_after=10**6)
    assert r.status == SOLVED and r.polls == r.iter


def test_iteration_limit_gives_max_iter(hq: Harness) -> None:
    qp, _, _ = random_qp(np.random.default_rng(7), N, NG, Shape())
    r = hq.solve(qp, max_iter=2)
    assert r.status == MAX_ITER and r.iter == 2


def test_status_messages_are_distinct(hq: Harness) -> None:
    msgs = [hq.status_message(s) for s in range(6)]
    assert len(set(msgs)) == 6
    assert hq.status_message(17) == "unknown QP status"
    assert "infeasible" in msgs[INFEASIBLE].lower() and "deadline" in msgs[TIMEOUT]


def test_residual_helper_measures_what_it_claims(hq: Harness) -> None:
    """ocp_qp_res_compute against hand-made violations of a solved QP."""
    qp, _, _ = random_qp(np.random.default_rng(8), N, NG, Shape(bound_density=0.5))
    r = hq.solve(qp, tol=TOL)
    assert r.status == SOLVED
    base = hq.res_compute()
    assert base["stat"] <= 1e-7 and base["eq"] <= 1e-12
    sol = r.sol
    sol.x[3, 2] += 0.25  # breaks the dynamics into x_3 (by 0.25) and out of it (by 0.25 A_3[:, 2])
    hq.write_sol(sol)
    expected = 0.25 * max(1.0, float(np.max(np.abs(qp.A[3][:, 2]))))
    assert hq.res_compute()["eq"] == pytest.approx(expected, rel=1e-9)
    sol.x[3, 2] -= 0.25
    sol.lam_lbu[1, 0] = -0.5
    hq.write_sol(sol)
    res = hq.res_compute()
    assert res["dual"] == 0.5 and res["stat"] >= 0.5 - 1e-7
    sol.lam_lbu[1, 0] = r.sol.lam_lbu[1, 0] = 0.0
    sol.u[2, 1] = qp.ubu[2, 1] + 0.125 if abs(qp.ubu[2, 1]) < HM_INF else qp.lbu[2, 1] - 0.125
    hq.write_sol(sol)
    assert hq.res_compute()["ineq"] == pytest.approx(0.125, rel=1e-9)


def test_polish_gives_rounding_level_kkt_residuals_and_never_worse_ones(hq: Harness) -> None:
    """At the default tol, the active-set polish (arg.polish) replaces the iterate by the
    equality-constrained optimum of its active set: KKT residuals at rounding level, the solution
    Clarabel's to 1e-8; when it cannot improve the iterate it leaves it."""
    polished = 0
    for seed in range(40):
        shape = Shape(hessian=["pd", "singular_q", "lp_like"][seed % 3])
        qp, _, _ = random_qp(np.random.default_rng(seed), N, NG, shape)
        plain = hq.solve(qp, polish=0)
        r = hq.solve(qp, polish=1)
        assert plain.status == r.status == SOLVED and plain.polished == 0
        worst = max(r.res[k] for k in ("stat", "eq", "ineq", "comp", "dual"))
        assert worst <= max(plain.res[k] for k in ("stat", "eq", "ineq", "comp", "dual"))
        if r.polished:
            polished += 1
            assert worst <= 1e-12 * max(1.0, abs(r.res["obj"]))
            assert primal_error(qp, r.sol, clarabel_solve(qp)) <= 1e-8
    assert polished >= 36  # measured: 39 of 40


# ------------------------------------------------------------------------------------------------
# Single precision
# ------------------------------------------------------------------------------------------------


@settings(QP_SETTINGS, max_examples=60)
@given(seed=seeds, soft=st.sampled_from([0.0, 0.5]))
def test_float_build_solves_well_conditioned_qps(hq_float: Harness, seed: int, soft: float) -> None:
    """Float carries ~7 digits; on QPs whose Hessian eigenvalues lie in [0.5, ~3] and whose data are
    O(1) the solution is determined far better than the default single-precision tol 1e-4 asks for.
    That tol bounds the duality gap relative to the cost, and a row that is only weakly active at the
    stopping point is still ~sqrt(tol) inside its bound: primal errors of up to sqrt(1e-4) = 1e-2
    (relative to max(1, ||ref||)) are what the tolerance allows; measured over 200 such QPs: 7.5e-3
    at most, 4.3e-3 at the 99th percentile. Residuals are checked at float resolution."""
    rng = np.random.default_rng(seed)
    qp, _, _ = random_qp(rng, N, NG, Shape(soft_fraction=soft))
    for n in range(N + 1):
        M = rng.standard_normal((6, 6))
        H = M @ M.T / 12 + 0.5 * np.eye(6)
        qp.Q[n] = H[2:, 2:]
        if n < N:
            qp.R[n], qp.S[n] = H[:2, :2], H[:2, 2:]
    r = hq_float.solve(qp)
    ref = clarabel_solve(qp)
    assert r.status == SOLVED and ref.status == "Solved"
    assert primal_error(qp, r.sol, ref) <= 1e-2
    err = kkt_errors(qp, r.sol)
    assert err["eq"] <= 1e-5 and err["ineq"] <= 1e-4 and err["stat"] <= 1e-3


@settings(QP_SETTINGS, max_examples=20)
@given(seed=seeds, kind=st.sampled_from(["rows", "unreachable_row", "unreachable_state"]))
def test_float_build_certifies_infeasibility(hq_float: Harness, seed: int, kind: str) -> None:
    rng = np.random.default_rng(seed)
    qp, _, _ = random_qp(rng, N, NG, Shape())
    r = hq_float.solve(make_infeasible(rng, qp, kind))
    assert r.status == INFEASIBLE


# ------------------------------------------------------------------------------------------------
# Builds: strict flags with both compilers and precisions; sanitizers on the C self-test
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("cc", ["gcc", "clang"])
@pytest.mark.parametrize("real", ["double", "float"])
def test_runtime_compiles_cleanly_under_strict_flags(build_dir: Path, cc: str, real: str) -> None:
    defines = {"QPT_N": "5", "QPT_NG": "2"}
    if real == "float":
        defines["HM_REAL_IS_FLOAT"] = ""
    compile_c([CDIR / "qp_harness.c"], build_dir / f"strict_{cc}_{real}.so", defines, shared=True, cc=cc,
              extra=("-Wmissing-prototypes",))


@pytest.mark.parametrize("cc", ["gcc", "clang"])
@pytest.mark.parametrize("real", ["double", "float"])
def test_c_selftest_passes_under_address_and_undefined_sanitizers(build_dir: Path, cc: str, real: str) -> None:
    exe = build_dir / f"qp_selftest_{cc}_{real}"
    defines = {"HM_REAL_IS_FLOAT": ""} if real == "float" else {}
    compile_c([CDIR / "qp_selftest.c"], exe, defines, shared=False, cc=cc, opt="-O1",
              extra=("-g", "-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"))
    proc = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert proc.stdout.startswith("OK") or "OK:" in proc.stdout


def test_bench_program_builds_and_solves(build_dir: Path) -> None:
    exe = build_dir / "qp_bench"
    compile_c([CDIR / "qp_bench.c"], exe, {"QPB_N": "50", "QPB_NG": "6"}, shared=False)
    proc = subprocess.run([str(exe), "3"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0
    lines = proc.stdout.strip().splitlines()
    assert len(lines) == 4 and all("QP solved" in line for line in lines), proc.stdout


# ------------------------------------------------------------------------------------------------
# The row capacity: the solvers' memory for soft rows sized by the rows a QP may hold in all
# ------------------------------------------------------------------------------------------------

ROW_CAPACITY = 5  # of the N * NG = 18 rows the stages 1..N of these QPs can have


@pytest.fixture(scope="session")
def hq_rows(build_dir: Path) -> Harness:
    return Harness.build(build_dir, N, NG, rows=ROW_CAPACITY)


def _soft_rows(qp: QP) -> int:
    return sum(int(qp.soft[n, i] != 0 and present(qp.lg[n, i])) for n in range(1, N + 1) for i in range(qp.ng[n]))


def test_a_qp_within_the_row_capacity_is_solved_bit_for_bit_as_with_room_for_every_row(
        hq: Harness, hq_rows: Harness) -> None:
    assert hq_rows.rows == ROW_CAPACITY and hq.rows == (N + 1) * NG
    rng = np.random.default_rng(2611)
    checked = 0
    for _ in range(300):
        qp, _, _ = random_qp(rng, N, NG, Shape(soft_fraction=0.9))
        if _soft_rows(qp) > ROW_CAPACITY or _soft_rows(qp) == 0:
            continue
        for solve in ("solve", "solve_fallback"):
            whole, capped = getattr(hq, solve)(qp), getattr(hq_rows, solve)(qp)
            assert (capped.status, capped.iter, capped.fallback) == (whole.status, whole.iter, whole.fallback)
            for f in SOL_FIELDS:
                np.testing.assert_array_equal(getattr(capped.sol, f), getattr(whole.sol, f), err_msg=f"{solve}: {f}")
        checked += 1
    assert checked >= 20


def test_a_qp_beyond_the_row_capacity_is_refused_before_any_work(hq: Harness, hq_rows: Harness) -> None:
    rng = np.random.default_rng(2612)
    refused = 0
    for _ in range(100):
        qp, _, _ = random_qp(rng, N, NG, Shape(soft_fraction=0.9))
        if _soft_rows(qp) <= ROW_CAPACITY:
            continue
        assert hq.solve(qp).status != NONFINITE  # the same QP fits the solver with room for every row
        for r in (hq_rows.solve(qp), hq_rows.solve_fallback(qp)):
            assert r.status == NONFINITE and r.iter == 0
        refused += 1
    assert refused >= 10
