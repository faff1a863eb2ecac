"""The whole OCP of a spec as ONE nonlinear program, for Ipopt: our problem, built from codegen/ocp.py.

This is the reference the real-time solvers are compared with (sub-optimality, step times). It is
*our* problem, not a re-derivation: the dynamics (``rk4_step``), the smoothed distance
(``smooth_distance``) and the collision potential (``collision_potential``) are the functions of
codegen/ocp.py that the generated solver uses. What differs from the RTI solver is only the
method: the human rows are hard (no exact-penalty slack), the obstacle row keeps its explicit
slack, and the Hessian of the Lagrangian is exact.

Decision vector ``w`` (NW = 4 (N+1) + 2 N + N entries), in blocks:

    X = [x_0, ..., x_N]          x_n = [px, py, theta, v]      offset 0
    U = [u_0, ..., u_{N-1}]      u_n = [a, omega]              offset 4 (N+1)
    S = [s_1, ..., s_N]          obstacle slack at node n >= 1 offset 4 (N+1) + 2 N

Objective (the paper's, ||r||^2_W = r' diag(W) r)::

    sum_{n<N} ||x_n - g||^2_Wg + ||u_n||^2_Wu  +  ||x_N - g||^2_WgN
    + sum_{n=0..N} sum_{i active} f(d(p_n, h_{i,n}))  +  sum_{n=1..N} l1 s_n + 0.5 l2 s_n^2

Constraints ``g(w)`` (NG rows), in blocks:

    x_0 - x0 = 0                                         4 rows
    x_{n+1} - F(x_n, u_n) = 0, n = 0..N-1                4 N rows (F: RK4 of codegen/ocp.py)
    d(p_n, h_{i,now}) >= d_h, n = 1..N, i = 1..N_h       N N_h rows (hard; free row when i inactive)
    d(p_n, o) + s_n >= d_s, n = 1..N                     N rows (free rows when there is no obstacle)

Bounds: v in bounds.v at n = 1..N, a and omega in their bounds, s >= 0. A row or bound that does not
apply is written as +-INF = 1e20, which Ipopt reads as infinite (its nlp_*_bound_inf is 1e19).

Parameter vector ``p`` (N_PARAM entries): one step's inputs and the runtime parameters, see
``ParamLayout``. The C program (templates/ipopt_reference.c.j2) receives it per step from the replay
file and never needs to know its layout, except x0 at offset 0 (warm start).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import params as params_table
from .casadi_emit import make_helpers_static, make_parameters_used
from .ocp import NU, NX, collision_potential, rk4_step, smooth_distance
from .spec import Spec

FloatArray = NDArray[np.float64]

INF = 1e20  # what "no bound" is written as; Ipopt's nlp_lower/upper_bound_inf default is -/+1e19

# The runtime parameters that define the problem (names as in <name>_params), with their sizes.
# (name, size) of the problem parameters: the rows of the parameter table that define the OCP.
PROBLEM_PARAMS: tuple[tuple[str, int], ...] = tuple((p.name, p.size) for p in params_table.PROBLEM_PARAMS)


def problem_params(spec: Spec) -> dict[str, float | tuple[float, ...]]:
    """The spec's values of the problem parameters (the defaults of the solver's runtime parameters)."""
    values = params_table.spec_params(spec)
    return {name: values[name] for name, _ in PROBLEM_PARAMS}


def check_problem_params(params: Mapping[str, Any]) -> dict[str, FloatArray]:
    """Every problem parameter present, of the right size and finite; returns them as arrays."""
    problems = []
    out: dict[str, FloatArray] = {}
    for key, size in PROBLEM_PARAMS:
        if key not in params:
            problems.append(f"{key}: missing")
            continue
        arr = np.asarray(params[key], dtype=np.float64).reshape(-1)
        if arr.size != size:
            problems.append(f"{key}: has {arr.size} value(s), needs {size}")
        elif not np.all(np.isfinite(arr)):
            problems.append(f"{key}: {params[key]!r} is not finite")
        else:
            out[key] = arr
    unknown = sorted(set(params) - {k for k, _ in PROBLEM_PARAMS})
    if unknown:
        problems.append(f"unknown parameter(s) {', '.join(unknown)}; known: {', '.join(k for k, _ in PROBLEM_PARAMS)}")
    if problems:
        raise ValueError("problem parameters are not usable:\n  - " + "\n  - ".join(problems))
    return out


def _per_node_goal(goal: ArrayLike, N: int) -> FloatArray:
    """(N + 1, NX): a goal (NX,) repeated at every node, or a goal per node as given."""
    g = np.asarray(goal, dtype=np.float64)
    if g.shape == (NX,):
        return np.tile(g, (N + 1, 1))
    if g.shape != (N + 1, NX):
        raise ValueError(f"goal must have shape ({NX},) or (N+1, {NX}) = ({N + 1}, {NX}), got {g.shape}")
    return g


@dataclass(frozen=True)
class ParamLayout:
    """Offsets of one step's inputs and of the runtime parameters in the parameter vector p."""

    N: int
    NH: int

    @property
    def fields(self) -> tuple[tuple[str, tuple[int, ...]], ...]:
        N, NH = self.N, self.NH
        step = (
            ("x0", (NX,)),
            ("goal", (N + 1, NX)),   # a goal per node (one goal: the same at every node)
            ("humans_now", (NH, 2)),
            ("humans_pred", (N + 1, NH, 2)),
            ("human_active", (NH,)),
            ("obstacle", (2,)),
            ("has_obstacle", (1,)),
        )
        return step + tuple((k, (n,)) for k, n in PROBLEM_PARAMS)

    def offsets(self) -> dict[str, tuple[int, tuple[int, ...]]]:
        out, at = {}, 0
        for key, shape in self.fields:
            out[key] = (at, shape)
            at += int(np.prod(shape))
        return out

    @property
    def size(self) -> int:
        return sum(int(np.prod(s)) for _, s in self.fields)

    def split(self, p: Any) -> dict[str, Any]:
        """Views of a symbolic (or numeric 1-D) p by field; multi-dimensional fields stay flat (C order)."""
        return {k: p[o : o + int(np.prod(s))] for k, (o, s) in self.offsets().items()}

    def pack(self, x0: ArrayLike, goal: ArrayLike, humans_now: ArrayLike | None, humans_pred: ArrayLike | None,
             obstacle: ArrayLike | None, params: Mapping[str, Any]) -> FloatArray:
        """p for one step: humans_now (k, 2) and humans_pred (N+1, k, 2) with k <= N_h, obstacle (2,) or None."""
        N, NH = self.N, self.NH
        now = np.zeros((0, 2)) if humans_now is None else np.asarray(humans_now, dtype=np.float64)
        k = now.shape[0] if now.ndim == 2 else -1
        if now.ndim != 2 or now.shape[1] != 2:
            raise ValueError(f"humans_now must have shape (k, 2), got {now.shape}")
        if k > NH:
            raise ValueError(f"{k} humans given but the problem was built for at most N_h = {NH}")
        pred = np.zeros((N + 1, 0, 2)) if humans_pred is None else np.asarray(humans_pred, dtype=np.float64)
        if pred.shape != (N + 1, k, 2):
            raise ValueError(f"humans_pred must have shape (N+1, k, 2) = ({N + 1}, {k}, 2), got {pred.shape}")
        values: dict[str, FloatArray] = {
            "x0": np.asarray(x0, dtype=np.float64).reshape(NX),
            "goal": _per_node_goal(goal, N),
        }
        hn = np.zeros((NH, 2))
        hn[:k] = now
        hp = np.zeros((N + 1, NH, 2))
        hp[:, :k] = pred
        active = np.zeros(NH)
        active[:k] = 1.0
        values.update(humans_now=hn, humans_pred=hp, human_active=active)
        if obstacle is None:
            values["obstacle"], values["has_obstacle"] = np.zeros(2), np.zeros(1)
        else:
            values["obstacle"], values["has_obstacle"] = np.asarray(obstacle, dtype=np.float64).reshape(2), np.ones(1)
        values.update(check_problem_params(params))
        p = np.empty(self.size)
        for key, (o, shape) in self.offsets().items():
            arr = np.asarray(values[key], dtype=np.float64)
            if arr.size != int(np.prod(shape)):
                raise ValueError(f"{key} must have {int(np.prod(shape))} entries, got shape {arr.shape}")
            p[o : o + arr.size] = arr.reshape(-1)
        if not np.all(np.isfinite(p)):
            bad = [k for k, (o, s) in self.offsets().items() if not np.all(np.isfinite(p[o : o + int(np.prod(s))]))]
            raise ValueError(f"non-finite inputs: {', '.join(bad)}")
        return p


@dataclass(frozen=True)
class DecisionLayout:
    """Offsets of X, U and S in the decision vector w."""

    N: int

    @property
    def x_offset(self) -> int:
        return 0

    @property
    def u_offset(self) -> int:
        return NX * (self.N + 1)

    @property
    def s_offset(self) -> int:
        return NX * (self.N + 1) + NU * self.N

    @property
    def size(self) -> int:
        return self.s_offset + self.N

    def unpack(self, w: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """X (..., N+1, 4), U (..., N, 2), S (..., N) from w (..., NW)."""
        a = np.asarray(w, dtype=np.float64)
        lead = a.shape[:-1]
        X = a[..., : self.u_offset].reshape(*lead, self.N + 1, NX)
        U = a[..., self.u_offset : self.s_offset].reshape(*lead, self.N, NU)
        S = a[..., self.s_offset :].reshape(*lead, self.N)
        return X, U, S

    def pack(self, X: ArrayLike, U: ArrayLike, S: ArrayLike | None = None) -> FloatArray:
        Xa = np.asarray(X, dtype=np.float64).reshape(self.N + 1, NX)
        Ua = np.asarray(U, dtype=np.float64).reshape(self.N, NU)
        Sa = np.zeros(self.N) if S is None else np.asarray(S, dtype=np.float64).reshape(self.N)
        return np.concatenate([Xa.reshape(-1), Ua.reshape(-1), Sa])


class ReferenceNlp:
    """The NLP of a spec as CasADi functions of (w, p): objective, constraints and their derivatives.

    Every function is built from per-node SX functions (stage cost, RK4 step, distance rows; each
    evaluated over the nodes with ``Function.map``), so the generated C holds each of them once and
    loops over the nodes. The derivatives are assembled from per-node derivatives taken only with
    respect to the node's own variables: the Jacobian and the Hessian are returned as vectors of
    nonzeros whose (row, col) positions are ``jac_pattern`` / ``hess_pattern``.

    Generated into C by ``generate_c``:

    - ``f(w, p) -> f``; ``grad_f(w, p) -> grad`` (dense NW)
    - ``g(w, p) -> g`` (dense NG); ``jac_g(w, p) -> J_nz`` (nonzeros at ``jac_pattern``)
    - ``hess_l(w, p, sigma, lam) -> H_nz``: lower triangle of sigma * hess f + sum_j lam_j hess g_j
      (the exact Hessian of the Lagrangian, nonzeros at ``hess_pattern``)
    - ``bounds(p) -> lbw, ubw, lbg, ubg``; ``cold_guess(p) -> w0`` (x_n = x0, u = 0, s = 0)

    Not generated, for evaluating other solvers' plans with one common function:

    - ``plan_cost(X, U, p)``: the objective with each obstacle slack at its smallest feasible value
    - ``rollout(x0, U) -> X``: the model's trajectory under the controls U from x0
    """

    def __init__(self, spec: Spec) -> None:
        self.spec = spec
        N, NH = spec.horizon.N, spec.humans.max
        self.N, self.NH = N, NH
        self.params = ParamLayout(N, NH)
        self.decision = DecisionLayout(N)
        NW, N_PARAM = self.decision.size, self.params.size
        uo, so = self.decision.u_offset, self.decision.s_offset
        dt, steps = spec.dt, spec.integrator.steps

        # ---- per-node SX functions, from codegen/ocp.py ----------------------------------------
        x, u = ca.SX.sym("x", NX), ca.SX.sym("u", NU)
        hp, hn = ca.SX.sym("h_pred", 2 * NH), ca.SX.sym("h_now", 2 * NH)
        gs, act = ca.SX.sym("goal", NX), ca.SX.sym("active", NH)
        wgs, wgNs, wus = ca.SX.sym("w_goal", NX), ca.SX.sym("w_goal_terminal", NX), ca.SX.sym("w_control", NU)
        qs, dths, kappas = ca.SX.sym("q"), ca.SX.sym("d_th"), ca.SX.sym("kappa")
        os_, ss = ca.SX.sym("o", 2), ca.SX.sym("s")
        sigma_s, lam_d = ca.SX.sym("sigma"), ca.SX.sym("lam_dyn", NX)
        mu_h, mu_o = ca.SX.sym("mu_h", NH), ca.SX.sym("mu_o")
        pos = x[:2]

        col = ca.SX(0)
        for i in range(NH):
            col += act[i] * collision_potential(smooth_distance(pos, hp[2 * i : 2 * i + 2]), qs, dths, kappas)
        r = x - gs
        l_stage = ca.dot(wgs * r, r) + ca.dot(wus * u, u) + col
        l_terminal = ca.dot(wgNs * r, r) + col
        x_next = rk4_step(x, u, dt, steps)
        d_humans = ca.vertcat(*[smooth_distance(pos, hn[2 * i : 2 * i + 2]) for i in range(NH)]) if NH else ca.SX(0, 1)
        d_obstacle = smooth_distance(pos, os_)
        xu = ca.vertcat(x, u)
        rows_value = ca.dot(mu_h, d_humans) + mu_o * d_obstacle  # the distance rows' part of the Lagrangian

        def lower(H: ca.SX) -> ca.SX:
            """Lower triangle of a dense square matrix, column by column (the order of hess_pattern)."""
            n = H.size1()
            return ca.vertcat(*[H[r_, c] for c in range(n) for r_ in range(c, n)])

        cost_in = [gs, act, qs, dths, kappas]

        def dense_fn(name: str, ins: list[ca.SX], outs: list[ca.SX]) -> ca.Function:
            return ca.Function(name, ins, [ca.densify(o) for o in outs])  # dense: nonzeros at fixed places

        stage_cost = dense_fn("stage_cost", [x, u, hp, *cost_in, wgs, wus], [l_stage])
        terminal_cost = dense_fn("terminal_cost", [x, hp, *cost_in, wgNs], [l_terminal])
        stage_grad = dense_fn("stage_grad", [x, u, hp, *cost_in, wgs, wus], [ca.gradient(l_stage, xu)])
        terminal_grad = dense_fn("terminal_grad", [x, hp, *cost_in, wgNs], [ca.gradient(l_terminal, x)])
        dynamics = dense_fn("dynamics", [x, u], [x_next])
        # Dynamics rows x_{n+1} - F(x_n, u_n): nonzeros d/dx_n (-A), d/du_n (-B), d/dx_{n+1} (I).
        jac_dyn = ca.vertcat(ca.vec(-ca.jacobian(x_next, x)), ca.vec(-ca.jacobian(x_next, u)), ca.DM.ones(NX))
        dyn_jac = dense_fn("dyn_jac", [x, u], [jac_dyn])
        human_rows = dense_fn("human_rows", [x, hn], [d_humans])
        human_jac = dense_fn("human_jac", [x, hn], [ca.vec(ca.jacobian(d_humans, pos)) if NH else ca.SX(0, 1)])
        obstacle_row = dense_fn("obstacle_row", [x, os_, ss], [d_obstacle + ss])
        obstacle_jac = dense_fn("obstacle_jac", [x, os_], [ca.vertcat(ca.jacobian(d_obstacle, pos).T, 1)])
        lag_stage = sigma_s * l_stage - ca.dot(lam_d, x_next) + rows_value
        stage_hess = dense_fn("stage_hess", [x, u, sigma_s, lam_d, mu_h, mu_o, hp, hn, os_, *cost_in, wgs, wus],
                       [lower(ca.hessian(lag_stage, xu)[0])])
        lag_terminal = sigma_s * l_terminal + rows_value
        terminal_hess = dense_fn("terminal_hess", [x, sigma_s, mu_h, mu_o, hp, hn, os_, *cost_in, wgNs],
                          [lower(ca.hessian(lag_terminal, x)[0])])
        self.stage_functions = (stage_cost, terminal_cost, dynamics, human_rows, obstacle_row)

        # ---- the NLP in MX over the whole horizon ------------------------------------------------
        w = ca.MX.sym("w", NW)
        p = ca.MX.sym("p", N_PARAM)
        P = self.params.split(p)
        X = ca.reshape(w[:uo], NX, N + 1)
        U = ca.reshape(w[uo:so], NU, N)
        S = ca.reshape(w[so:], 1, N)
        HP = ca.reshape(P["humans_pred"], 2 * NH, N + 1)
        x0, hnow, obstacle = P["x0"], P["humans_now"], P["obstacle"]
        # the goals node by node (C order: node-major), as the stage functions' columns
        G = ca.reshape(P["goal"], NX, N + 1)
        rest = [P["human_active"], P["q"], P["d_th"], P["kappa"]]
        cin = [G[:, :N], *rest]
        cin_N = [G[:, N], *rest]
        l1, l2 = P["slack_l1"], P["slack_l2"]

        f = (ca.sum2(stage_cost.map(N)(X[:, :N], U, HP[:, :N], *cin, P["w_goal"], P["w_control"]))
             + terminal_cost(X[:, N], HP[:, N], *cin_N, P["w_goal_terminal"])
             + ca.sum2(l1 * S + 0.5 * l2 * S**2))
        GXU = stage_grad.map(N)(X[:, :N], U, HP[:, :N], *cin, P["w_goal"], P["w_control"])
        gX = ca.horzcat(GXU[:NX, :], terminal_grad(X[:, N], HP[:, N], *cin_N, P["w_goal_terminal"]))
        grad = ca.vertcat(ca.vec(gX), ca.vec(GXU[NX:, :]), ca.vec(l1 + l2 * S))

        g_rows = [X[:, 0] - x0, ca.vec(X[:, 1:] - dynamics.map(N)(X[:, :N], U))]
        if NH:
            g_rows.append(ca.vec(human_rows.map(N)(X[:, 1:], hnow)))
        g_rows.append(ca.vec(obstacle_row.map(N)(X[:, 1:], obstacle, S)))
        g = ca.vertcat(*g_rows)
        NG = g.size1()
        self.ng = NG
        self.row_offsets = {"x0": 0, "dynamics": NX, "humans": NX * (N + 1), "obstacle": NX * (N + 1) + N * NH}

        jac_parts: list[Any] = [ca.DM.ones(NX), ca.vec(dyn_jac.map(N)(X[:, :N], U))]
        if NH:
            jac_parts.append(ca.vec(human_jac.map(N)(X[:, 1:], hnow)))
        jac_parts.append(ca.vec(obstacle_jac.map(N)(X[:, 1:], obstacle)))
        jac_nz = ca.vertcat(*jac_parts)

        sigma = ca.MX.sym("sigma")
        lam = ca.MX.sym("lam", NG)
        ro = self.row_offsets
        LD = ca.reshape(lam[ro["dynamics"] : ro["humans"]], NX, N)
        MH = ca.reshape(lam[ro["humans"] : ro["obstacle"]], NH, N)  # rows at nodes 1..N
        MO = ca.reshape(lam[ro["obstacle"] :], 1, N)
        # Node n < N carries the rows of node n (none at n = 0); node N its own.
        MHs = ca.horzcat(ca.MX.zeros(NH, 1), MH[:, : N - 1])
        MOs = ca.horzcat(ca.MX.zeros(1, 1), MO[:, : N - 1])
        hess_nz = ca.vertcat(
            ca.vec(stage_hess.map(N)(X[:, :N], U, sigma, LD, MHs, MOs, HP[:, :N], hnow, obstacle, *cin,
                                     P["w_goal"], P["w_control"])),
            terminal_hess(X[:, N], sigma, MH[:, N - 1], MO[:, N - 1], HP[:, N], hnow, obstacle, *cin_N,
                          P["w_goal_terminal"]),
            ca.vec(ca.repmat(sigma * l2, N, 1)),
        )

        self.f = ca.Function("f", [w, p], [f], ["w", "p"], ["f"])
        self.grad_f = ca.Function("grad_f", [w, p], [grad], ["w", "p"], ["grad"])
        self.g = ca.Function("g", [w, p], [g], ["w", "p"], ["g"])
        self.jac_g = ca.Function("jac_g", [w, p], [jac_nz], ["w", "p"], ["J_nz"])
        self.hess_l = ca.Function("hess_l", [w, p, sigma, lam], [hess_nz], ["w", "p", "sigma", "lam"], ["H_nz"])
        self.jac_pattern = self._jac_pattern()
        self.hess_pattern = self._hess_pattern()
        for fn, (rows, _) in ((self.jac_g, self.jac_pattern), (self.hess_l, self.hess_pattern)):
            sp = fn.sparsity_out(0)
            assert sp.is_dense() and sp.numel() == len(rows), f"{fn.name()}: values and pattern disagree"

        # ---- bounds and the cold start, SX functions of p ---------------------------------------
        ps = ca.SX.sym("p", N_PARAM)
        Ps = self.params.split(ps)
        active_s, has_obstacle = Ps["human_active"], Ps["has_obstacle"]
        vb, ab, ob = Ps["v_bounds"], Ps["a_bounds"], Ps["omega_bounds"]

        def on(flag: ca.SX, value: ca.SX) -> ca.SX:
            return ca.if_else(flag > 0.5, value, -INF)

        lbg = [ca.SX.zeros(NX * (N + 1))]
        for _ in range(1, N + 1):
            lbg += [on(active_s[i], Ps["d_h"]) for i in range(NH)]
        lbg += [on(has_obstacle[0], Ps["d_s"])] * N
        ubg = ca.vertcat(ca.DM.zeros(NX * (N + 1)), ca.DM.ones(NG - NX * (N + 1)) * INF)
        lbw = ca.SX(np.full(NW, -INF))
        ubw = ca.SX(np.full(NW, INF))
        for n in range(1, N + 1):
            lbw[NX * n + 3], ubw[NX * n + 3] = vb[0], vb[1]
        for n in range(N):
            lbw[uo + NU * n], ubw[uo + NU * n] = ab[0], ab[1]
            lbw[uo + NU * n + 1], ubw[uo + NU * n + 1] = ob[0], ob[1]
            lbw[so + n] = 0.0
        self.bounds = ca.Function(
            "bounds", [ps], [ca.densify(lbw), ca.densify(ubw), ca.densify(ca.vertcat(*lbg)), ca.densify(ca.SX(ubg))],
            ["p"], ["lbw", "ubw", "lbg", "ubg"],
        )
        guess = ca.vertcat(*([Ps["x0"]] * (N + 1)), ca.SX.zeros(NU * N + N))
        self.cold_guess = ca.Function("cold_guess", [ps], [guess], ["p"], ["w0"])

        # ---- common evaluation of other solvers' plans -------------------------------------------
        # The objective with each slack at its smallest feasible value s_n = max(0, d_s - d(p_n, o))
        # (0 without an obstacle).
        Xm, Um, pm = ca.MX.sym("X", N + 1, NX), ca.MX.sym("U", N, NU), ca.MX.sym("p", N_PARAM)
        Pm = self.params.split(pm)
        dist_o = obstacle_row.map(N)(Xm[1:, :].T, Pm["obstacle"], 0)
        s_min = Pm["has_obstacle"] * ca.fmax(0, Pm["d_s"] - dist_o)
        w_plan = ca.vertcat(ca.vec(Xm.T), ca.vec(Um.T), s_min.T)
        self.plan_cost = ca.Function("plan_cost", [Xm, Um, pm], [self.f(w_plan, pm)], ["X", "U", "p"], ["cost"])
        Us = ca.SX.sym("U", N, NU)
        xr = ca.SX.sym("x0", NX)
        traj = [xr]
        for n in range(N):
            traj.append(rk4_step(traj[-1], Us[n, :].T, dt, steps))
        self.rollout = ca.Function("rollout", [xr, Us], [ca.horzcat(*traj).T], ["x0", "U"], ["X"])

    # ---- sparsity patterns (the order of the generated nonzeros) ---------------------------------
    def _jac_pattern(self) -> tuple[list[int], list[int]]:
        N, NH = self.N, self.NH
        uo, so = self.decision.u_offset, self.decision.s_offset
        ro = self.row_offsets
        rows: list[int] = []
        cols: list[int] = []
        for k in range(NX):  # x_0 - x0
            rows.append(k)
            cols.append(k)
        for n in range(N):  # column-major blocks: -A (4x4), -B (4x2), I (4)
            r0 = ro["dynamics"] + NX * n
            for c in range(NX):
                rows += [r0 + k for k in range(NX)]
                cols += [NX * n + c] * NX
            for c in range(NU):
                rows += [r0 + k for k in range(NX)]
                cols += [uo + NU * n + c] * NX
            rows += [r0 + k for k in range(NX)]
            cols += [NX * (n + 1) + k for k in range(NX)]
        for n in range(1, N + 1):  # human rows at node n: column-major (NH x 2) wrt px, py
            r0 = ro["humans"] + NH * (n - 1)
            for c in range(2):
                rows += [r0 + i for i in range(NH)]
                cols += [NX * n + c] * NH
        for n in range(1, N + 1):  # obstacle row at node n: px, py, s_n
            r = ro["obstacle"] + n - 1
            rows += [r, r, r]
            cols += [NX * n, NX * n + 1, so + n - 1]
        return rows, cols

    def _hess_pattern(self) -> tuple[list[int], list[int]]:
        N = self.N
        uo, so = self.decision.u_offset, self.decision.s_offset
        rows: list[int] = []
        cols: list[int] = []

        def var(n: int, k: int) -> int:
            return NX * n + k if k < NX else uo + NU * n + (k - NX)

        for n in range(N):
            for c in range(NX + NU):
                for r in range(c, NX + NU):
                    rows.append(var(n, r))
                    cols.append(var(n, c))
        for c in range(NX):
            for r in range(c, NX):
                rows.append(NX * N + r)
                cols.append(NX * N + c)
        for n in range(N):
            rows.append(so + n)
            cols.append(so + n)
        return rows, cols

    @property
    def nw(self) -> int:
        return self.decision.size

    @property
    def n_param(self) -> int:
        return self.params.size

    def generated_functions(self) -> list[ca.Function]:
        return [self.f, self.grad_f, self.g, self.jac_g, self.hess_l, self.bounds, self.cold_guess]

    def nlp_solver(self, tol: float = 1e-10, max_iter: int = 3000, print_level: int = 0) -> ca.Function:
        """CasADi's own Ipopt on the same NLP, with CasADi's own derivatives (the cross-check of the C program)."""
        w = ca.MX.sym("w", self.nw)
        p = ca.MX.sym("p", self.n_param)
        nlp = {"x": w, "p": p, "f": self.f(w, p), "g": self.g(w, p)}
        return ca.nlpsol("reference", "ipopt", nlp, {
            "print_time": False,
            "ipopt": ipopt_options(tol, max_iter, print_level),
        })


def ipopt_options(tol: float, max_iter: int, print_level: int = 0) -> dict[str, Any]:
    """The Ipopt options of the reference, the same for the C program and CasADi's nlpsol."""
    return {
        "tol": float(tol),
        "acceptable_tol": float(tol),
        "max_iter": int(max_iter),
        "print_level": int(print_level),
        "sb": "yes",
        "mu_strategy": "adaptive",
    }


@dataclass(frozen=True)
class GeneratedNlp:
    """What the C program template needs about the generated NLP functions."""

    c_file: Path
    h_file: Path
    prefix: str
    nw: int
    ng: int
    n_param: int
    jac_rows: list[int]
    jac_cols: list[int]
    hess_rows: list[int]
    hess_cols: list[int]
    sz_arg: int
    sz_res: int
    sz_iw: int
    sz_w: int


def generate_c(nlp: ReferenceNlp, prefix: str, out_dir: Path) -> GeneratedNlp:
    """Write <prefix>.c/.h with the NLP functions, named <prefix>_f, <prefix>_grad_f, ..."""
    out_dir.mkdir(parents=True, exist_ok=True)
    cg = ca.CodeGenerator(
        f"{prefix}.c",
        {"with_header": True, "casadi_int": "int", "casadi_real": "double", "prefix": f"{prefix}_casadi",
         "main": False, "mex": False, "cpp": False},
    )
    sz = {"arg": 1, "res": 1, "iw": 1, "w": 1}
    for fn in nlp.generated_functions():
        if fn.is_a("SXFunction"):
            sx_in = fn.sx_in()
            renamed = ca.Function(f"{prefix}_{fn.name()}", sx_in, fn.call(sx_in), fn.name_in(), fn.name_out())
        else:
            mx_in = fn.mx_in()
            renamed = ca.Function(f"{prefix}_{fn.name()}", mx_in, fn.call(mx_in), fn.name_in(), fn.name_out())
        cg.add(renamed)
        sz["arg"] = max(sz["arg"], renamed.sz_arg())
        sz["res"] = max(sz["res"], renamed.sz_res())
        sz["iw"] = max(sz["iw"], renamed.sz_iw())
        sz["w"] = max(sz["w"], renamed.sz_w())
    cg.generate(str(out_dir) + "/")
    c_file = out_dir / f"{prefix}.c"
    c_file.write_text(
        f"/* {prefix}.c: the reference NLP of the humanmpc spec \"{nlp.spec.name}\" (sha256 {nlp.spec.digest()}),\n"
        f" * written by CasADi {ca.CasadiMeta.version()}. Do not edit. */\n"
        + make_helpers_static(make_parameters_used(c_file.read_text()))
    )
    jr, jc = nlp.jac_pattern
    hr, hc = nlp.hess_pattern
    assert all(r >= c for r, c in zip(hr, hc, strict=True)), "Hessian pattern must be the lower triangle"
    return GeneratedNlp(
        c_file=c_file, h_file=out_dir / f"{prefix}.h", prefix=prefix, nw=nlp.nw, ng=nlp.ng, n_param=nlp.n_param,
        jac_rows=jr, jac_cols=jc, hess_rows=hr, hess_cols=hc,
        sz_arg=sz["arg"], sz_res=sz["res"], sz_iw=sz["iw"], sz_w=sz["w"],
    )
