"""Relative cumulative sub-optimality: the formula, the reference, and the common plan cost on
examples whose answer is known."""

from __future__ import annotations

import math

import numpy as np
import pytest

from humanmpc.codegen.reference_nlp import ReferenceNlp
from humanmpc.codegen.spec import resolve_spec
from humanmpc.compare.rcso import plan_costs, rcso, reference_costs
from humanmpc.compare.replay import Replay


def test_rcso_of_a_constructed_sequence() -> None:
    optimal = [10.0, 20.0, 30.0]
    assert rcso([11.0, 20.0, 33.0], optimal) == (pytest.approx(4.0 / 60.0), 3)
    assert rcso(optimal, optimal) == (0.0, 3)
    # A better local optimum than the reference counts negative.
    assert rcso([9.0, 20.0, 30.0], optimal)[0] == pytest.approx(-1.0 / 60.0)
    # Steps without a reference or without a finite plan cost are left out, and counted.
    value, n = rcso([11.0, np.nan, 33.0, 5.0], [10.0, 20.0, 30.0, np.nan])
    assert (value, n) == (pytest.approx(4.0 / 40.0), 2)
    value, n = rcso([np.nan], [1.0])
    assert math.isnan(value) and n == 0
    with pytest.raises(ValueError, match="same shape"):
        rcso([1.0, 2.0], [1.0])
    with pytest.raises(ValueError, match="positive total"):
        rcso([1.0], [0.0])


def test_reference_is_the_best_successful_run() -> None:
    cold = np.array([10.0, 12.0, 7.0, 1.0])
    warm = np.array([11.0, 9.0, 8.0, 0.5])
    ok_cold = np.array([True, True, False, False])
    ok_warm = np.array([True, True, True, False])
    ref = reference_costs([cold, warm], [ok_cold, ok_warm])
    np.testing.assert_array_equal(ref[:3], [10.0, 9.0, 8.0])
    assert math.isnan(ref[3])
    with pytest.raises(ValueError, match="at least one"):
        reference_costs([], [])


def potential(d: float, q: float, d_th: float, kappa: float) -> float:
    if d <= d_th:
        return -(kappa * q / 4) * d + (q / 2 + kappa * q * d_th / 4)
    return q / (1 + math.exp(kappa * (d - d_th)))


def test_plan_cost_of_a_hand_computed_plan() -> None:
    """N = 2, the robot standing still at the origin: every term by hand."""
    spec = resolve_spec({
        "humans": {"max": 2, "d_h": 0.3},
        "horizon": {"N": 2, "T": 0.2},
        "weights": {"goal": [1.0, 2.0, 0.0, 3.0], "goal_terminal": [4.0, 5.0, 0.0, 0.0], "control": [0.5, 0.25]},
        "collision_cost": {"q": 2.0, "d_th": 1.0, "kappa": 5.0},
        "obstacle": {"d_s": 0.8, "slack_l1": 10.0, "slack_l2": 6.0},
    })
    nlp = ReferenceNlp(spec)
    goal = np.array([1.0, 1.0, 0.0, 0.5])
    human = np.array([3.0, 4.0])  # the same predicted position at every node
    step = {"x0": np.zeros(4), "goal": goal, "humans_now": human[None], "humans_pred": np.tile(human, (3, 1, 1)),
            "obstacle": np.array([0.3, 0.4])}
    replay = Replay.from_steps([step, {**step, "humans_now": None, "humans_pred": None, "obstacle": None}], spec)
    costs, violation = plan_costs(nlp, replay, np.zeros((2, 2, 2)))

    eps2 = 1e-6
    goal_terms = 2 * (1 * 1 + 2 * 1 + 0 + 3 * 0.25) + (4 * 1 + 5 * 1)  # two stages + terminal
    collision = 3 * potential(math.sqrt(25 + eps2), 2.0, 1.0, 5.0)  # nodes 0, 1, 2
    s = 0.8 - math.sqrt(0.25 + eps2)  # obstacle slack at nodes 1 and 2
    slack = 2 * (10.0 * s + 0.5 * 6.0 * s * s)
    assert costs[0] == pytest.approx(goal_terms + collision + slack, rel=1e-12)
    assert costs[1] == pytest.approx(goal_terms, rel=1e-12)
    assert violation.tolist() == [0.0, 0.0]

    # Controls are costed through the model: a = 1 for one interval moves the robot (RK4, exact
    # for constant acceleration along theta = 0) and adds 0.5 * 1^2 of control cost.
    u = np.zeros((2, 2, 2))
    u[1, 0, 0] = 1.0
    moved, _ = plan_costs(nlp, replay, u)
    x1 = np.array([0.005, 0.0, 0.0, 0.1])
    x2 = np.array([0.015, 0.0, 0.0, 0.1])
    w, wN = np.array([1.0, 2.0, 0.0, 3.0]), np.array([4.0, 5.0, 0.0, 0.0])
    expected = (np.sum(w * goal**2) + 0.5 + np.sum(w * (x1 - goal) ** 2) + np.sum(wN * (x2 - goal) ** 2))
    assert moved[1] == pytest.approx(expected, rel=1e-12)
    # Non-finite controls have no cost.
    u[0, 1, 1] = np.nan
    assert math.isnan(plan_costs(nlp, replay, u)[0][0])


def test_optimal_plans_have_zero_and_perturbed_plans_positive_rcso() -> None:
    spec = resolve_spec({"humans": {"max": 3}, "horizon": {"N": 15, "T": 1.5}})
    nlp = ReferenceNlp(spec)
    rng = np.random.default_rng(1)
    steps = []
    for _ in range(3):
        now = rng.uniform([1.0, -2.0], [4.0, 2.0], (3, 2))
        steps.append({"x0": np.array([0.0, 0.0, 0.0, 0.5]), "goal": np.array([4.0, 0.0, 0.0, 0.8]),
                      "humans_now": now, "humans_pred": np.tile(now, (16, 1, 1)), "obstacle": np.array([2.0, 1.0])})
    replay = Replay.from_steps(steps, spec)
    solver = nlp.nlp_solver(tol=1e-10)
    U = np.zeros((3, 15, 2))
    for t in range(3):
        p = nlp.params.pack(**replay.inputs(t), params=replay.params)
        lbw, ubw, lbg, ubg = nlp.bounds(p)
        sol = solver(x0=nlp.cold_guess(p), p=p, lbx=lbw, ubx=ubw, lbg=lbg, ubg=ubg)
        assert solver.stats()["success"]
        U[t] = nlp.decision.unpack(np.array(sol["x"]).ravel())[1]
    optimal, violation = plan_costs(nlp, replay, U)
    assert np.all(violation <= 1e-6)
    assert rcso(optimal, optimal) == (0.0, 3)
    worse = U.copy()
    worse[:, :, 1] += 0.2  # turn more than optimal
    costs, _ = plan_costs(nlp, replay, worse)
    value, n = rcso(costs, optimal)
    assert n == 3 and value > 1e-4
