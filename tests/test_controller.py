"""The navigation controller in the generated C, through its Python face, with the spec's defaults.

Closed loops here drive the robot model of the simulation with the controller's commands; people
are scripted (they walk as told, whatever the robot does), so every outcome is the controller's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.controller import Controller
from humanmpc.planners.global_path import plan_path
from humanmpc.results import ControllerResult
from humanmpc.sim.robot import RobotModel, step
from humanmpc.sim.world import Polygon, World
from tests.conftest import make_solver

DT = 0.1
D_H, D_TH = 0.5, 1.0  # the spec's defaults [m]
People = Callable[[float], np.ndarray]  # time -> (k, 4) tracks [x, y, vx, vy]


@pytest.fixture()
def ctl(default_dir: Path) -> Controller:
    return humanmpc.load(default_dir).controller()


def walking(*tracks: tuple[float, float, float, float]) -> People:
    """People walking at constant velocity from their positions at t = 0."""
    start = np.array(tracks, dtype=float).reshape(-1, 4)

    def at(t: float) -> np.ndarray:
        now = start.copy()
        now[:, :2] += t * start[:, 2:]
        return now

    return at


@dataclass
class Run:
    states: list[np.ndarray] = field(default_factory=list)
    results: list[ControllerResult] = field(default_factory=list)
    people: list[np.ndarray] = field(default_factory=list)

    @property
    def xy(self) -> np.ndarray:
        return np.array([s[:2] for s in self.states])

    def min_distance(self) -> float:
        """Smallest distance between the robot and anyone, over the run [m] (inf: nobody)."""
        d = [np.min(np.hypot(*(p[:, :2] - s[:2]).T)) for s, p in zip(self.states, self.people, strict=True) if len(p)]
        return float(min(d)) if d else np.inf

    def path_length(self) -> float:
        return float(np.sum(np.linalg.norm(np.diff(self.xy, axis=0), axis=1)))


def drive(ctl: Controller, start: tuple[float, float, float], goal: tuple[float, float, float], *,
          people: People | None = None, obstacles: np.ndarray | None = None, path: np.ndarray | None = None,
          seconds: float = 40.0) -> Run:
    """The closed loop until the controller says the goal is reached and the robot stands, or time is up."""
    model = RobotModel()
    x = np.array([*start, 0.0])
    run = Run()
    for k in range(round(seconds / DT)):
        t = k * DT
        now = people(t) if people is not None else np.zeros((0, 4))
        r = ctl.step(t, pose=x[:3], v=x[3], path=path, goal=goal, people=now, obstacles=obstacles)
        assert np.all(np.isfinite(r.command)) and np.all(np.isfinite(r.u))
        run.states.append(x.copy())
        run.people.append(now)
        run.results.append(r)
        x = step(model, x, r.u, DT)
        if r.goal_reached and abs(x[3]) < 1e-9:
            run.states.append(x.copy())
            run.people.append(people(t + DT) if people is not None else np.zeros((0, 4)))
            break
    return run


def never_silently_stalled(run: Run, stall_time: float) -> bool:
    """Whenever the robot has not come 0.2 m nearer its goal for stall_time + 1 s, the controller says so
    (stalled) or is in a protective stop, or has reached the goal."""
    left = np.array([r.distance_to_goal for r in run.results])
    window = round((stall_time + 1.0) / DT)
    for k in range(window, len(left)):
        if left[k - window] - left[k] < 0.2:
            r = run.results[k]
            if not (r.stalled or r.stop or r.goal_reached):
                return False
    return True


# -- the goal the OCP sees ------------------------------------------------------------------------


def test_the_carrot_lies_lookahead_metres_along_an_l_shaped_path_with_its_heading(ctl: Controller) -> None:
    """Hand-computed: path (0,0) -> (2,0) -> (2,5), robot at (0.5, 0.3): projection (0.5, 0); the carrot
    v_ref * T = 4 m further along is 1.5 m to the corner and 2.5 m up: (2, 2.5), heading pi/2."""
    path = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 5.0]])
    r = ctl.step(0.0, pose=(0.5, 0.3, 0.0), v=0.0, path=path)
    np.testing.assert_allclose(r.ocp_goal[:3], [2.0, 2.5, np.pi / 2], atol=1e-12)
    assert r.distance_to_goal == pytest.approx(6.5)  # 1.5 + 5 m left along the path
    assert r.ocp_goal[3] == pytest.approx(0.8)  # v_ref, not tapered 6.5 m away


def test_near_the_goal_the_ocp_sees_the_final_pose_and_arrives_at_rest(ctl: Controller) -> None:
    """The carrot objective (progress off), 3 m from the goal (less than v_ref * T = 4 m): the final pose
    with its heading, no speed to track."""
    ctl.set_params(progress=0)
    r = ctl.step(0.0, pose=(0.0, 0.0, 0.0), v=0.5, goal=(3.0, 0.0, 0.3))
    np.testing.assert_allclose(r.ocp_goal, [3.0, 0.0, 0.3, 0.0], atol=1e-12)
    ctl.set_params(approach=0)
    r = ctl.step(0.1, pose=(0.0, 0.0, 0.0), v=0.5, goal=(1.2, 0.0, 0.3))
    assert r.ocp_goal[3] == pytest.approx(0.5 * 1.2)  # goal_taper * distance left < v_ref


def test_a_heading_across_the_wrap_reaches_the_ocp_unwrapped(ctl: Controller) -> None:
    """Odometry wraps at +-pi; the OCP's heading must not jump by 2 pi between periods."""
    ctl.step(0.0, pose=(0.0, 0.0, np.pi - 0.01), v=0.0, goal=(-5.0, 0.01, np.pi))
    r = ctl.step(0.1, pose=(0.0, 0.0, -np.pi + 0.01), v=0.0, goal=(-5.0, -0.01, np.pi))
    assert r.plan[0, 2] == pytest.approx(np.pi + 0.01)
    assert abs(r.ocp_goal[2] - r.plan[0, 2]) < np.pi


# -- the people the OCP sees ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def one_person_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_solver(tmp_path_factory.mktemp("one"), {"name": "one", "horizon": {"N": 20, "T": 2.0},
                                                         "humans": {"max": 1}, "controller": {"max_tracks": 4}})


def test_the_person_the_ocp_sees_is_the_one_nearest_over_the_horizon_not_now(one_person_dir: Path) -> None:
    """N_h = 1 of two tracks. Robot at rest at the origin facing +x. A: 1.5 m away, walking off at
    1 m/s (nearest now, 1.5 m at best). B: 2.5 m ahead, walking at the robot at 1 m/s (0 m at t = 2.5 s
    is beyond the 2 s horizon: 0.5 m at t = 2 s). B is chosen."""
    ctl = humanmpc.load(one_person_dir).controller()
    people = np.array([[0.0, 1.5, 0.0, 1.0], [2.5, 0.0, -1.0, 0.0]])
    r = ctl.step(0.0, pose=(0.0, 0.0, 0.0), v=0.0, goal=(10.0, 0.0, 0.0), people=people, ids=np.array([7, 9]))
    assert r.people_ids.tolist() == [9] and r.people_index.tolist() == [1]
    np.testing.assert_allclose(r.predictions[:, 0], [[2.5 - 0.1 * n, 0.0] for n in range(21)], atol=1e-12)
    # A standing still 1.5 m away is nearer than B, who walks off at 1 m/s
    people = np.array([[0.0, 1.5, 0.0, 0.0], [2.5, 0.0, 1.0, 0.0]])
    r = ctl.step(0.1, pose=(0.0, 0.0, 0.0), v=0.0, goal=(10.0, 0.0, 0.0), people=people, ids=np.array([7, 9]))
    assert r.people_ids.tolist() == [7]


def test_an_uncertain_track_counts_as_nearer(one_person_dir: Path) -> None:
    """Two standing people 2.0 and 2.4 m away; the farther one's position has a standard deviation of
    0.3 m (2 sigma = 0.6 m): 2.4 - 0.6 = 1.8 < 2.0, it is chosen."""
    ctl = humanmpc.load(one_person_dir).controller()
    people = np.array([[0.0, 2.0, 0.0, 0.0], [0.0, -2.4, 0.0, 0.0]])
    cov = np.array([[np.nan, np.nan, np.nan], [0.09, 0.0, 0.01]])
    r = ctl.step(0.0, pose=(0.0, 0.0, 0.0), v=0.0, goal=(10.0, 0.0, 0.0), people=people, covariances=cov)
    assert r.people_index.tolist() == [1]


def test_the_obstacle_the_ocp_sees_is_the_point_nearest_the_robot(ctl: Controller) -> None:
    pts = np.array([[3.0, 3.0], [0.5, -1.0], [-2.0, 0.0]])
    r = ctl.step(0.0, pose=(0.0, 0.0, 0.0), v=0.0, goal=(5.0, 0.0, 0.0), obstacles=pts)
    assert r.obstacle is not None and r.obstacle.tolist() == [0.5, -1.0]
    assert ctl.step(0.1, pose=(0.0, 0.0, 0.0), v=0.0, goal=(5.0, 0.0, 0.0)).obstacle is None


# -- behaviour in closed loop, the spec's defaults -------------------------------------------------


def test_with_a_constant_v_ref_the_robot_arrives_and_stops_at_the_goal_without_circling(ctl: Controller) -> None:
    run = drive(ctl, (0.0, 0.0, 0.0), (6.0, 2.0, np.pi / 2), seconds=30.0)
    last = run.results[-1]
    assert last.goal_reached and last.outcome_name == "goal_reached"
    assert np.hypot(*(run.xy[-1] - [6.0, 2.0])) <= 0.3 + 0.15  # tolerance + braking distance
    assert run.states[-1][3] == pytest.approx(0.0, abs=1e-9)
    assert run.path_length() < 1.3 * np.hypot(6.0, 2.0)


def test_the_turn_rate_does_not_flip_between_its_bounds_on_the_way_to_a_far_goal(ctl: Controller) -> None:
    """The default spec's RTI (exact Hessian) towards a goal 10 m away and 5 m aside: no step changes
    omega by more than 2 rad/s (the Gauss-Newton RTI of the paper's configuration did on 77 to 190
    of 250 steps)."""
    run = drive(ctl, (0.0, 0.0, 0.0), (10.0, 5.0, 0.0), seconds=25.0)
    omega = np.array([r.command[1] for r in run.results])
    assert run.results[-1].goal_reached
    assert np.max(np.abs(np.diff(omega))) <= 2.0


def test_a_person_standing_on_the_straight_line_is_passed_with_room(ctl: Controller) -> None:
    """Passed at nearly d_th (the potential's half-height, 1 m: a preference the progress objective weighs
    against the path's length; 0.98 m measured), never within d_h."""
    run = drive(ctl, (0.0, 0.0, 0.0), (10.0, 0.0, 0.0), people=walking((5.0, 0.05, 0.0, 0.0)))
    assert run.results[-1].goal_reached
    assert run.min_distance() >= 0.9 * D_TH
    assert never_silently_stalled(run, ctl.params["stall_time"])


def test_a_slow_walker_ahead_in_the_same_direction_is_overtaken(ctl: Controller) -> None:
    run = drive(ctl, (0.0, 0.0, 0.0), (12.0, 0.0, 0.0), people=walking((2.0, 0.0, 0.15, 0.0)))
    assert run.results[-1].goal_reached
    person_x = 2.0 + 0.15 * DT * (len(run.states) - 1)
    assert run.xy[-1, 0] > person_x + 1.0  # ahead of them at the end
    assert run.min_distance() >= D_H
    assert never_silently_stalled(run, ctl.params["stall_time"])


def test_a_head_on_walker_is_passed_with_room(ctl: Controller) -> None:
    run = drive(ctl, (0.0, 0.0, 0.0), (10.0, 0.0, 0.0), people=walking((9.0, 0.1, -1.0, 0.0)))
    assert run.results[-1].goal_reached
    assert run.min_distance() >= D_H


def test_a_crossing_pair_is_let_through_or_passed_without_contact(ctl: Controller) -> None:
    """Two people side by side crossing the robot's way at 1 m/s, timed to meet it mid-way."""
    run = drive(ctl, (0.0, 0.0, 0.0), (10.0, 0.0, 0.0),
                people=walking((5.0, -4.5, 0.0, 1.0), (5.6, -4.5, 0.0, 1.0)))
    assert run.results[-1].goal_reached
    assert run.min_distance() >= D_H


def test_the_robot_reaches_a_goal_that_peoples_predicted_paths_cross(ctl: Controller) -> None:
    """The goal 1.5 m ahead of the robot at rest; two people 5 m to either side walk across it at 1.2 m/s,
    so their predictions reach the goal after about 4 s, when the robot, there after under 3 s, would
    have stopped. The collision potential ends at the robot's earliest arrival (arrival_margin): it
    arrives first, and never nearer anyone than d_th. Without that end (a margin beyond the horizon),
    the predictions push the plan off the goal and the robot waits for them to pass."""
    people = walking((1.5, -5.0, 0.0, 1.2), (1.5, 5.0, 0.0, -1.2))
    run = drive(ctl, (0.0, 0.0, 0.0), (1.5, 0.0, 0.0), people=people, seconds=15.0)
    assert run.results[-1].goal_reached
    assert len(run.states) * DT < 3.5
    assert run.min_distance() >= D_TH
    ctl.reset()
    ctl.set_params(arrival_margin=1e4)
    waited = drive(ctl, (0.0, 0.0, 0.0), (1.5, 0.0, 0.0), people=people, seconds=15.0)
    assert len(waited.states) * DT > 5.0


def test_a_person_crossing_the_goal_before_the_robot_can_arrive_is_let_through(ctl: Controller) -> None:
    """The same goal, one person 1.8 m to its side walking across it at 1.2 m/s: at the goal in 1.5 s,
    before the robot can be (the potential still acts on those nodes). The robot lets them pass."""
    run = drive(ctl, (0.0, 0.0, 0.0), (1.5, 0.0, 0.0), people=walking((1.5, -1.8, 0.0, 1.2)), seconds=15.0)
    assert run.results[-1].goal_reached
    assert run.min_distance() >= D_TH


U_SHAPE = World((Polygon.rectangle((3.0, 0.0), 0.3, 4.0), Polygon.rectangle((1.6, 2.0), 3.0, 0.3),
                 Polygon.rectangle((1.6, -2.0), 3.0, 0.3)), (-4.0, 8.0, -5.0, 5.0))


def test_a_u_shaped_obstacle_is_left_along_the_global_path_without_contact(ctl: Controller) -> None:
    """The robot starts inside a U open behind it, the goal beyond its bottom: the straight way leads
    into the bottom; the global path leads out of the opening and around, and the controller follows it
    without touching a wall (the robot's radius, 0.3 m)."""
    points = U_SHAPE.boundary_samples(10.0)
    start, goal = (1.0, 0.0, 0.0), (6.0, 0.0, 0.0)
    path = plan_path(U_SHAPE, start[:2], goal[:2], robot_radius=0.3)
    assert np.min(path[:, 0]) < 0.1  # the path does leave through the opening
    run = drive(ctl, start, goal, obstacles=points, path=path, seconds=60.0)
    assert run.results[-1].goal_reached
    assert np.min(U_SHAPE.signed_distance(run.xy)) > 0.3
    assert never_silently_stalled(run, ctl.params["stall_time"])


# -- outcomes, never silent ------------------------------------------------------------------------


def test_a_person_within_d_h_is_a_protective_stop_with_its_reason(ctl: Controller) -> None:
    r = ctl.step(0.0, pose=(0.0, 0.0, 0.0), v=0.5, goal=(5.0, 0.0, 0.0), people=np.array([[0.4, 0.0, 0.0, 0.0]]))
    assert r.stop and r.reason == "human_too_close" and r.outcome_name == "stopped"
    assert r.u[0] < 0.0 and r.command[1] == 0.0  # brakes, no turning


def test_non_finite_odometry_is_a_protective_stop_that_brakes(ctl: Controller) -> None:
    r = ctl.step(0.0, pose=(np.nan, 0.0, 0.0), v=0.5, goal=(5.0, 0.0, 0.0))
    assert r.stop and r.reason == "invalid_input"
    # no pose, but a speed to brake from: at the forward braking rate, no turning
    assert r.u[0] == ctl.params["a_bounds"][0] and r.command.tolist() == pytest.approx([0.4, 0.0])
    r = ctl.step(0.1, pose=(0.0, 0.0, 0.0), v=0.5, goal=(5.0, 0.0, 0.0), people=np.array([[1.0, np.inf, 0, 0]]))
    assert r.stop and r.reason == "invalid_input" and r.u[0] < 0.0


def test_without_a_path_or_a_goal_the_controller_says_so_and_brakes(ctl: Controller) -> None:
    r = ctl.step(0.0, pose=(0.0, 0.0, 0.0), v=0.6)
    assert r.outcome_name == "no_goal" and not r.stop
    assert r.u[0] < 0.0 and r.command[0] == pytest.approx(0.5)


def test_inputs_beyond_the_capacities_are_refused_naming_the_spec_key(ctl: Controller) -> None:
    with pytest.raises(ValueError, match=r"controller\.max_path_points"):
        ctl.step(0.0, pose=(0, 0, 0), v=0.0, path=np.zeros((ctl.max_path_points + 1, 2)))
    with pytest.raises(ValueError, match=r"shape \(n, 4\)"):
        ctl.step(0.0, pose=(0, 0, 0), v=0.0, goal=(1, 0, 0), people=np.zeros((3, 2)))


def test_controller_parameters_are_checked_by_their_rules(ctl: Controller) -> None:
    with pytest.raises(ValueError, match="goal_tolerance must be"):
        ctl.set_params(goal_tolerance=0.0)
    with pytest.raises(KeyError, match="unknown parameter"):
        ctl.set_params(lookahed=2.0)
    ctl.set_params(v_ref=0.5, speed_limit=0.5)
    assert ctl.params["v_ref"] == 0.5


def test_a_loop_after_the_goal_jumps_behind_is_replaced_by_a_recovery_plan(ctl: Controller) -> None:
    """The carrot objective, cruising at 0.8 m/s with the goal 10 m ahead, the goal jumps 10 m behind: with the
    paper's speed weight (250, and its free turn rate) the real-time iterations continue the forward plan into a loop;
    the recovery replaces it by a cold SQP plan, so no plan handed out is a loop."""
    def loops(recovery: int) -> tuple[int, int]:
        ctl.reset()
        ctl.set_params(w_goal=(0.5, 0.5, 0.0, 250.0), w_control=(0.0, 0.0), approach=0, progress=0,
                       recovery_iterations=recovery)
        x, out, recovered = np.array([0.0, 0.0, 0.0, 0.8]), 0, 0
        for k in range(30):
            goal = (x[0] + 10.0, 0.0, 0.0) if k < 20 else (x[0] - 10.0, x[1], np.pi)
            r = ctl.step(0.1 * k, pose=x[:3], v=x[3], goal=goal)
            xy = r.plan[:, :2]
            length = np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1))
            out += int(length >= 1.0 and np.linalg.norm(xy[-1] - xy[0]) < 0.5 * length)
            recovered += int(r.recovered)
            x = r.plan[1]
        return out, recovered

    without, _ = loops(0)
    assert without >= 3
    with_recovery, recovered = loops(10)
    assert recovered >= 1 and with_recovery == 0


@pytest.mark.parametrize(("distance", "bearing_deg"), [(0.66, 180.0), (1.0, 180.0), (2.0, 180.0), (3.0, 180.0),
                                                        (1.0, 135.0), (3.0, 135.0)])
def test_a_goal_behind_the_robot_within_the_approach_is_reached(ctl: Controller, distance: float,
                                                               bearing_deg: float) -> None:
    """At rest with the goal behind, within the approach (v_ref T = 4 m), nobody near: turning in place moves
    no node of the plan and v >= 0 forbids backing up, so the real-time iterations alone stand still for good
    (before the turn start, the robot stood stalled at every one of these goals). The controller starts a
    recovery from a turn towards the goal and gets there, turning once, not circling."""
    a = np.radians(bearing_deg)
    goal = (distance * np.cos(a), distance * np.sin(a), a)  # facing the way there: no turn at the goal
    run = drive(ctl, (0.0, 0.0, 0.0), goal, seconds=15.0)
    assert run.results[-1].goal_reached
    assert any(r.recovered for r in run.results)
    assert run.path_length() < distance + 1.5  # the way there: a turn, then straight on
    # reached at rest (the goal checker's standstill): a period more than reached on entering the tolerance
    assert len(run.results) * DT < 3.1 + 1.5 * distance


def test_a_robot_that_cannot_leave_its_standstill_says_it_is_stalled(ctl: Controller) -> None:
    """The carrot objective, 0.4 m straight behind, 0.1 m beyond goal_tolerance: turning around costs the OCP
    more than the 5 s horizon of standing 0.4 m off, and the recovery from a turn goes back to standing. The
    controller does not pretend: after stall_time it reports the robot stalled, and it never drives off."""
    ctl.set_params(progress=0)
    run = drive(ctl, (0.0, 0.0, 0.0), (-0.4, 0.0, 0.0), seconds=8.0)
    assert not run.results[-1].goal_reached
    assert run.results[-1].stalled and run.results[-1].outcome_name == "stalled"
    assert never_silently_stalled(run, stall_time=5.0)
    assert np.max(np.abs(run.xy)) < 0.05


def test_a_stalled_robot_stops_or_heads_for_its_goal_never_walks_off(ctl: Controller) -> None:
    """The paper's objective (no progress objective, no passing decisions): beside a person who crosses at the
    robot's own cruising speed, it turned and walked along with them (45 s and 40 m, stalled at full speed at
    right angles to its goal). Stalled, the command now brakes unless it heads for the carrot: towards it, or
    on a plan that is nearer it half a horizon on (a plan that starts off sideways to go round; braking those
    too held a robot among standing people for 23 s). Here the robot stops, then turns and gets there."""
    ctl.set_params(progress=0, passing=0)
    run = drive(ctl, (0.0, 0.0, 0.0), (10.0, 0.0, 0.0), people=walking((3.0, -3.0, 0.0, 0.8)), seconds=45.0)
    stalled = [k for k, r in enumerate(run.results) if r.stalled]
    assert stalled, "the paper's objective no longer stalls here: the test needs another scene"
    for k in stalled:
        r, x = run.results[k], run.states[k]
        carrot = np.asarray(r.ocp_goal[:2])
        towards = np.cos(np.arctan2(carrot[1] - x[1], carrot[0] - x[0]) - x[2])
        braking = abs(r.command[0]) <= max(abs(x[3]) - 0.05, 0.05)  # at least half a_bounds[0] per period
        mid = np.asarray(r.plan)[len(r.plan) // 2, :2]
        nearer = np.hypot(*(mid - carrot)) < np.hypot(*(x[:2] - carrot))
        assert r.command[0] * towards > 0 or braking or nearer, (k, x, r.command)
    first = run.states[stalled[0]]
    left = [np.hypot(10.0 - x[0], x[1]) for x in run.states[stalled[0]:]]
    assert max(left) <= left[0] + first[3] ** 2 / (2 * 1.0) + 0.1  # a_bounds[0] = -1: no farther than braking
    assert run.results[-1].goal_reached


def test_with_the_progress_objective_a_goal_just_behind_is_reached(ctl: Controller) -> None:
    """The same goal 0.4 m behind with the progress objective (the default): its per-node goals on the line
    behind give the turn a gradient, and the robot gets there."""
    run = drive(ctl, (0.0, 0.0, 0.0), (-0.4, 0.0, 0.0), seconds=8.0)
    assert run.results[-1].goal_reached


@pytest.mark.parametrize("heading_deg", [90.0, 180.0, -135.0])
def test_at_a_goal_pose_the_robot_turns_in_place_to_its_heading(ctl: Controller, heading_deg: float) -> None:
    """The goal 3 m ahead with another heading: within goal_tolerance the robot brakes and turns in place until
    its heading is within yaw_goal_tolerance (0.25 rad) of the goal's; only then is the goal reached. Before,
    the goal was reached facing the way the robot came (the goal's heading up to 170 degrees off)."""
    heading = np.radians(heading_deg)
    run = drive(ctl, (0.0, 0.0, 0.0), (3.0, 0.0, heading), seconds=20.0)
    last = run.results[-1]
    assert last.goal_reached
    assert abs(np.angle(np.exp(1j * (run.states[-1][2] - heading)))) <= 0.25 + 1e-9
    at_goal = [r for r in run.results if not r.goal_reached and np.hypot(*(r.plan[0, :2] - (3.0, 0.0))) <= 0.3]
    turning = [r for r in at_goal if r.command[1] != 0.0]
    assert turning and all(abs(r.command[0]) <= 0.05 for r in turning)  # it brakes first, then turns in place
    assert all(r.command[0] <= r.plan[0, 3] + 1e-12 for r in at_goal)  # never speeds up there
    assert np.hypot(*(run.states[-1][:2] - (3.0, 0.0))) <= 0.3 + 0.05
    ctl.reset()
    ctl.set_params(yaw_goal_tolerance=3.2)  # any heading: the goal is reached on arrival
    run = drive(ctl, (0.0, 0.0, 0.0), (3.0, 0.0, heading), seconds=20.0)
    assert run.results[-1].goal_reached
    assert abs(np.angle(np.exp(1j * (run.states[-1][2] - heading)))) > 0.5


def test_a_person_within_d_h_at_the_goal_holds_the_turn(ctl: Controller) -> None:
    """Someone standing 0.4 m from the robot at its goal: no turn, a protective stop with its reason (the paper's
    C2: no motion with a person within d_h), the goal not reached; once they leave, it turns to the heading."""
    heading = np.pi / 2
    x = np.array([0.0, 0.0, 0.0, 0.0])
    near = np.array([[0.0, -0.4, 0.0, 0.0]])
    for k in range(20):
        r = ctl.step(0.1 * k, pose=x[:3], v=x[3], goal=(0.1, 0.0, heading), people=near)
        assert r.command[1] == 0.0 and not r.goal_reached
        assert r.stop and r.reason == "human_too_close" and r.outcome_name == "stopped"
        x = step(RobotModel(), x, r.u, DT)
    r = ctl.step(2.0, pose=x[:3], v=x[3], goal=(0.1, 0.0, heading), people=np.zeros((0, 4)))
    assert r.command[1] > 0.0 and not r.goal_reached
