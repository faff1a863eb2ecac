"""Speed and separation (humans.separation, humans.reaction_time): the commanded speed towards a person
is at most the speed from which braking at the lower acceleration bound, after the reaction time, stops
the robot before they come within d_h, while they close in; the monitor stops when braking cannot
keep it.

The expected speeds are computed here by hand from the stopping distance, not by the runtime's formula:
a robot at speed v towards a person at distance d who closes in at c needs
    v t_r + v^2 / (2 a) + c (t_r + v / a) <= d - d_h
(its own reaction and braking distance, and the person's walk while it reacts and brakes). With the
defaults t_r = 0.3 s, a = 1 m/s^2, d_h = 0.5 m.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import humanmpc

N = 50
DT = 0.1
T_R, A_BRAKE, D_H = 0.3, 1.0, 0.5
SIDE = 0.55  # m: the people's offset from the robot's line


def stopping_distance(v: float, c: float) -> float:
    """How far the gap to a person closing in at c shrinks before a robot at v has stopped."""
    return v * T_R + v * v / (2 * A_BRAKE) + c * (T_R + v / A_BRAKE)


def step_towards(solver: humanmpc.Solver, v0: float, person: tuple[float, float], velocity: tuple[float, float],
                 goal_speed: float = 1.0) -> humanmpc.StepResult:
    """The plan of a robot at the origin heading along +x at v0, the goal 20 m ahead, one person: a full
    SQP, so that the bound at every node holds at the plan's own positions (a real-time iteration
    freezes the bounds at the shifted previous plan, a cold start's being a straight line at v0)."""
    h = np.array([person])
    vel = np.array([velocity])
    pred = np.stack([h + vel * DT * n for n in range(N + 1)])
    solver.reset()
    return solver.solve(np.array([0.0, 0.0, 0.0, v0]), np.array([20.0, 0.0, 0.0, goal_speed]), h, pred, None,
                        max_iter=50, tol=1e-8)


@pytest.fixture()
def solver(default_dir: Path) -> humanmpc.Solver:
    s = humanmpc.load(default_dir)
    # no collision cost: nothing but the bound holds the robot back (the goal asks for 1 m/s)
    s.set_params(q=0.0, deadline_ms=1e5)  # full SQPs (solve) keep the deadline: not what is tested here
    assert s.params["separation"] == 1 and s.params["reaction_time"] == T_R
    assert tuple(s.params["a_bounds"]) == (-A_BRAKE, 1.0) and s.params["d_h"] == D_H
    return s


# The person is 0.55 m to the side of the robot's line: the straight line keeps d_h, so nothing but the
# bound holds the robot back. Its heading then closes the gap at cos_phi = x / d of its speed:
#     cos_phi (v t_r + v^2 / (2 a)) + c (t_r + v / a) = d - d_h
@pytest.mark.parametrize(("ahead", "closing", "expected"), [
    # standing at (0.8, 0.55): d = 0.970824, cos_phi = 0.824046, c = 0
    #   v^2 / 2 + 0.3 v - 0.571356 = 0  ->  v = -0.3 + sqrt(0.09 + 1.142712)
    (0.8, 0.0, 0.810276),
    # at (1.3, 0.55) walking at 0.5 m/s along -x: d = 1.411559, cos_phi = 0.920968, c = 0.5 * 1.3 / d = 0.460484
    #   0.460484 v^2 + 0.736773 v - 0.773415 = 0  ->  v = (-0.736773 + sqrt(1.967417)) / 0.920968
    (1.3, 0.5, 0.723023),
])
def test_commanded_speed_is_the_hand_computed_speed_whose_stopping_distance_is_the_gap(
        solver: humanmpc.Solver, ahead: float, closing: float, expected: float) -> None:
    r = step_towards(solver, 0.8, (ahead, SIDE), (-closing, 0.0))
    assert not r.stop
    v = float(r.command[0])
    assert v == pytest.approx(expected, abs=1e-4)
    d = float(np.hypot(ahead, SIDE))
    c = closing * ahead / d
    gap = ahead / d * (v * T_R + v * v / (2 * A_BRAKE)) + c * (T_R + v / A_BRAKE)
    assert gap == pytest.approx(d - D_H, abs=2e-4)


def test_every_planned_speed_keeps_the_stopping_distance_from_where_the_person_will_be(
        solver: humanmpc.Solver) -> None:
    closing = 0.5
    r = step_towards(solver, 0.8, (3.0, SIDE), (-closing, 0.0))
    assert not r.stop
    for n in range(1, N + 1):
        p, theta, v = r.x[n - 1, :2], r.x[n - 1, 2], r.x[n, 3]
        h = np.array([3.0 - closing * DT * (n - 1), SIDE])
        d = float(np.linalg.norm(h - p))
        cos_phi = float(np.dot([np.cos(theta), np.sin(theta)], h - p)) / d
        if cos_phi <= 0.0:
            continue
        c = closing * float((h - p)[0]) / d  # the person's velocity (-closing, 0) towards the robot
        # the robot's part of the stopping distance is along its heading: cos_phi of it closes the gap
        gap = cos_phi * (v * T_R + v * v / (2 * A_BRAKE)) + max(c, 0.0) * (T_R + v / A_BRAKE)
        braked = max(0.0, 0.8 - A_BRAKE * DT * n)  # a bound that braking cannot keep is the monitor's
        if v > braked + 1e-6:
            assert gap <= d - D_H + 1e-4, f"node {n}: v = {v:.4f} m/s needs {gap:.4f} m, has {d - D_H:.4f} m"


def test_a_person_walking_away_earns_no_credit(solver: humanmpc.Solver) -> None:
    r = step_towards(solver, 0.8, (0.8, SIDE), (1.0, 0.0))
    assert float(r.command[0]) == pytest.approx(0.810276, abs=1e-4)  # as if standing


def test_a_person_behind_the_robot_does_not_bound_its_speed(solver: humanmpc.Solver) -> None:
    r = step_towards(solver, 0.8, (-0.8, SIDE), (0.0, 0.0))
    assert not r.stop
    assert float(r.command[0]) == pytest.approx(0.8 + 1.0 * DT, abs=1e-4)  # full acceleration


def test_a_person_too_close_to_brake_for_stops_the_robot_with_its_own_reason(solver: humanmpc.Solver) -> None:
    # 1 m/s, a person appears at (0.55, 0.52): d = 0.756902, cos_phi = 0.726646; the bound
    # v^2 / 2 + 0.3 v - 0.353523 = 0 gives v = 0.592767 m/s, and braking for one period reaches 0.9 only
    r = step_towards(solver, 1.0, (0.55, 0.52), (0.0, 0.0))
    assert r.stop and r.reason == "separation" and r.stop_reason == 8
    assert float(r.u0[0]) == -A_BRAKE and float(r.command[0]) == pytest.approx(1.0 - A_BRAKE * DT)
    assert float(r.u0[1]) == 0.0 and float(r.command[1]) == 0.0


def test_without_separation_the_same_situations_are_neither_stopped_nor_slowed(solver: humanmpc.Solver) -> None:
    solver.set_params(separation=0)
    r = step_towards(solver, 1.0, (0.55, 0.52), (0.0, 0.0))
    assert not r.stop
    r = step_towards(solver, 0.8, (0.8, SIDE), (0.0, 0.0))
    assert float(r.command[0]) == pytest.approx(0.9, abs=1e-4)


def test_reaction_time_lowers_the_speed_as_the_stopping_distance_says(solver: humanmpc.Solver) -> None:
    solver.set_params(reaction_time=0.0)
    # cos_phi v^2 / 2 = 0.470824 gives v = 1.069 m/s: not binding, full acceleration
    r = step_towards(solver, 0.8, (0.8, SIDE), (0.0, 0.0))
    assert float(r.command[0]) == pytest.approx(0.9, abs=1e-4)
    solver.set_params(reaction_time=1.0)
    # v^2 / 2 + v - 0.571356 = 0: v = -1 + sqrt(2.142712)
    r = step_towards(solver, 0.45, (0.8, SIDE), (0.0, 0.0))
    assert float(r.command[0]) == pytest.approx(0.463801, abs=1e-4)


def test_the_controller_stops_for_a_track_running_at_the_robot(default_dir: Path) -> None:
    ctl = humanmpc.load(default_dir).controller()
    # (1.2, 0.55) at 2 m/s along -x: d = 1.32, c = 1.82 m/s, c t_r = 0.55 of the 0.82 m gap: the bound is
    # 0.1 m/s, braking for one period reaches 0.7
    r = ctl.step(0.0, pose=(0.0, 0.0, 0.0), v=0.8, omega=0.0, goal=(10.0, 0.0, 0.0),
                 people=np.array([[1.2, SIDE, -2.0, 0.0]]))
    assert r.stop and r.reason == "separation"
    assert float(r.u[0]) == -A_BRAKE and float(r.command[1]) == 0.0
    assert np.all(np.isfinite(r.command))
