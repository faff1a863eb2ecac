"""The paper's OCP written a second time, independently of codegen/ocp.py, and solved by Ipopt.

This is the reference the SQP is judged against: the true problem with *hard* human distance rows
(the solver uses exact-penalty slacks on them), a soft obstacle row with an explicit slack, and the
same smoothed distance sqrt(dx^2 + dy^2 + eps^2) the spec documents (codegen/ocp.DIST_EPS).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

EPS = 1e-3  # the documented distance smoothing (codegen/ocp.DIST_EPS); a problem constant, not a tolerance


@dataclass
class Scene:
    x0: np.ndarray
    goal: np.ndarray  # (4,) the goal of every node, or (N+1, 4) a goal per node
    humans_now: np.ndarray  # (k, 2)
    humans_pred: np.ndarray  # (N+1, k, 2)
    obstacle: np.ndarray | None


@dataclass
class Params:
    N: int = 50
    dt: float = 0.1
    w_goal: tuple[float, ...] = (0.5, 0.5, 0.0, 250.0)
    w_goal_terminal: tuple[float, ...] = (40.0, 40.0, 2.0, 0.0)
    w_control: tuple[float, ...] = (0.0, 0.0)
    q: float = 2.0
    d_th: float = 1.0
    kappa: float = 5.0
    d_h: float = 0.5
    d_s: float = 0.5
    slack_l1: float = 100.0
    slack_l2: float = 100.0
    v: tuple[float, float] = (0.0, 1.0)
    a: tuple[float, float] = (-1.0, 1.0)
    omega: tuple[float, float] = (-1.5, 1.5)


@dataclass
class Solution:
    x: np.ndarray  # (N+1, 4)
    u: np.ndarray  # (N, 2)
    cost: float
    success: bool
    iterations: int
    stats: dict = field(default_factory=dict)


def _dist(p: ca.MX, c: np.ndarray) -> ca.MX:
    return ca.sqrt((p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 + EPS**2)


def _potential(d: ca.MX, q: float, d_th: float, kappa: float) -> ca.MX:
    # Paper eq. (f): linear below d_th, logistic above (evaluated safely on both sides).
    e = ca.exp(-kappa * (ca.fmax(d, d_th) - d_th))
    return ca.if_else(d <= d_th, -(kappa * q / 4) * d + (q / 2 + kappa * q * d_th / 4), q * e / (1 + e))


def _rk4(x: ca.MX, u: ca.MX, dt: float) -> ca.MX:
    def f(z: ca.MX) -> ca.MX:
        return ca.vertcat(z[3] * ca.cos(z[2]), z[3] * ca.sin(z[2]), u[1], u[0])

    k1 = f(x)
    k2 = f(x + dt / 2 * k1)
    k3 = f(x + dt / 2 * k2)
    k4 = f(x + dt * k3)
    return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def goal_at(goal: np.ndarray, n: int) -> np.ndarray:
    """The goal node n tracks."""
    return goal if goal.ndim == 1 else goal[n]


def objective(scene: Scene, pr: Params, x: np.ndarray, u: np.ndarray) -> float:
    """The NLP objective at a trajectory (obstacle slack at its smallest feasible value)."""
    total = 0.0
    g = scene.goal
    for n in range(pr.N + 1):
        w = np.array(pr.w_goal_terminal if n == pr.N else pr.w_goal)
        total += float(np.sum(w * (x[n] - goal_at(g, n)) ** 2))
        if n < pr.N:
            total += float(np.sum(np.array(pr.w_control) * u[n] ** 2))
        for i in range(scene.humans_now.shape[0]):
            d = float(np.sqrt(np.sum((x[n, :2] - scene.humans_pred[n, i]) ** 2) + EPS**2))
            total += float(_potential(d, pr.q, pr.d_th, pr.kappa))
        if n >= 1 and scene.obstacle is not None:
            d = float(np.sqrt(np.sum((x[n, :2] - scene.obstacle) ** 2) + EPS**2))
            s = max(0.0, pr.d_s - d)
            total += pr.slack_l1 * s + 0.5 * pr.slack_l2 * s * s
    return total


def solve_ipopt(scene: Scene, pr: Params, x_init: np.ndarray | None = None, u_init: np.ndarray | None = None,
                tol: float = 1e-10) -> Solution:
    opti = ca.Opti()
    N = pr.N
    X = opti.variable(4, N + 1)
    U = opti.variable(2, N)
    has_obs = scene.obstacle is not None
    S = opti.variable(N) if has_obs else None
    g = scene.goal
    cost = 0
    opti.subject_to(X[:, 0] == scene.x0)
    k = scene.humans_now.shape[0]
    for n in range(N + 1):
        w = pr.w_goal_terminal if n == N else pr.w_goal
        for j in range(4):
            cost += w[j] * (X[j, n] - goal_at(g, n)[j]) ** 2
        for i in range(k):
            cost += _potential(_dist(X[:2, n], scene.humans_pred[n, i]), pr.q, pr.d_th, pr.kappa)
        if n < N:
            cost += pr.w_control[0] * U[0, n] ** 2 + pr.w_control[1] * U[1, n] ** 2
            opti.subject_to(X[:, n + 1] == _rk4(X[:, n], U[:, n], pr.dt))
            opti.subject_to(opti.bounded(pr.a[0], U[0, n], pr.a[1]))
            opti.subject_to(opti.bounded(pr.omega[0], U[1, n], pr.omega[1]))
        if n >= 1:
            opti.subject_to(opti.bounded(pr.v[0], X[3, n], pr.v[1]))
            for i in range(k):
                opti.subject_to(_dist(X[:2, n], scene.humans_now[i]) >= pr.d_h)
            if has_obs:
                s = S[n - 1]
                opti.subject_to(_dist(X[:2, n], scene.obstacle) + s >= pr.d_s)
                opti.subject_to(s >= 0)
                cost += pr.slack_l1 * s + 0.5 * pr.slack_l2 * s**2
    opti.minimize(cost)
    if x_init is not None:
        opti.set_initial(X, x_init.T)
        opti.set_initial(U, u_init.T)
        if has_obs:
            d = np.sqrt(np.sum((x_init[1:, :2] - scene.obstacle) ** 2, axis=1) + EPS**2)
            opti.set_initial(S, np.maximum(0.0, pr.d_s - d) + 1e-9)
    else:
        opti.set_initial(X, np.tile(scene.x0, (N + 1, 1)).T)
    opti.solver("ipopt", {"print_time": False},
                {"print_level": 0, "sb": "yes", "tol": tol, "acceptable_tol": tol, "max_iter": 3000,
                 "mu_strategy": "adaptive"})
    try:
        sol = opti.solve()
        ok = True
        res = sol
    except RuntimeError:
        ok = False
        res = opti.debug
    stats = opti.stats()
    x = np.asarray(res.value(X)).T
    u = np.asarray(res.value(U)).T.reshape(N, 2)
    return Solution(x=x, u=u, cost=objective(scene, pr, x, u), success=ok and stats["success"],
                    iterations=int(stats["iter_count"]), stats=stats)
