"""The SQP against Ipopt on the independently written NLP, and the real-time iteration in closed loop."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import humanmpc

from .conftest import make_solver
from .nlp_reference import EPS, Params, Scene, objective, solve_ipopt

N = 50
DT = 0.1
D_H = 0.5


@pytest.fixture(scope="module")
def crowd30(tmp_path_factory: pytest.TempPathFactory) -> humanmpc.Solver:
    """The paper's spec with N_h = 30 (the largest crowd of the paper's scalability experiment)."""
    d = make_solver(tmp_path_factory.mktemp("crowd30"), {"preset": "paper", "name": "crowd30", "humans": {"max": 30}})
    return humanmpc.load(d)


def random_scene(rng: np.random.Generator, k: int, *, keep_clear_of_path: bool = False) -> Scene:
    x0 = np.array([0.0, 0.0, rng.uniform(-0.5, 0.5), rng.uniform(0.0, 1.0)])
    goal = np.array([rng.uniform(6.0, 9.0), rng.uniform(-1.0, 1.0), 0.0, 0.8])
    now = []
    while len(now) < k:
        p = np.array([rng.uniform(0.5, 9.5), rng.uniform(-4.5, 4.5)])
        if np.linalg.norm(p - x0[:2]) < 1.5:
            continue  # the robot must start well outside d_h, so that the hard problem is feasible
        if keep_clear_of_path and abs(p[1]) < 3.5:
            continue
        now.append(p)
    humans_now = np.array(now).reshape(k, 2)
    vel = rng.uniform(-1.0, 1.0, size=(k, 2))
    if keep_clear_of_path:
        vel[:, 1] = np.sign(humans_now[:, 1]) * np.abs(vel[:, 1])  # walking away from the path
    pred = np.stack([humans_now + vel * DT * n for n in range(N + 1)]) if k else np.zeros((N + 1, 0, 2))
    obstacle = np.array([rng.uniform(2.0, 6.0), rng.uniform(-2.0, 2.0)])
    if keep_clear_of_path:
        obstacle[1] = 4.0 * np.sign(obstacle[1] or 1.0)
    return Scene(x0=x0, goal=goal, humans_now=humans_now, humans_pred=pred, obstacle=obstacle)


def solve_ours(solver: humanmpc.Solver, scene: Scene) -> humanmpc.StepResult:
    solver.reset()
    solver.set_params(deadline_ms=1e5)  # the reference to converge, not a control period's deadline
    return solver.solve(scene.x0, scene.goal, scene.humans_now, scene.humans_pred, scene.obstacle,
                        max_iter=300, tol=1e-9)


def human_clearance(x: np.ndarray, humans_now: np.ndarray) -> float:
    """Smallest (smoothed, as the model defines it) distance of the planned positions at nodes 1..N to
    the humans' current positions."""
    if humans_now.shape[0] == 0:
        return np.inf
    sq = np.sum((x[1:, None, :2] - humans_now[None, :, :]) ** 2, axis=2)
    return float(np.sqrt(sq + EPS**2).min())


SCENES = [(seed, k) for seed, k in enumerate([0, 1, 2, 3, 5, 5, 8, 10, 10, 12, 15, 15, 18, 20, 20, 24, 25, 28, 30, 30,
                                              30, 7])]


@pytest.mark.parametrize(("seed", "k"), SCENES, ids=[f"seed{s}-{k}humans" for s, k in SCENES])
def test_full_sqp_reaches_a_local_optimum_that_ipopt_cannot_improve(crowd30: humanmpc.Solver, seed: int,
                                                                     k: int) -> None:
    scene = random_scene(np.random.default_rng(1000 + seed), k)
    ours = solve_ours(crowd30, scene)
    assert ours.status_name == "solved", f"SQP did not converge: {ours.status_name}, kkt {ours.kkt:.2e}"
    assert ours.kkt <= 1e-8
    # The true (hard) human constraint holds at our optimum: the exact penalty kept it.
    assert human_clearance(ours.x, scene.humans_now) >= D_H - 1e-6
    pr = Params()
    our_cost = objective(scene, pr, ours.x, ours.u)
    assert our_cost == pytest.approx(ours.cost, rel=1e-9)  # the solver's own objective is the NLP's
    ref = solve_ipopt(scene, pr, x_init=ours.x, u_init=ours.u)
    assert ref.success, f"Ipopt failed from our solution: {ref.stats.get('return_status')}"
    assert ref.cost >= our_cost - 1e-6 * abs(our_cost), f"Ipopt found a lower cost: {ref.cost} < {our_cost}"
    assert np.max(np.abs(ref.x - ours.x)) <= 1e-3
    assert np.max(np.abs(ref.u - ours.u)) <= 1e-2


@pytest.mark.parametrize("seed", range(4))
def test_with_no_human_near_the_path_both_reach_the_same_optimum_from_a_cold_start(
    crowd30: humanmpc.Solver, seed: int
) -> None:
    scene = random_scene(np.random.default_rng(2000 + seed), 6, keep_clear_of_path=True)
    ours = solve_ours(crowd30, scene)
    assert ours.status_name == "solved"
    pr = Params()
    ref = solve_ipopt(scene, pr)
    assert ref.success
    our_cost = objective(scene, pr, ours.x, ours.u)
    assert our_cost == pytest.approx(ref.cost, rel=1e-6)
    assert np.max(np.abs(ref.x - ours.x)) <= 1e-3


def references_along(scene: Scene, speed: float, weave: float) -> np.ndarray:
    """(N+1, 4) goals per node, the progress objective's kind: points along a weaving line from the start
    towards the scene's goal at the given speed, heading along it, that speed to track."""
    t = 0.1 * np.arange(51)
    heading = float(np.arctan2(scene.goal[1], scene.goal[0]))
    along = speed * t
    refs = np.zeros((51, 4))
    refs[:, 0] = along * np.cos(heading) - weave * np.sin(t) * np.sin(heading)
    refs[:, 1] = along * np.sin(heading) + weave * np.sin(t) * np.cos(heading)
    refs[:, 2] = heading
    refs[:, 3] = speed
    return refs


@pytest.mark.parametrize(("seed", "k"), [(0, 0), (1, 5), (2, 12), (3, 30)])
def test_full_sqp_with_a_goal_per_node_reaches_an_optimum_ipopt_cannot_improve(crowd30: humanmpc.Solver, seed: int,
                                                                               k: int) -> None:
    """Per-node goals (the progress objective's references along a path): the full SQP against CasADi's Ipopt
    on the independent formulation of tests/nlp_reference.py."""
    rng = np.random.default_rng(3000 + seed)
    scene = random_scene(rng, k)
    scene.goal = references_along(scene, rng.uniform(0.4, 1.0), rng.uniform(0.0, 1.0))
    ours = solve_ours(crowd30, scene)
    assert ours.status_name == "solved", f"SQP did not converge: {ours.status_name}, kkt {ours.kkt:.2e}"
    pr = Params()
    our_cost = objective(scene, pr, ours.x, ours.u)
    assert our_cost == pytest.approx(ours.cost, rel=1e-9)
    ref = solve_ipopt(scene, pr, x_init=ours.x, u_init=ours.u)
    assert ref.success, f"Ipopt failed from our solution: {ref.stats.get('return_status')}"
    assert ref.cost >= our_cost - 1e-6 * abs(our_cost), f"Ipopt found a lower cost: {ref.cost} < {our_cost}"
    assert np.max(np.abs(ref.x - ours.x)) <= 1e-3


def test_the_same_goal_at_every_node_is_bit_for_bit_one_goal(paper: humanmpc.Solver) -> None:
    scene = random_scene(np.random.default_rng(7), 5)
    paper.reset()
    one = [paper.step(scene.x0, scene.goal, scene.humans_now, scene.humans_pred, scene.obstacle) for _ in range(3)]
    paper.reset()
    per_node = np.tile(scene.goal, (51, 1))
    many = [paper.step(scene.x0, per_node, scene.humans_now, scene.humans_pred, scene.obstacle) for _ in range(3)]
    for a, b in zip(one, many, strict=True):
        assert np.array_equal(a.x, b.x) and np.array_equal(a.u, b.u) and a.cost == b.cost


def tapered_goal(goal: np.ndarray, x: np.ndarray) -> np.ndarray:
    """v_ref falls off near the goal (as a planner's goal checker does), so the robot stops there."""
    g = goal.copy()
    g[3] = min(goal[3], 0.5 * float(np.hypot(*(goal[:2] - x[:2]))))
    return g


def test_rti_closed_loop_reaches_the_goal_in_an_open_scene(paper: humanmpc.Solver) -> None:
    paper.reset()
    x = np.array([0.0, 0.0, 0.5, 0.0])
    goal = np.array([8.0, 2.0, 0.0, 0.8])
    statuses = []
    for _ in range(250):
        r = paper.step(x, tapered_goal(goal, x), obstacle=[4.0, 1.5])
        statuses.append(r.qp_status)
        x = humanmpc_unicycle(x, r.u0)
        if np.hypot(*(goal[:2] - x[:2])) < 0.1:
            break
    assert np.hypot(*(goal[:2] - x[:2])) < 0.1
    assert statuses.count(0) == len(statuses)


def omega_in_closed_loop(solver: humanmpc.Solver, goal: np.ndarray, steps: int = 120) -> np.ndarray:
    """The turn rates the RTI commands driving from the origin towards a goal, nobody around."""
    solver.reset()
    x = np.array([0.0, 0.0, 0.0, 0.0])
    omegas = []
    for _ in range(steps):
        r = solver.step(x, tapered_goal(goal, x))
        assert not r.stop
        omegas.append(r.u0[1])
        x = humanmpc_unicycle(x, r.u0)
    return np.array(omegas)


def test_rti_with_the_exact_hessian_steers_smoothly_towards_a_far_offset_goal(paper: humanmpc.Solver) -> None:
    """A goal 17 m ahead and 1 m to the side: the Gauss-Newton RTI (the paper's zero control weights)
    throws omega from one bound to the other at almost every step; the exact Hessian does not."""
    goal = np.array([17.0, 1.0, 0.0, 0.8])
    try:
        paper.set_params(exact_hessian=True)
        exact = omega_in_closed_loop(paper, goal)
        paper.set_params(exact_hessian=False)
        gauss_newton = omega_in_closed_loop(paper, goal)
    finally:
        paper.set_params(exact_hessian=False)
    assert np.mean(np.abs(exact)) < 0.1 and np.count_nonzero(np.abs(exact) > 0.5) <= 2  # one turn to the goal
    assert np.mean(np.abs(gauss_newton)) > 1.0  # the defect the option removes, measured on the same loop


def test_spec_solver_hessian_sets_the_default_of_the_runtime_switch(tmp_path: Path) -> None:
    exact = humanmpc.load(make_solver(tmp_path, {"name": "exact_rti", "solver": {"hessian": "exact"}}))
    assert exact.params["exact_hessian"] == 1
    with pytest.raises(ValueError, match="exact_hessian must be 0 or 1"):
        exact.set_params(exact_hessian=2)


def humanmpc_unicycle(x: np.ndarray, u: np.ndarray, substeps: int = 10) -> np.ndarray:
    """The plant: the unicycle integrated finely (not the solver's own RK4 step)."""
    h = DT / substeps
    for _ in range(substeps):
        x = x + h * np.array([x[3] * np.cos(x[2]), x[3] * np.sin(x[2]), u[1], u[0]])
    return x


@pytest.mark.parametrize("seed", range(3))
def test_rti_plans_keep_d_h_from_humans_whenever_that_is_possible(crowd30: humanmpc.Solver, seed: int) -> None:
    """Every RTI step either plans a path that keeps d_h from the humans' current positions or
    commands a protective stop, and a stop only where a human already is within d_h of the robot or,
    but for at most one step of the run, where no plan can keep d_h (Ipopt, on the hard problem from
    that state, finds none): humans walking into the robot can make the hard constraint infeasible.

    The one step allowed: the exact-penalty NLP has local solutions inside d_h that the hard problem
    does not have, and a robot that has let a person come to the edge of d_h can land in one (even
    the full SQP, cold, converges there) while Ipopt still finds a path along the edge. Over seeds
    0-23 of this loop it happens at one step in 3 (faa5bbb) or 4 (915af81) of the 24 runs,
    never twice in a run."""
    rng = np.random.default_rng(3000 + seed)
    crowd30.reset()
    x = np.array([0.0, 0.0, 0.0, 0.0])
    goal = np.array([10.0, 0.0, 0.0, 0.8])
    k = 20
    humans = np.column_stack([rng.uniform(2, 10, k), rng.uniform(-4, 4, k)])
    humans = humans[np.linalg.norm(humans, axis=1) > 1.5]
    vel = rng.uniform(-0.6, 0.6, size=humans.shape)
    kept = too_close_now = 0
    infeasible: list[int] = []
    missed: list[int] = []  # stopped although Ipopt keeps d_h
    for step in range(150):
        pred = np.stack([humans + vel * DT * n for n in range(N + 1)])
        g = tapered_goal(goal, x)
        r = crowd30.step(x, g, humans, pred, None)
        if float(np.min(np.linalg.norm(humans - x[:2], axis=1))) < D_H:
            too_close_now += 1  # a human walked into the robot: the monitor stops it
            assert r.stop and r.reason == "human_too_close"
        elif not r.stop:
            assert r.qp_status_name == "solved"
            assert human_clearance(r.x, humans) >= D_H - 1e-5
            kept += 1
        else:
            # The monitor refused a plan inside d_h: only right when no plan can keep d_h.
            assert r.reason == "unsafe_plan", r.reason
            infeasible.append(step)
            if len(infeasible) <= 4:  # Ipopt on the hard problem is slow when it is infeasible
                scene = Scene(x0=x.copy(), goal=g, humans_now=humans.copy(), humans_pred=pred, obstacle=None)
                ref = solve_ipopt(scene, Params())
                if ref.success and human_clearance(ref.x, humans) >= D_H - 1e-5:
                    missed.append(step)
        x = humanmpc_unicycle(x, r.u0)
        humans = humans + vel * DT
    assert len(missed) <= 1, f"stopped at steps {missed} although Ipopt keeps d_h there"
    assert kept > 100
    assert len(infeasible) <= 15, f"plans inside d_h at steps {infeasible}"


def test_step_rejects_inputs_of_the_wrong_shape(paper: humanmpc.Solver) -> None:
    x0, goal = np.zeros(4), np.array([5.0, 0.0, 0.0, 0.8])
    with pytest.raises(ValueError, match=r"x0 must have shape \(4,\)"):
        paper.step(np.zeros(3), goal)
    with pytest.raises(ValueError, match=r"humans_now must have shape \(k, 2\)"):
        paper.step(x0, goal, np.zeros((2, 3)), np.zeros((N + 1, 2, 3)))
    with pytest.raises(ValueError, match=r"humans_pred must have shape \(N\+1, k, 2\) = \(51, 2, 2\)"):
        paper.step(x0, goal, np.ones((2, 2)), np.zeros((N, 2, 2)))
    with pytest.raises(ValueError, match=r"at most N_h = 10"):
        paper.step(x0, goal, np.ones((11, 2)), np.zeros((N + 1, 11, 2)))
    with pytest.raises(ValueError, match="obstacle must have shape"):
        paper.step(x0, goal, obstacle=[1.0, 2.0, 3.0])


def test_prepare_then_feedback_equals_step(paper: humanmpc.Solver, tmp_path: Path) -> None:
    scene = random_scene(np.random.default_rng(5), 4)
    twin = humanmpc.load(paper.path)
    paper.reset()
    twin.reset()
    for _ in range(3):
        a = paper.step(scene.x0, scene.goal, scene.humans_now, scene.humans_pred, scene.obstacle)
        twin.prepare(scene.goal, scene.humans_now, scene.humans_pred, scene.obstacle, x0_guess=scene.x0)
        b = twin.feedback(scene.x0)
        np.testing.assert_array_equal(a.x, b.x)
        np.testing.assert_array_equal(a.u, b.u)


def test_runtime_parameters_change_the_plan_without_regenerating(paper: humanmpc.Solver) -> None:
    scene = random_scene(np.random.default_rng(9), 3)
    before = paper.params
    try:
        paper.reset()
        a = paper.solve(scene.x0, scene.goal, scene.humans_now, scene.humans_pred, scene.obstacle)
        paper.set_params(w_goal=[2.0, 2.0, 0.0, 10.0], q=6.0)
        assert paper.params["q"] == 6.0 and paper.params["w_goal"] == (2.0, 2.0, 0.0, 10.0)
        paper.reset()
        b = paper.solve(scene.x0, scene.goal, scene.humans_now, scene.humans_pred, scene.obstacle)
        assert np.max(np.abs(a.x - b.x)) > 1e-2
    finally:
        paper.set_params(**{k: v for k, v in before.items()})
    with pytest.raises(KeyError, match="unknown parameter 'qq'"):
        paper.set_params(qq=1.0)
    with pytest.raises(ValueError, match="kappa must be a number with 0 < kappa"):
        paper.set_params(kappa=0.0)
    with pytest.raises(ValueError, match="v_bounds must be"):
        paper.set_params(v_bounds=[1.0, 0.0])
    with pytest.raises(ValueError, match="finite"):
        paper.set_params(w_control=[np.nan, 0.0])
    assert paper.params == before
