#!/usr/bin/env python3
"""acados as a peer of humanmpc's solver: the same OCP with acados_template, run over a replay.

A standalone script for the interpreter of the acados virtualenv (Python 3.12 with PyPI's
``comma-deps-acados``, which ships prebuilt acados, acados_template, the tera renderer and a
casadi of its own). It must not import humanmpc (it runs under another interpreter, with another
casadi); humanmpc.compare creates the virtualenv and runs this script.

The formulation mirrors codegen/ocp.py and codegen/reference_nlp.py (the replay's metadata carries
N, dt, the spec and the problem parameters; the distance smoothing comes on the command line):

- model x = [px, py, theta, v], u = [a, omega]; ERK with 4 stages, 1 step per interval (= RK4);
- cost CONVEX_OVER_NONLINEAR with the Gauss-Newton Hessian: inner r = [x - g, u, d(p, h_1..h_NH)]
  (predicted humans), outer psi(r) = r_x' Wg r_x + r_u' Wu r_u + sum_i f(d_i), f the paper's
  potential, so acados' generalised Gauss-Newton Hessian uses f''; terminal r = [x - g, d_i],
  weights WgN; node 0 has the path cost;
- hard human rows d(p, h_i,now) >= d_h as ``con_h_expr`` (disabled at node 0, where x is the
  measurement; the reference has none there either); the obstacle row d(p, o) >= d_s soft
  (idxsh, zl = L1, Zl = L2: l1 s + 0.5 l2 s^2); bounds on v (nodes 1..N), a, omega;
- parameters per stage: p = [g (4), h_pred,n (2 NH), h_now (2 NH), o (2)]. Absent humans and an
  absent obstacle are parked 200 m away in x and y (potential below 1e-200, rows inactive).

Per step: the measured x0 and the parameters are set, the previous solution is shifted by one
interval (plain shift, last node repeated; acados has no shift of its own), one SQP-RTI step runs,
and acados' ``time_tot``, the wall time of ``solve()``, the status, the QP iterations and the plan
are recorded. A failed step (status != 0; 4 is a QP failure, 3 a minimum step) is counted; a
non-finite iterate is re-initialised to x0 (cold) before the next step.

Modes: ``default`` (HPIPM defaults: BALANCE, full-horizon partial condensing, 50 QP iterations)
and ``fastest`` (SPEED_ABS, partial condensing to --cond-N stages, --qp-iter-max QP iterations).

usage: python acados_peer.py REPLAY.npz RESULTS.npz --build DIR --mode default|fastest
                             [--dist-eps 1e-3] [--cond-N K] [--qp-iter-max K] [--regularization R]
       python acados_peer.py --selfcheck OUT.npz   (evaluates the potential and the RK4 step)
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

ACADOS_PKG_HINT = "pip install comma-deps-acados==0.2.2.post104 (Python 3.12)"
PARKED = 200.0  # absent humans and an absent obstacle are put this far from the robot, in x and y [m]
BIG = 1.0e3  # "no upper bound" of the distance rows [m]: larger values slow HPIPM down (no bound masks)


def _acados_dirs() -> tuple[Path, Path, Path]:
    """(install dir, lib dir, tera renderer) of the wheel's prebuilt acados, without importing casadi."""
    import importlib.util

    spec = importlib.util.find_spec("acados")
    if spec is None or not spec.submodule_search_locations:
        sys.exit(f"acados_peer: the 'acados' package is not installed in {sys.executable}: {ACADOS_PKG_HINT}")
    root = Path(next(iter(spec.submodule_search_locations)))
    install = root / "install"
    return install, install / "lib", install / "bin" / "t_renderer"


def _setup_environment() -> None:
    """ACADOS_SOURCE_DIR, ACADOS_PYTHON_INTERFACE_PATH, TERA_PATH and LD_LIBRARY_PATH for the wheel's acados.

    The dynamic loader reads LD_LIBRARY_PATH only at start-up, and libacados.so (loaded by
    acados_template with ctypes) finds its own libraries (hpipm, blasfeo, qpOASES_e) through it:
    when it is missing, the script runs itself again with it set.
    """
    install, lib, tera = _acados_dirs()
    for path in (lib / "libacados.so", tera):
        if not path.exists():
            sys.exit(f"acados_peer: {path} is missing: the acados wheel is incomplete ({ACADOS_PKG_HINT})")
    os.environ["ACADOS_SOURCE_DIR"] = str(install)
    os.environ["ACADOS_PYTHON_INTERFACE_PATH"] = str(install.parent / "acados_template")
    os.environ["TERA_PATH"] = str(tera)
    paths = [p for p in os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep) if p]
    if str(lib) not in paths:
        os.environ["LD_LIBRARY_PATH"] = os.pathsep.join([str(lib), *paths])
        os.execv(sys.executable, [sys.executable, *sys.argv])


def potential(d: Any, q: float, d_th: float, kappa: float) -> Any:
    """The paper's f(d), written exactly as codegen/ocp.collision_potential."""
    import casadi as ca

    linear = -(kappa * q / 4.0) * d + (q / 2.0 + kappa * q * d_th / 4.0)
    e = ca.exp(-kappa * (ca.fmax(d, d_th) - d_th))
    return ca.if_else(d <= d_th, linear, q * e / (1.0 + e))


def dist(p: Any, c: Any, eps: float) -> Any:
    import casadi as ca

    return ca.sqrt(ca.sumsqr(p - c) + eps**2)


def ode(x: Any, u: Any) -> Any:
    import casadi as ca

    return ca.vertcat(x[3] * ca.cos(x[2]), x[3] * ca.sin(x[2]), u[1], u[0])


def build_ocp(meta: dict, mode: str, eps: float, cond_n: int, qp_iter_max: int, regularization: float,
              build: Path) -> tuple[Any, str]:
    import casadi as ca
    import numpy as np
    from acados.acados_template import AcadosModel, AcadosOcp

    N, dt, NH = int(meta["N"]), float(meta["dt"]), int(meta["NH"])
    prm = meta["params"]
    wg, wgN, wu = (np.asarray(prm[k], dtype=float) for k in ("w_goal", "w_goal_terminal", "w_control"))
    q, d_th, kappa = float(prm["q"]), float(prm["d_th"]), float(prm["kappa"])
    d_h, d_s, l1, l2 = float(prm["d_h"]), float(prm["d_s"]), float(prm["slack_l1"]), float(prm["slack_l2"])
    vb, ab, ob = prm["v_bounds"], prm["a_bounds"], prm["omega_bounds"]

    name = f"hm_{meta['spec']['name']}_{NH}_{mode}"
    x = ca.SX.sym("x", 4)
    u = ca.SX.sym("u", 2)
    xdot = ca.SX.sym("xdot", 4)
    p = ca.SX.sym("p", 4 + 4 * NH + 2)
    g = p[0:4]
    pred = [p[4 + 2 * i : 6 + 2 * i] for i in range(NH)]
    now = [p[4 + 2 * NH + 2 * i : 6 + 2 * NH + 2 * i] for i in range(NH)]
    o = p[4 + 4 * NH : 6 + 4 * NH]
    pos = x[:2]

    model = AcadosModel()
    model.name = name
    model.x, model.u, model.xdot, model.p = x, u, xdot, p
    model.f_expl_expr = ode(x, u)
    model.f_impl_expr = xdot - ode(x, u)

    d_pred = [dist(pos, h, eps) for h in pred]
    r_x, r_u, r_d = ca.SX.sym("r_x", 4), ca.SX.sym("r_u", 2), ca.SX.sym("r_d", NH)
    col = sum((potential(r_d[i], q, d_th, kappa) for i in range(NH)), ca.SX(0))
    model.cost_y_expr = ca.vertcat(x - g, u, *d_pred)
    model.cost_r_in_psi_expr = ca.vertcat(r_x, r_u, r_d)
    model.cost_psi_expr = ca.dot(wg * r_x, r_x) + ca.dot(wu * r_u, r_u) + col
    model.cost_y_expr_e = ca.vertcat(x - g, *d_pred)
    model.cost_r_in_psi_expr_e = ca.vertcat(r_x, r_d)
    model.cost_psi_expr_e = ca.dot(wgN * r_x, r_x) + col
    rows = ca.vertcat(*[dist(pos, h, eps) for h in now], dist(pos, o, eps))
    model.con_h_expr = rows
    model.con_h_expr_e = rows

    ocp = AcadosOcp()
    ocp.model = model
    ocp.dims.N = N
    ocp.cost.cost_type = "CONVEX_OVER_NONLINEAR"
    ocp.cost.cost_type_e = "CONVEX_OVER_NONLINEAR"
    ocp.cost.yref = np.zeros(4 + 2 + NH)
    ocp.cost.yref_e = np.zeros(4 + NH)
    lh = np.array([d_h] * NH + [d_s])
    uh = np.full(NH + 1, BIG)
    c = ocp.constraints
    c.lh, c.uh, c.lh_e, c.uh_e = lh, uh, lh.copy(), uh.copy()
    c.idxsh = np.array([NH])
    c.idxsh_e = np.array([NH])
    ocp.cost.zl = np.array([l1])
    ocp.cost.zu = np.array([l1])
    ocp.cost.Zl = np.array([l2])
    ocp.cost.Zu = np.array([l2])
    ocp.cost.zl_e, ocp.cost.zu_e, ocp.cost.Zl_e, ocp.cost.Zu_e = (np.array([l1]), np.array([l1]),
                                                                  np.array([l2]), np.array([l2]))
    c.idxbx = np.array([3])
    c.lbx, c.ubx = np.array([vb[0]]), np.array([vb[1]])
    c.idxbx_e = np.array([3])
    c.lbx_e, c.ubx_e = np.array([vb[0]]), np.array([vb[1]])
    c.idxbu = np.array([0, 1])
    c.lbu, c.ubu = np.array([ab[0], ob[0]]), np.array([ab[1], ob[1]])
    c.x0 = np.zeros(4)
    ocp.parameter_values = np.zeros(4 + 4 * NH + 2)

    s = ocp.solver_options
    s.tf = N * dt
    s.integrator_type = "ERK"
    s.sim_method_num_stages = 4
    s.sim_method_num_steps = 1
    s.nlp_solver_type = "SQP_RTI"
    s.hessian_approx = "GAUSS_NEWTON"
    s.qp_solver = "PARTIAL_CONDENSING_HPIPM"
    s.levenberg_marquardt = float(regularization)
    s.print_level = 0
    if mode == "fastest":
        s.hpipm_mode = "SPEED_ABS"
        s.qp_solver_cond_N = int(cond_n)
        s.qp_solver_iter_max = int(qp_iter_max)
    elif mode != "default":
        sys.exit(f"acados_peer: unknown mode {mode!r}: use default or fastest")
    ocp.code_export_directory = str(build / f"c_generated_code_{name}")
    return ocp, name


def park(x0: Any, inputs_now: Any, inputs_pred: Any, k: int, NH: int, N: int) -> tuple[Any, Any]:
    import numpy as np

    far = x0[:2] + PARKED
    now = np.tile(far, (NH, 1))
    pred = np.tile(far, (N + 1, NH, 1))
    now[:k] = inputs_now[:k]
    pred[:, :k] = inputs_pred[:, :k]
    return now, pred


def run(args: argparse.Namespace) -> None:
    import numpy as np
    from acados.acados_template import AcadosOcpSolver

    data = np.load(args.replay, allow_pickle=False)
    meta = json.loads(str(data["meta"]))
    if meta.get("format") != "humanmpc-replay":
        sys.exit(f"acados_peer: {args.replay} is not a humanmpc replay")
    N, NH = int(meta["N"]), int(meta["NH"])
    x0s, goals, n_h = data["x0"], data["goal"], data["n_humans"]
    h_now, h_pred, has_o, obst = data["humans_now"], data["humans_pred"], data["has_obstacle"], data["obstacle"]
    T = int(x0s.shape[0])
    build = Path(args.build).resolve()
    build.mkdir(parents=True, exist_ok=True)
    ocp, name = build_ocp(meta, args.mode, args.dist_eps, args.cond_n, args.qp_iter_max, args.regularization, build)

    t0 = time.perf_counter()
    cwd = os.getcwd()
    os.chdir(build)  # acados_template writes its json and builds relative to the working directory
    try:
        solver = AcadosOcpSolver(ocp, json_file=str(build / f"{name}.json"), verbose=False)
    finally:
        os.chdir(cwd)
    build_s = time.perf_counter() - t0

    lh0 = np.array([-BIG] * NH + [-BIG])  # no distance rows at node 0 (x_0 is the measurement)
    solver.constraints_set(0, "lh", lh0)

    status = np.zeros(T, dtype=np.int64)
    qp_iter = np.zeros(T, dtype=np.int64)
    time_tot = np.zeros(T)
    wall = np.zeros(T)
    X = np.zeros((T, N + 1, 4))
    U = np.zeros((T, N, 2))
    x_prev: Any = None
    u_prev: Any = None
    for t in range(T):
        x0 = x0s[t]
        now, pred = park(x0, h_now[t], h_pred[t], int(n_h[t]), NH, N)
        o = obst[t] if has_o[t] else x0[:2] + PARKED
        for n in range(N + 1):
            solver.set(n, "p", np.concatenate([goals[t], pred[n].ravel(), now.ravel(), o]))
        # Initial guess: shifted previous plan, or x0 everywhere (cold).
        for n in range(N + 1):
            if x_prev is None:
                solver.set(n, "x", x0)
            else:
                solver.set(n, "x", x_prev[min(n + 1, N)])
            if n < N:
                solver.set(n, "u", np.zeros(2) if u_prev is None else u_prev[min(n + 1, N - 1)])
        solver.constraints_set(0, "lbx", x0)
        solver.constraints_set(0, "ubx", x0)
        t1 = time.perf_counter()
        st = solver.solve()
        wall[t] = (time.perf_counter() - t1) * 1e3
        status[t] = int(st)
        time_tot[t] = float(solver.get_stats("time_tot")[0]) * 1e3
        qp = np.asarray(solver.get_stats("qp_iter")).ravel()
        qp_iter[t] = int(qp.sum()) if qp.size else 0
        X[t] = np.array([solver.get(n, "x") for n in range(N + 1)])
        U[t] = np.array([solver.get(n, "u") for n in range(N)])
        if np.all(np.isfinite(X[t])) and np.all(np.isfinite(U[t])):
            x_prev, u_prev = X[t].copy(), U[t].copy()
        else:
            solver.reset()
            solver.constraints_set(0, "lh", lh0)
            x_prev, u_prev = None, None
    info = {
        "mode": args.mode, "name": name, "steps": T, "build_s": build_s,
        "hpipm_mode": ocp.solver_options.hpipm_mode, "qp_solver_cond_N": ocp.solver_options.qp_solver_cond_N,
        "qp_solver_iter_max": ocp.solver_options.qp_solver_iter_max,
        "levenberg_marquardt": ocp.solver_options.levenberg_marquardt, "python": sys.version.split()[0],
    }
    np.savez(args.out, status=status, qp_iter=qp_iter, time_tot_ms=time_tot, wall_ms=wall, x=X, u=U,
             info=np.array(json.dumps(info)))


def selfcheck(out: str, eps: float) -> None:
    """Evaluate the potential, the distance and one ERK4 step of acados' integrator for a test."""
    import casadi as ca
    import numpy as np
    from acados.acados_template import AcadosModel, AcadosSim, AcadosSimSolver

    d = np.linspace(0.0, 3.0, 61)
    f = np.array([float(potential(ca.DM(v), 2.0, 1.0, 5.0)) for v in d])
    dd = float(dist(ca.DM([0.3, -0.2]), ca.DM([1.0, 0.5]), eps))
    x, u, xdot = ca.SX.sym("x", 4), ca.SX.sym("u", 2), ca.SX.sym("xdot", 4)
    model = AcadosModel()
    model.name = "hm_selfcheck"
    model.x, model.u, model.xdot = x, u, xdot
    model.f_expl_expr = ode(x, u)
    model.f_impl_expr = xdot - ode(x, u)
    sim = AcadosSim()
    sim.model = model
    sim.solver_options.T = 0.1
    sim.solver_options.integrator_type = "ERK"
    sim.solver_options.num_stages = 4
    sim.solver_options.num_steps = 1
    build = Path(out).resolve().parent / "acados_selfcheck"
    build.mkdir(parents=True, exist_ok=True)
    sim.code_export_directory = str(build / "c_generated_code_sim")
    cwd = os.getcwd()
    os.chdir(build)
    try:
        integ = AcadosSimSolver(sim, json_file=str(build / "sim.json"), verbose=False)
    finally:
        os.chdir(cwd)
    xs = np.array([0.1, -0.2, 0.3, 0.5])
    us = np.array([0.4, -0.7])
    integ.set("x", xs)
    integ.set("u", us)
    integ.solve()
    np.savez(out, d=d, f=f, dist=dd, x=xs, u=us, x_next=integ.get("x"))


def main() -> None:
    parser = argparse.ArgumentParser(description="acados SQP-RTI + HPIPM on a humanmpc replay")
    parser.add_argument("replay", nargs="?")
    parser.add_argument("out", nargs="?")
    parser.add_argument("--build", help="build folder for acados' generated code")
    parser.add_argument("--mode", default="default", choices=["default", "fastest"])
    parser.add_argument("--dist-eps", type=float, default=1e-3)
    parser.add_argument("--cond-N", dest="cond_n", type=int, default=5)
    parser.add_argument("--qp-iter-max", type=int, default=50)
    parser.add_argument("--regularization", type=float, default=1e-6)
    parser.add_argument("--selfcheck", metavar="OUT.npz")
    args = parser.parse_args()
    _setup_environment()
    if args.selfcheck:
        selfcheck(args.selfcheck, args.dist_eps)
        return
    if not (args.replay and args.out and args.build):
        parser.error("REPLAY, RESULTS and --build are required")
    run(args)


if __name__ == "__main__":
    main()
