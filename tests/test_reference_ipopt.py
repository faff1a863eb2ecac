"""The Ipopt reference: the NLP is our problem, its derivatives are right, and the C program against
Debian's Ipopt reaches the same optimum as CasADi's own Ipopt, reporting failures by status."""

from __future__ import annotations

import subprocess
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from humanmpc.codegen.reference_nlp import ReferenceNlp, problem_params
from humanmpc.codegen.spec import Spec, resolve_spec
from humanmpc.compare.peers.ipopt import (
    IpoptReference,
    IpoptRunError,
    build_ipopt_reference,
    ipopt_unavailable_reason,
    status_name,
)
from humanmpc.compare.replay import Replay, ReplayError, synthetic_replay

from . import nlp_reference as indep
from .conftest import require_tool


def random_scene(rng: np.random.Generator, N: int, k: int, obstacle: bool = True) -> dict:
    """Humans around the straight way to the goal, none within 1.2 m of the robot's start."""
    now = np.empty((k, 2))
    for i in range(k):
        while True:
            c = rng.uniform([-1.0, -3.0], [7.0, 3.0])
            if np.linalg.norm(c) > 1.2:
                now[i] = c
                break
    vel = rng.uniform(-0.8, 0.8, (k, 2))
    pred = now[None] + vel[None] * (0.1 * np.arange(N + 1))[:, None, None]
    return {
        "x0": np.array([0.0, 0.0, rng.uniform(-0.5, 0.5), rng.uniform(0.0, 0.8)]),
        "goal": np.array([6.0, rng.uniform(-1, 1), 0.0, 0.8]),
        "humans_now": now,
        "humans_pred": pred,
        "obstacle": np.array([rng.uniform(2, 4), rng.uniform(-0.6, 0.6)]) if obstacle else None,
    }


def indep_params(spec: Spec) -> indep.Params:
    p = problem_params(spec)
    return indep.Params(N=spec.horizon.N, dt=spec.dt, w_goal=p["w_goal"], w_goal_terminal=p["w_goal_terminal"],
                        w_control=p["w_control"], q=p["q"], d_th=p["d_th"], kappa=p["kappa"], d_h=p["d_h"],
                        d_s=p["d_s"], slack_l1=p["slack_l1"], slack_l2=p["slack_l2"], v=p["v_bounds"],
                        a=p["a_bounds"], omega=p["omega_bounds"])


# ---- the NLP itself (no Ipopt needed) ----------------------------------------------------------


def test_hand_assembled_derivatives_equal_casadi_ad() -> None:
    """Gradient, Jacobian and exact Hessian of the Lagrangian (assembled node by node, at their
    patterns) against CasADi's AD of the whole NLP, at random points and multipliers."""
    spec = resolve_spec({"preset": "paper", "humans": {"max": 4}, "horizon": {"N": 6, "T": 0.6}})
    nlp = ReferenceNlp(spec)
    rng = np.random.default_rng(3)
    W = ca.MX.sym("w", nlp.nw)
    for k, with_obstacle in ((3, True), (0, False), (4, True)):
        scene = random_scene(rng, nlp.N, k, with_obstacle)
        scene["x0"] = rng.normal(size=4)
        p = nlp.params.pack(**scene, params=problem_params(spec))
        w, sigma, lam = rng.normal(size=nlp.nw), rng.uniform(0.1, 2), rng.normal(size=nlp.ng)
        J_ref = np.array(ca.Function("j", [W], [ca.jacobian(nlp.g(W, p), W)])(w))
        J = np.zeros_like(J_ref)
        np.add.at(J, nlp.jac_pattern, np.array(nlp.jac_g(w, p)).ravel())
        np.testing.assert_allclose(J, J_ref, atol=1e-12)
        lagrangian = sigma * nlp.f(W, p) + ca.dot(ca.DM(lam), nlp.g(W, p))
        H_ref = np.tril(np.array(ca.Function("h", [W], [ca.hessian(lagrangian, W)[0]])(w)))
        H = np.zeros_like(H_ref)
        np.add.at(H, nlp.hess_pattern, np.array(nlp.hess_l(w, p, sigma, lam)).ravel())
        np.testing.assert_allclose(H, H_ref, atol=1e-10 * max(1.0, np.abs(H_ref).max()))
        g_ref = np.array(ca.Function("g", [W], [ca.gradient(nlp.f(W, p), W)])(w)).ravel()
        np.testing.assert_allclose(np.array(nlp.grad_f(w, p)).ravel(), g_ref, atol=1e-12)
    rows, cols = nlp.hess_pattern
    assert all(r >= c for r, c in zip(rows, cols, strict=True)), "Ipopt wants the lower triangle"
    assert len(set(zip(rows, cols, strict=True))) == len(rows), "no duplicate Hessian entries"
    assert len(set(zip(*nlp.jac_pattern, strict=True))) == len(nlp.jac_pattern[0]), "no duplicate Jacobian entries"


def test_objective_equals_the_independent_formulation() -> None:
    """plan_cost (our NLP's objective, slack at its minimum) equals tests/nlp_reference.objective,
    written independently of codegen/, on random trajectories."""
    spec = resolve_spec({"preset": "paper", "humans": {"max": 3}, "horizon": {"N": 8, "T": 0.8},
                         "obstacle": {"d_s": 1.5}})
    nlp = ReferenceNlp(spec)
    pr = indep_params(spec)
    rng = np.random.default_rng(5)
    for k in (0, 2, 3):
        scene = random_scene(rng, nlp.N, k)
        scene["obstacle"] = np.array([0.5, 0.3])  # close: the slack is active at some nodes
        p = nlp.params.pack(**scene, params=problem_params(spec))
        X = rng.normal(scale=0.7, size=(nlp.N + 1, 4))
        U = rng.normal(size=(nlp.N, 2))
        ours = float(nlp.plan_cost(X, U, p))
        theirs = indep.objective(indep.Scene(**scene), pr, X, U)
        assert ours == pytest.approx(theirs, rel=1e-12)


def test_objective_with_a_goal_per_node_equals_the_independent_formulation() -> None:
    spec = resolve_spec({"preset": "paper", "humans": {"max": 3}, "horizon": {"N": 8, "T": 0.8}})
    nlp = ReferenceNlp(spec)
    pr = indep_params(spec)
    rng = np.random.default_rng(6)
    scene = random_scene(rng, nlp.N, 2)
    scene["goal"] = rng.normal(size=(nlp.N + 1, 4))
    p = nlp.params.pack(**scene, params=problem_params(spec))
    X = rng.normal(scale=0.7, size=(nlp.N + 1, 4))
    U = rng.normal(size=(nlp.N, 2))
    assert float(nlp.plan_cost(X, U, p)) == pytest.approx(indep.objective(indep.Scene(**scene), pr, X, U), rel=1e-12)


def test_bounds_switch_rows_off_for_absent_humans_and_obstacle() -> None:
    spec = resolve_spec({"preset": "paper", "humans": {"max": 3}, "horizon": {"N": 4, "T": 0.4}})
    nlp = ReferenceNlp(spec)
    scene = random_scene(np.random.default_rng(0), 4, 1, obstacle=False)
    lbw, ubw, lbg, ubg = (np.array(v).ravel() for v in nlp.bounds(nlp.params.pack(**scene,
                                                                                  params=problem_params(spec))))
    ro = nlp.row_offsets
    human_lb = lbg[ro["humans"] : ro["obstacle"]].reshape(4, 3)
    assert np.all(human_lb[:, 0] == spec.humans.d_h) and np.all(human_lb[:, 1:] <= -1e19)
    assert np.all(lbg[ro["obstacle"] :] <= -1e19)
    X_lb = lbw[: 4 * 5].reshape(5, 4)
    assert X_lb[0, 3] <= -1e19 and np.all(X_lb[1:, 3] == spec.bounds.v[0])
    assert np.all(lbw[nlp.decision.s_offset :] == 0.0)
    assert np.all(lbg[: ro["humans"]] == 0) and np.all(ubg[: ro["humans"]] == 0)
    assert np.all(ubw[nlp.decision.u_offset : nlp.decision.s_offset : 2] == spec.bounds.a[1])


# ---- the C program against Debian's Ipopt -------------------------------------------------------


@pytest.fixture(scope="module")
def ipopt_ok() -> None:
    reason = ipopt_unavailable_reason()
    if reason is not None:
        pytest.fail(f"{reason} (`make test` installs it: see APT_PACKAGES in the Makefile)")


@pytest.fixture(scope="module")
def ref30(tmp_path_factory: pytest.TempPathFactory, ipopt_ok: None) -> IpoptReference:
    """The paper's spec with N_h = 30 (N = 50)."""
    spec = resolve_spec({"preset": "paper", "humans": {"max": 30}})
    return build_ipopt_reference(spec, tmp_path_factory.mktemp("ipopt30"))


def test_c_ipopt_reaches_the_nlpsol_optimum(ref30: IpoptReference) -> None:
    """Random scenes with 0, 5 and 30 humans: the C program (Debian Ipopt 3.11, our derivatives)
    and CasADi's nlpsol('ipopt') (Ipopt 3.14, CasADi's derivatives) from the same start agree to
    1e-6 relative, and the C solution is feasible."""
    rng = np.random.default_rng(11)
    scenes = [random_scene(rng, 50, k, obstacle=bool(j % 2)) for k in (0, 5, 30) for j in range(2)]
    replay = Replay.from_steps(scenes, ref30.spec)
    run = ref30.run(replay, tol=1e-10)
    assert run.status_names() == ["Solve_Succeeded"] * len(scenes)
    nlp = ref30.nlp
    solver = nlp.nlp_solver(tol=1e-10)
    for t in range(replay.steps):
        p = nlp.params.pack(**replay.inputs(t), params=replay.params)
        lbw, ubw, lbg, ubg = nlp.bounds(p)
        sol = solver(x0=nlp.cold_guess(p), p=p, lbx=lbw, ubx=ubw, lbg=lbg, ubg=ubg)
        assert solver.stats()["success"], f"scene {t}: nlpsol failed"
        assert run.cost[t] == pytest.approx(float(sol["f"]), rel=1e-6), f"scene {t} ({replay.n_humans[t]} humans)"
        # Ipopt's objective is taken inside its relaxed bounds (bound_relax_factor 1e-8: slacks a hair
        # below 0, times slack_l1 = 100, times N = 50); the solution it returns is projected back.
        assert abs(run.cost[t] - float(nlp.f(run.w[t], p))) <= 2 * 1e-8 * 100.0 * 50
        assert np.all(run.s[t] >= 0.0)
        g = np.array(nlp.g(run.w[t], p)).ravel()
        assert np.all(g >= np.array(lbg).ravel() - 1e-7) and np.all(g <= np.array(ubg).ravel() + 1e-7)
        assert run.iterations[t] > 0 and run.solve_ms[t] > 0 and run.total_ms[t] >= run.solve_ms[t]
    np.testing.assert_allclose(run.x[:, 0], replay.x0, atol=1e-9)


def test_c_ipopt_optimum_satisfies_the_independent_reference(ref30: IpoptReference) -> None:
    """tests/nlp_reference (written without codegen/) values the C program's optimum at the same cost."""
    scene = random_scene(np.random.default_rng(2), 50, 5)
    run = ref30.run(Replay.from_steps([scene], ref30.spec), tol=1e-10)
    pr = indep_params(ref30.spec)
    assert indep.objective(indep.Scene(**scene), pr, run.x[0], run.u[0]) == pytest.approx(run.cost[0], rel=1e-7)


def test_warm_start_reaches_the_cold_optimum_with_fewer_iterations(tmp_path: Path, ipopt_ok: None) -> None:
    spec = resolve_spec({"preset": "paper", "humans": {"max": 2}, "horizon": {"N": 20, "T": 2.0}})
    replay = synthetic_replay(spec, 2, 8, seed=4)
    ref = build_ipopt_reference(spec, tmp_path / "ip")
    cold, warm = ref.run(replay, tol=1e-10), ref.run(replay, warm=True, tol=1e-10)
    assert cold.failures == 0 and warm.failures == 0
    np.testing.assert_allclose(warm.cost, cold.cost, rtol=1e-6)
    assert warm.iterations[1:].sum() < cold.iterations[1:].sum()
    assert warm.iterations[0] == cold.iterations[0]  # nothing to warm-start from at step 0
    # An up-to-date program is reused, not rebuilt.
    mtime = ref.program.stat().st_mtime_ns
    assert build_ipopt_reference(spec, tmp_path / "ip").program.stat().st_mtime_ns == mtime


def test_failures_are_reported_with_ipopt_status(ref30: IpoptReference) -> None:
    """A human standing on the robot (infeasible) and an iteration limit give Ipopt's own statuses,
    and the steps after them are still solved."""
    rng = np.random.default_rng(8)
    ok = random_scene(rng, 50, 5)
    blocked = random_scene(rng, 50, 5)
    blocked["humans_now"][0] = blocked["x0"][:2]
    blocked["humans_pred"][:, 0] = blocked["x0"][:2]
    replay = Replay.from_steps([ok, blocked, ok], ref30.spec)
    run = ref30.run(replay, max_iter=200)
    assert run.success.tolist() == [True, False, True]
    assert status_name(run.status[1]) in ("Infeasible_Problem_Detected", "Restoration_Failed",
                                          "Maximum_Iterations_Exceeded", "Search_Direction_Becomes_Too_Small")
    limited = ref30.run(Replay.from_steps([ok], ref30.spec), max_iter=2)
    assert limited.status_names() == ["Maximum_Iterations_Exceeded"] and limited.iterations[0] == 2
    assert run.failures == 1


def test_a_replay_of_another_spec_is_refused(ref30: IpoptReference, tmp_path: Path) -> None:
    other = resolve_spec({"preset": "paper", "humans": {"max": 30}, "weights": {"goal": [1.0, 1.0, 0.0, 250.0]}})
    replay = Replay.from_steps([random_scene(np.random.default_rng(0), 50, 3)], other)
    with pytest.raises(ReplayError, match="recorded for spec"):
        ref30.run(replay)
    # The program itself checks the spec hash and the sizes of what it reads.
    good = Replay.from_steps([random_scene(np.random.default_rng(0), 50, 3)], ref30.spec)
    data = bytearray(ref30.pack(good, tmp_path / "in.bin").read_bytes())
    data[8:12] = b"0000"
    (tmp_path / "bad.bin").write_bytes(bytes(data))
    proc = subprocess.run([str(ref30.program), str(tmp_path / "bad.bin"), str(tmp_path / "out.bin")],
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 3 and "regenerate the program for that spec" in proc.stderr
    (tmp_path / "short.bin").write_bytes(bytes(ref30.pack(good, tmp_path / "in.bin").read_bytes()[:-8]))
    proc = subprocess.run([str(ref30.program), str(tmp_path / "short.bin"), str(tmp_path / "out.bin")],
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 3 and "truncated replay" in proc.stderr
    proc = subprocess.run([str(ref30.program), str(tmp_path / "missing.bin"), str(tmp_path / "out.bin")],
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 2 and "cannot open the replay" in proc.stderr
    ref30_missing = IpoptReference(ref30.spec, ref30.build_dir, ref30.nlp, tmp_path / "no_such_program")
    with pytest.raises((IpoptRunError, FileNotFoundError)):
        ref30_missing.run(good)


def test_generated_c_is_warning_free(ref30: IpoptReference, tmp_path: Path) -> None:
    cc = require_tool("gcc")
    d = ref30.build_dir
    for src in (f"{ref30.spec.name}_ipopt.c", f"{ref30.spec.name}_nlp.c"):
        proc = subprocess.run([cc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O0",
                               "-I/usr/include/coin", "-DHAVE_CSTDDEF", "-I", str(d), "-c", str(d / src),
                               "-o", str(tmp_path / "x.o")], capture_output=True, text=True, check=False)
        assert proc.returncode == 0, proc.stderr[-3000:]


def test_zero_humans_spec_builds_and_solves(tmp_path: Path, ipopt_ok: None) -> None:
    spec = resolve_spec({"preset": "paper", "name": "nobody", "humans": {"max": 0}, "horizon": {"N": 20, "T": 2.0}})
    ref = build_ipopt_reference(spec, tmp_path / "ip0")
    replay = Replay.from_steps([{"x0": [0, 0, 0, 0], "goal": [3, 1, 0, 0.8], "humans_now": None,
                                 "humans_pred": None, "obstacle": [1.5, 0.3]}], spec)
    run = ref.run(replay, tol=1e-10)
    nlp = ref.nlp
    p = nlp.params.pack(**replay.inputs(0), params=replay.params)
    solver = nlp.nlp_solver(tol=1e-10)
    lbw, ubw, lbg, ubg = nlp.bounds(p)
    sol = solver(x0=nlp.cold_guess(p), p=p, lbx=lbw, ubx=ubw, lbg=lbg, ubg=ubg)
    assert run.status_names() == ["Solve_Succeeded"]
    assert run.cost[0] == pytest.approx(float(sol["f"]), rel=1e-6)
