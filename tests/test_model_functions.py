"""Generated model functions against CasADi's own evaluation, independent formulas and finite differences."""

from __future__ import annotations

import numpy as np
import pytest

import humanmpc
from humanmpc.codegen.ocp import DIST_EPS, OcpModel
from humanmpc.codegen.spec import Spec

SEEDS = list(range(8))
POINTS = 40


def random_state(rng: np.random.Generator) -> np.ndarray:
    return np.array([rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-np.pi, np.pi), rng.uniform(-0.5, 1.5)])


def paper_f(d: np.ndarray, q: float, d_th: float, kappa: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The paper's potential and its derivatives, written out by hand (independent of CasADi)."""
    d = np.asarray(d, dtype=float)
    lin = d <= d_th
    s = kappa * (d - d_th)
    es = np.exp(np.where(lin, 0.0, s))
    f = np.where(lin, -(kappa * q / 4) * d + (q / 2 + kappa * q * d_th / 4), q / (1 + es))
    f1 = np.where(lin, -kappa * q / 4, -q * kappa * es / (1 + es) ** 2)
    f2 = np.where(lin, 0.0, q * kappa**2 * es * (es - 1) / (1 + es) ** 3)
    return f, f1, f2


def central_jacobian(fun, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    cols = []
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        cols.append((np.atleast_1d(fun(x + e)) - np.atleast_1d(fun(x - e))) / (2 * h))
    return np.stack(cols, axis=-1)


def numpy_rk4(x: np.ndarray, u: np.ndarray, dt: float) -> np.ndarray:
    def ode(z: np.ndarray) -> np.ndarray:
        return np.array([z[3] * np.cos(z[2]), z[3] * np.sin(z[2]), u[1], u[0]])

    k1 = ode(x)
    k2 = ode(x + dt / 2 * k1)
    k3 = ode(x + dt / 2 * k2)
    k4 = ode(x + dt * k3)
    return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


@pytest.fixture(scope="module")
def casadi_model() -> OcpModel:
    return OcpModel(Spec())


def test_dimensions_match_the_spec(paper: humanmpc.Solver) -> None:
    d = paper.dims
    assert (d.nx, d.nu, d.N, d.nh, d.ng) == (4, 2, 50, 10, 11)
    assert d.dt == pytest.approx(0.1) and d.T == 5.0


def test_default_parameters_are_the_specs_values(paper: humanmpc.Solver) -> None:
    p = paper.params
    assert p["w_goal"] == (0.5, 0.5, 0.0, 250.0)
    assert p["w_goal_terminal"] == (40.0, 40.0, 2.0, 0.0)
    assert (p["q"], p["d_th"], p["kappa"], p["d_h"], p["d_s"]) == (2.0, 1.0, 5.0, 0.5, 0.5)
    assert p["v_bounds"] == (0.0, 1.0) and p["qp_max_iter"] == 50


@pytest.mark.parametrize("seed", SEEDS)
def test_c_functions_equal_casadis_evaluation(paper: humanmpc.Solver, casadi_model: OcpModel, seed: int) -> None:
    rng = np.random.default_rng(seed)
    for mf in casadi_model.functions:
        c_fn = getattr(paper.model, mf.name)
        for _ in range(POINTS):
            args = [rng.uniform(-3, 3, size=(p.rows, p.cols)) for p in mf.inputs]
            if mf.name in ("cost_collision", "cost_collision_gn"):
                args[4] = np.array([[rng.uniform(0.1, 20)]])  # kappa > 0
            expected = mf.function(*args)
            got = c_fn(*[a.reshape(-1) if a.shape[1] == 1 else a for a in args])
            for e, g in zip(expected, got, strict=True):
                np.testing.assert_allclose(np.asarray(g).reshape(e.shape), e.full(), rtol=1e-13, atol=1e-14)


@pytest.mark.parametrize("seed", SEEDS)
def test_dynamics_are_rk4_and_jacobians_match_finite_differences(paper: humanmpc.Solver, seed: int) -> None:
    rng = np.random.default_rng(seed)
    dyn = paper.model.dynamics
    for _ in range(POINTS):
        x, u = random_state(rng), rng.uniform(-1.5, 1.5, 2)
        r = dyn(x, u)
        np.testing.assert_allclose(r.x_next, numpy_rk4(x, u, paper.dims.dt), rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(r.A, central_jacobian(lambda z: dyn(z, u).x_next, x), atol=1e-8)
        np.testing.assert_allclose(r.B, central_jacobian(lambda w: dyn(x, w).x_next, u), atol=1e-8)


@pytest.mark.parametrize("seed", SEEDS)
def test_least_squares_costs_gradients_and_hessians(paper: humanmpc.Solver, seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(POINTS):
        x, u, g = random_state(rng), rng.uniform(-2, 2, 2), random_state(rng)
        wg, wu, wn = rng.uniform(0, 10, 4), rng.uniform(0, 10, 2), rng.uniform(0, 10, 4)
        st = paper.model.cost_stage(x, u, g, wg, wu)
        assert st.l == pytest.approx(np.sum(wg * (x - g) ** 2) + np.sum(wu * u**2), rel=1e-13)
        cost = paper.model.cost_stage
        np.testing.assert_allclose(st.grad_x, central_jacobian(lambda z: cost(z, u, g, wg, wu).l, x)[0],
                                   rtol=1e-7, atol=1e-6)
        np.testing.assert_allclose(st.grad_u, central_jacobian(lambda w: cost(x, w, g, wg, wu).l, u)[0],
                                   rtol=1e-7, atol=1e-6)
        np.testing.assert_allclose(st.hess_x, np.diag(2 * wg), atol=1e-12)
        np.testing.assert_allclose(st.hess_u, np.diag(2 * wu), atol=1e-12)
        tm = paper.model.cost_terminal(x, g, wn)
        assert tm.l == pytest.approx(np.sum(wn * (x - g) ** 2), rel=1e-13)
        np.testing.assert_allclose(tm.grad_x, 2 * wn * (x - g), rtol=1e-13, atol=1e-12)
        np.testing.assert_allclose(tm.hess_x, np.diag(2 * wn), atol=1e-12)


def smooth_dist(p: np.ndarray, c: np.ndarray) -> float:
    return float(np.sqrt(np.sum((p - c) ** 2) + DIST_EPS**2))


@pytest.mark.parametrize("seed", SEEDS)
def test_collision_cost_is_the_papers_potential_with_exact_gradient_and_gn_hessian(
    paper: humanmpc.Solver, seed: int
) -> None:
    rng = np.random.default_rng(seed)
    col = paper.model.cost_collision
    for i in range(POINTS):
        q, d_th, kappa = rng.uniform(0.5, 5), rng.uniform(0.2, 2.0), rng.uniform(0.5, 20)
        h = rng.uniform(-3, 3, 2)
        # Half the points inside d_th (linear branch), half outside (logistic branch).
        r = rng.uniform(0.05, d_th) if i % 2 else rng.uniform(d_th, d_th + 3)
        ang = rng.uniform(-np.pi, np.pi)
        p = h + r * np.array([np.cos(ang), np.sin(ang)])
        out = col(p, h, q, d_th, kappa)
        d = smooth_dist(p, h)
        f, _, f2 = paper_f(np.array(d), q, d_th, kappa)
        assert out.f == pytest.approx(float(f), rel=1e-12, abs=1e-14)
        fd_grad = central_jacobian(lambda z: col(z, h, q, d_th, kappa).f, p)[0]
        np.testing.assert_allclose(out.grad_p, fd_grad, rtol=1e-6, atol=1e-7)
        grad_d = central_jacobian(lambda z: paper.model.distance_constraint(z, h, 0.0).g, p)[0]
        np.testing.assert_allclose(out.hess_gn_p, float(f2) * np.outer(grad_d, grad_d), rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("seed", SEEDS)
def test_exact_second_derivatives_match_finite_differences(paper: humanmpc.Solver, seed: int) -> None:
    rng = np.random.default_rng(seed)
    col, con, dyn = paper.model.cost_collision, paper.model.distance_constraint, paper.model.dynamics
    for _ in range(POINTS // 2):
        h = rng.uniform(-3, 3, 2)
        p = h + rng.uniform(0.1, 3.0) * np.array([np.cos(a := rng.uniform(-np.pi, np.pi)), np.sin(a)])
        q, d_th, kappa = 2.0, rng.uniform(0.3, 2.0), rng.uniform(1, 10)
        fd_col = central_jacobian(lambda z: col(z, h, q, d_th, kappa).grad_p, p)
        np.testing.assert_allclose(col(p, h, q, d_th, kappa).hess_p, fd_col, rtol=1e-5, atol=1e-6)
        fd_con = central_jacobian(lambda z: con(z, h, 0.5).jac_p.reshape(-1), p)
        np.testing.assert_allclose(con(p, h, 0.5).hess_p, fd_con, rtol=1e-5, atol=1e-6)
        x, u, pi = random_state(rng), rng.uniform(-1.5, 1.5, 2), rng.uniform(-10, 10, 4)
        hs = paper.model.dynamics_hessian(x, u, pi)
        # d/dz of pi' [A B]: rows of the Hessian of pi' F(x, u)
        grad = lambda z: np.concatenate([pi @ dyn(z[:4], z[4:]).A, pi @ dyn(z[:4], z[4:]).B])  # noqa: E731
        H = central_jacobian(grad, np.concatenate([x, u]))
        np.testing.assert_allclose(hs.hess_xx, H[:4, :4], atol=1e-6)
        np.testing.assert_allclose(hs.hess_ux, H[4:, :4], atol=1e-6)
        np.testing.assert_allclose(hs.hess_uu, H[4:, 4:], atol=1e-6)


def test_gauss_newton_hessian_is_psd_everywhere_including_inside_d_th_and_at_zero(paper: humanmpc.Solver) -> None:
    rng = np.random.default_rng(7)
    col = paper.model.cost_collision
    cases = []
    for _ in range(300):
        h = rng.uniform(-3, 3, 2)
        cases.append((h + rng.uniform(-4, 4, 2), h))  # anywhere
        cases.append((h + rng.uniform(-0.5, 0.5, 2), h))  # inside d_th = 1
        cases.append((h.copy(), h))  # distance 0
    for p, h in cases:
        for q, d_th, kappa in [(2.0, 1.0, 5.0), (rng.uniform(0, 10), rng.uniform(0, 3), rng.uniform(0.1, 50))]:
            H = col(p, h, q, d_th, kappa).hess_gn_p
            assert np.all(np.isfinite(H))
            np.testing.assert_allclose(H, H.T, atol=1e-14)
            assert np.linalg.eigvalsh(H).min() >= -1e-12 * max(1.0, np.abs(H).max())
    p = np.array([1.0, 2.0])
    out = col(p, p, 2.0, 1.0, 5.0)
    assert np.all(out.grad_p == 0.0) and np.all(out.hess_gn_p == 0.0)


def test_potential_is_c2_and_convex(casadi_model: OcpModel) -> None:
    q, d_th, kappa = 2.0, 1.0, 5.0
    ds = np.linspace(0.0, 8.0, 4001)
    vals = np.array([[float(v) for v in casadi_model.potential(d, q, d_th, kappa)] for d in ds])
    f, f1, f2 = paper_f(ds, q, d_th, kappa)
    np.testing.assert_allclose(vals[:, 0], f, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(vals[:, 1], f1, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(vals[:, 2], f2, rtol=1e-9, atol=1e-12)
    assert vals[:, 2].min() >= 0.0  # convex in d
    eps = 1e-9
    left = np.array([float(v) for v in casadi_model.potential(d_th - eps, q, d_th, kappa)])
    right = np.array([float(v) for v in casadi_model.potential(d_th + eps, q, d_th, kappa)])
    np.testing.assert_allclose(left, right, atol=1e-7)  # f, f', f'' continuous at d_th
    assert left[0] == pytest.approx(q / 2)


def test_potential_never_overflows_for_extreme_parameters(paper: humanmpc.Solver) -> None:
    for d in (0.0, 1e-3, 0.9, 1.0, 50.0, 1e6):
        out = paper.model.cost_collision([d, 0.0], [0.0, 0.0], 1e6, 100.0, 1e3)
        assert np.isfinite(out.f) and np.all(np.isfinite(out.grad_p)) and np.all(np.isfinite(out.hess_gn_p))


@pytest.mark.parametrize("seed", SEEDS)
def test_distance_rows_and_jacobians(paper: humanmpc.Solver, seed: int) -> None:
    rng = np.random.default_rng(seed)
    con = paper.model.distance_constraint
    for _ in range(POINTS):
        p, c, dmin = rng.uniform(-3, 3, 2), rng.uniform(-3, 3, 2), rng.uniform(0, 1)
        out = con(p, c, dmin)
        assert out.g == pytest.approx(np.linalg.norm(p - c) - dmin, abs=DIST_EPS**2 / max(np.linalg.norm(p - c), 1e-3))
        np.testing.assert_allclose(out.jac_p.reshape(-1), central_jacobian(lambda z: con(z, c, dmin).g, p)[0],
                                   rtol=1e-6, atol=1e-8)


def test_wrong_shapes_raise_clear_errors(paper: humanmpc.Solver) -> None:
    with pytest.raises(ValueError, match=r"dynamics\(\): input 'x' must be shape \(4,\), got shape \(3,\)"):
        paper.model.dynamics([0, 0, 0], [0, 0])
    with pytest.raises(ValueError, match=r"input 'q' must be a scalar"):
        paper.model.cost_collision([0, 0], [1, 1], [1, 2], 1.0, 5.0)
    with pytest.raises(TypeError, match=r"takes 2 inputs \(x, u\), got 1"):
        paper.model.dynamics([0, 0, 0, 0])
