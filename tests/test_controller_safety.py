"""The controller's safety guarantees, whatever the tracks and whatever it is doing: someone within d_h
always stops the robot, every stop brakes towards standstill from either direction, the heading has no
limit a long mission can reach, the deadline covers the whole controller step, and too many tracks mean
one thing in every face (the nearest are kept, the rest reported).

Each test reproduces an attack on an earlier controller (the values are the attack's) through the Python
face of the generated C; the robot is the simulation's unicycle, driven by the controller's commands.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.controller import Controller
from humanmpc.sim.robot import RobotModel, step
from tests.conftest import make_solver

DT = 0.1
D_H = 0.5  # [m], both specs


@pytest.fixture(scope="module")
def paper_preset_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """preset: paper: N_h = 2 people in the OCP, no speed-and-separation bound."""
    return make_solver(tmp_path_factory.mktemp("safety_paper"), {"name": "safety_paper", "preset": "paper",
                                                                   "humans": {"max": 2}})


@pytest.fixture()
def ctl(default_dir: Path) -> Controller:
    return humanmpc.load(default_dir).controller()


def drive(ctl: Controller, people: np.ndarray, steps: int, *, covariances: np.ndarray | None = None,
          goal: tuple[float, float, float] = (5.0, 0.0, 0.0), v0: float = 0.0) -> list[tuple[np.ndarray, object]]:
    """A closed loop against standing people: (state before the step, result) per step."""
    x = np.array([0.0, 0.0, 0.0, v0])
    out = []
    for k in range(steps):
        r = ctl.step(k * DT, pose=x[:3], v=x[3], goal=goal, people=people, covariances=covariances)
        out.append((x.copy(), r))
        v = float(r.command[0])
        x[0] += DT * v * np.cos(x[2])
        x[1] += DT * v * np.sin(x[2])
        x[2] += DT * float(r.command[1])
        x[3] = v
    return out


def nearest(x: np.ndarray, people: np.ndarray) -> float:
    return float(np.min(np.hypot(people[:, 0] - x[0], people[:, 1] - x[1])))


def brakes(v: float, r: object) -> bool:
    """The command moves the speed towards 0 without crossing it, and does not turn."""
    cmd = r.command  # type: ignore[attr-defined]
    return abs(cmd[0]) <= abs(v) + 1e-12 and cmd[0] * v >= 0.0 and cmd[1] == 0.0


# -- someone within d_h, whatever the ranking of the tracks -----------------------------------------------

def test_a_person_within_d_h_stops_the_robot_though_uncertain_tracks_outrank_them(paper_preset_dir: Path) -> None:
    """N_h = 2; two uncertain tracks 3 m away rank before a person 0.3 m ahead by their 2-sigma margin. The
    robot stood still (0.30 m) and, once moving, drove into the person (0.02 m at step 7) with no stop."""
    ctl = humanmpc.load(paper_preset_dir).controller()
    people = np.array([[0, 3, 0, 0], [0, -3, 0, 0], [0.3, 0, 0, 0]], dtype=float)
    cov = np.array([[4, 0, 4], [4, 0, 4], [0.01, 0, 0.01]], dtype=float)
    for x, r in drive(ctl, people, 20, covariances=cov):
        assert nearest(x, people) >= 0.3 - 1e-9          # never nearer than where it started
        assert r.stop and r.reason == "human_too_close"  # type: ignore[attr-defined]
        assert brakes(x[3], r)


@pytest.mark.parametrize("where", [(0.0, 0.3), (-0.3, 0.0)], ids=["beside", "behind"])
def test_a_person_within_d_h_beside_or_behind_stops_the_robot_among_many_tracks(ctl: Controller,
                                                                                 where: tuple[float, float]) -> None:
    """The default spec (N_h = 10): ten uncertain tracks 3 m away and one person 0.3 m beside or behind. The
    controller had commanded [0.1, 0] with u = [1, 0] and no stop."""
    far = [[3 * np.cos(a), 3 * np.sin(a), 0, 0] for a in np.linspace(0, 2 * np.pi, 10, endpoint=False)]
    people = np.array([*far, [*where, 0, 0]], dtype=float)
    cov = np.array([[4, 0, 4]] * 10 + [[0.01, 0, 0.01]], dtype=float)
    r = ctl.step(0.0, pose=(0, 0, 0), v=0.0, goal=(5, 0, 0), people=people, covariances=cov)
    assert r.stop and r.reason == "human_too_close" and r.command.tolist() == [0.0, 0.0]


@pytest.mark.parametrize("speed", [2.0, 2.4])
def test_a_person_overtaking_from_behind_comes_to_a_robot_at_rest(ctl: Controller, speed: float) -> None:
    """A person 3 m behind on the robot's line runs after it at 2.5-3 times its speed (tracked for 1.5 s or more
    before they arrive, longer than the reaction and braking time, 0.3 + 0.8 s). The speed-and-separation
    bound sees people ahead only: the robot braked only once they were within d_h, at 0.4 m/s. Now it stops
    while a stop can still bring it to rest before they come within d_h."""
    sim = RobotModel()
    x = np.array([0.0, 0.0, 0.0, 0.8])
    person = np.array([-3.0, 0.0, speed, 0.0])
    reasons = set()
    for k in range(60):
        now = person.copy()
        now[:2] += k * DT * person[2:]
        r = ctl.step(k * DT, pose=x[:3], v=x[3], goal=(10.0, 0.0, 0.0), people=now[None, :])
        if r.stop:
            reasons.add(r.reason)
        if nearest(x, now[None, :]) < D_H:
            assert abs(x[3]) < 0.05, f"moving at {x[3]:.2f} m/s {nearest(x, now[None, :]):.2f} m from them"
        x = step(sim, x, r.u, DT)
    assert "predicted_contact" in reasons


def test_the_ocp_sees_everyone_within_the_stopping_reach_whatever_their_rank(paper_preset_dir: Path) -> None:
    """A person 1 m ahead (outside d_h, inside the stopping reach of a robot at 0.8 m/s) and two uncertain
    tracks 3 m away: N_h = 2 and the person is one of the two."""
    ctl = humanmpc.load(paper_preset_dir).controller()
    people = np.array([[0, 3, 0, 0], [0, -3, 0, 0], [1.0, 0.0, 0, 0]], dtype=float)
    cov = np.array([[4, 0, 4], [4, 0, 4], [0.01, 0, 0.01]], dtype=float)
    r = ctl.step(0.0, pose=(0, 0, 0), v=0.8, goal=(5, 0, 0), people=people, covariances=cov)
    assert 2 in r.people_index.tolist()


def test_a_person_within_d_h_stops_the_robot_at_its_goal_and_without_one(ctl: Controller) -> None:
    """At the goal (goal (0.1, 0, 0), someone at 0.2 m) the controller reported goal_reached with no stop;
    without a goal, 'no goal' with no stop."""
    person = np.array([[0.2, 0.0, 0.0, 0.0]])
    r = ctl.step(0.0, pose=(0, 0, 0), v=0.3, goal=(0.1, 0.0, 0.0), people=person)
    assert r.stop and r.reason == "human_too_close" and r.outcome_name == "stopped" and brakes(0.3, r)
    r = ctl.step(0.1, pose=(0, 0, 0), v=0.3, people=person)
    assert r.stop and r.reason == "human_too_close" and r.outcome_name == "stopped" and brakes(0.3, r)
    # turning in place to the goal's heading
    r = ctl.step(0.2, pose=(0, 0, 0), v=0.0, goal=(0.1, 0.0, 2.0), people=person)
    assert r.stop and r.reason == "human_too_close" and r.command.tolist() == [0.0, 0.0]


# -- every stop brakes ---------------------------------------------------------------------------------------

def test_an_upper_acceleration_bound_that_cannot_brake_a_reversing_robot_is_refused(ctl: Controller) -> None:
    with pytest.raises(ValueError, match="a_bounds must be"):
        ctl.set_params(v_bounds=[-1.0, 1.0], a_bounds=[-1.0, 1e-9])


def test_a_stop_brakes_a_reversing_robot_at_the_upper_acceleration_bound(ctl: Controller) -> None:
    """v = -0.8 m/s towards a person 0.3 m behind: the stop had held v = -0.8 for five steps."""
    ctl.set_params(v_bounds=[-1.0, 1.0], a_bounds=[-1.0, 0.5])
    people = np.array([[-0.3, 0.0, 0.0, 0.0]])
    r = ctl.step(0.0, pose=(0, 0, 0), v=-0.8, goal=(5, 0, 0), people=people)
    assert r.stop and r.reason == "human_too_close"
    assert r.u[0] == pytest.approx(0.5) and r.command[0] == pytest.approx(-0.75) and brakes(-0.8, r)


def test_a_stop_without_a_pose_brakes_a_reversing_robot_instead_of_speeding_it_up(ctl: Controller) -> None:
    """NaN pose, v = -0.5: the stop commanded u = [-1, 0]."""
    ctl.set_params(v_bounds=[-1.0, 1.0])
    r = ctl.step(0.0, pose=(np.nan, 0, 0), v=-0.5, goal=(5, 0, 0))
    assert r.stop and r.reason == "invalid_input"
    assert r.u[0] > 0.0 and brakes(-0.5, r)
    r = ctl.step(0.1, pose=(0, 0, 0), v=np.nan, goal=(5, 0, 0))
    assert r.stop and r.u.tolist() == [0.0, 0.0] and r.command.tolist() == [0.0, 0.0]


@pytest.mark.parametrize("v", [1.18, -0.197])
def test_braking_at_the_goal_passes_the_command_guard(ctl: Controller, v: float) -> None:
    """At the goal, from a speed outside the bounds: the braking skipped the command guard (cmd [1.08, 0]
    above v_bounds, or [-0.097, 0] below them, with no stop). Now a stop of its own reason, still braking."""
    r = ctl.step(0.0, pose=(0, 0, 0), v=v, goal=(0.1, 0.0, 0.0))
    assert r.stop and r.reason == "command_bounds" and brakes(v, r)


# -- the heading, the deadline, too many tracks --------------------------------------------------------------

def test_a_robot_that_keeps_turning_one_way_never_reaches_a_heading_limit(ctl: Controller) -> None:
    """Odometry wraps the heading to (-pi, pi]; the controller unwinds it. 3 rad a period for 3,500 periods
    is 10,500 rad, beyond the inputs' 1e4 rad limit that stopped the robot for good after 2.8 h."""
    theta = 0.0
    for k in range(3500):
        wrapped = float(np.angle(np.exp(1j * theta)))
        r = ctl.step(k * DT, pose=(0.0, 0.0, wrapped), v=0.0, goal=(50.0, 0.0, 0.0))
        assert r.reason != "invalid_input", k
        theta += 3.0
    assert abs(r.plan[0, 2]) <= 64.0 + 2 * np.pi


def test_the_deadline_covers_the_whole_controller_step(ctl: Controller) -> None:
    """A step at the goal runs no solver, so no deadline was checked: with a deadline of 1 ns it braked
    with no stop."""
    ctl.set_params(deadline_ms=1e-6)
    r = ctl.step(0.0, pose=(0, 0, 0), v=0.3, goal=(0.1, 0.0, 0.0))
    assert r.stop and r.reason == "deadline" and brakes(0.3, r)
    r = ctl.step(0.1, pose=(0, 0, 0), v=0.3, goal=(5.0, 0.0, 0.0), people=np.array([[3.0, 1.0, 0, 0]]))
    assert r.stop and r.reason == "deadline" and brakes(0.3, r)


def test_too_many_tracks_keep_the_nearest_and_say_how_many_were_left_out(ctl: Controller) -> None:
    """More tracks than max_tracks raised in Python while the C called it an invalid input and the ROS node
    kept the nearest: now every face keeps the nearest, through the C."""
    m = ctl.max_tracks
    far = np.array([[10.0 + i, 5.0, 0.0, 0.0] for i in range(m + 5)])
    people = np.vstack([far, [[0.3, 0.0, 0.0, 0.0]]])  # the nearest comes last
    r = ctl.step(0.0, pose=(0, 0, 0), v=0.0, goal=(5, 0, 0), people=people, ids=np.arange(len(people)))
    assert r.n_tracks_dropped == 6
    assert r.stop and r.reason == "human_too_close"
    r = ctl.step(0.1, pose=(0, 0, 0), v=0.0, goal=(5, 0, 0), people=far)
    assert r.n_tracks_dropped == 5 and not r.stop
    # a track with no position is kept (it counts as nearest) and stops the robot as an invalid input
    r = ctl.step(0.2, pose=(0, 0, 0), v=0.0, goal=(5, 0, 0), people=np.vstack([far, [[np.nan, 0, 0, 0]]]))
    assert r.stop and r.reason == "invalid_input" and r.n_tracks_dropped == 6
