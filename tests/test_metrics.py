"""Metrics on hand-made episodes with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from humanmpc.eval.episode import EpisodeLog
from humanmpc.eval.metrics import (
    TTC_CAP,
    compute_metrics,
    freezing,
    mean_jerk,
    omega_flip_rate,
    people_disturbance,
    rising_edges,
    time_to_collision,
)
from humanmpc.sim.robot import RobotModel
from humanmpc.sim.world import Circle, World

DT = 0.1


def make_log(
    xy: np.ndarray,
    humans: np.ndarray,
    *,
    theta: np.ndarray | None = None,
    speed: np.ndarray | float = 0.0,
    present: np.ndarray | None = None,
    world: World | None = None,
    goal: tuple[float, float] = (10.0, 0.0),
    reached: bool = True,
    stops: np.ndarray | None = None,
    reasons: list[str | None] | None = None,
    velocities: np.ndarray | None = None,
    undisturbed: np.ndarray | None = None,
) -> EpisodeLog:
    n = xy.shape[0]
    th = np.zeros(n) if theta is None else theta
    states = np.column_stack([xy, th, np.broadcast_to(speed, (n,))])
    T = n - 1
    return EpisodeLog(
        scenario="hand", seed=0, planner="test", dt=DT, world=world or World(),
        robot=RobotModel(), goal=np.array([*goal, 0.0, 0.8]), goal_tolerance=0.3, time_limit=60.0,
        times=DT * np.arange(n), states=states, humans=humans, controls=np.zeros((T, 2)),
        obstacle_points=np.zeros((T, 2)),
        stops=np.zeros(T, dtype=bool) if stops is None else stops,
        reasons=[None] * T if reasons is None else reasons,
        solve_ms=np.linspace(1.0, 2.0, T), plans=[None] * T,
        reached_goal=reached, ended_by="goal" if reached else "time_limit", present_mask=present,
        human_velocities=velocities, undisturbed_velocities=undisturbed,
    )


def straight(n: int = 101, speed: float = 1.0) -> np.ndarray:
    return np.column_stack([speed * DT * np.arange(n), np.zeros(n)])


def test_straight_path_has_its_length_and_no_irregularity() -> None:
    xy = straight()  # 0 .. 10 m along x, heading at the goal
    m = compute_metrics(make_log(xy, np.zeros((101, 0, 2))))
    assert m.path_length == pytest.approx(10.0)
    assert m.path_irregularity == pytest.approx(0.0, abs=1e-4)
    assert m.time_to_goal == pytest.approx(10.0)
    assert m.success and m.collisions == 0 and not m.timeout
    assert np.isinf(m.min_human_distance) and m.time_within_dth == 0.0


def test_heading_off_the_goal_direction_counts_as_irregularity() -> None:
    xy = straight(11)  # 1 m long, but the robot faces 90 degrees off the goal direction
    m = compute_metrics(make_log(xy, np.zeros((11, 0, 2)), theta=np.full(11, np.pi / 2)))
    assert m.path_irregularity == pytest.approx(11 * np.pi / 2 / 1.0)


def test_min_distance_and_time_in_zones_for_a_human_beside_the_path() -> None:
    xy = straight()
    # A human standing 0.8 m beside x = 5.05 m (off the 0.1 m sample grid, no ties).
    humans = np.tile([[5.05, 0.8]], (101, 1, 1))
    m = compute_metrics(make_log(xy, humans))
    assert m.min_human_distance == pytest.approx(np.hypot(0.05, 0.8))
    # d < 1.0 m  <=>  |x - 5.05| < 0.6  <=>  x in {4.5, ..., 5.6}: 12 intervals
    assert m.time_within_dth == pytest.approx(1.2)
    # personal zone 0.45 <= d < 1.2  <=>  |x - 5.05| < sqrt(1.2^2 - 0.8^2) = 0.894: x in {4.2, ..., 5.9}
    assert m.time_personal == pytest.approx(1.8)
    assert m.time_intimate == 0.0 and m.collisions == 0


def test_passing_through_a_human_counts_one_collision_event_and_fails() -> None:
    xy = straight()
    humans = np.tile([[5.0, 0.1]], (101, 1, 1))
    m = compute_metrics(make_log(xy, humans))
    assert m.human_collisions == 1 and m.collisions == 1 and not m.success
    assert m.min_human_distance == pytest.approx(0.1)
    # centre distance < 0.45 (= 0.2 + 0.25) <=> |x - 5| < 0.4359: x in {4.6, ..., 5.4}
    assert m.collision_time == pytest.approx(0.9)
    assert m.time_intimate == pytest.approx(0.9)


def test_touching_an_obstacle_is_a_collision() -> None:
    world = World((Circle((5.0, 0.5), 0.35),))
    m = compute_metrics(make_log(straight(), np.zeros((101, 0, 2)), world=world))
    assert m.obstacle_collisions == 1 and m.human_collisions == 0 and not m.success


def test_jerk_of_a_cubic_position_profile_is_its_constant_third_derivative() -> None:
    t = DT * np.arange(30)
    xy = np.column_stack([0.5 * t**3, np.zeros_like(t)])  # x''' = 3
    assert mean_jerk(xy, DT) == pytest.approx(3.0)
    assert mean_jerk(straight(), DT) == pytest.approx(0.0, abs=1e-9)


def test_a_turn_rate_flip_is_a_change_of_omega_above_2_rad_per_s_between_steps() -> None:
    """Hand-counted: omega 0, 1.5, -1.5 (a 3 rad/s jump), -0.4 (1.1), 1.7 (2.1), 1.7 over 6 steps."""
    controls = np.column_stack([np.zeros(6), [0.0, 1.5, -1.5, -0.4, 1.7, 1.7]])
    assert omega_flip_rate(controls) == pytest.approx(2 / 6)
    assert omega_flip_rate(np.column_stack([np.zeros(4), [0.0, 2.0, 0.0, 2.0]])) == 0.0  # exactly 2: no flip
    assert omega_flip_rate(np.zeros((0, 2))) == 0.0


def test_protective_stops_are_counted_as_events_per_reason() -> None:
    stops = np.zeros(100, dtype=bool)
    stops[10:15] = True
    stops[40:42] = True
    stops[70:71] = True
    reasons: list[str | None] = [None] * 100
    for i in range(10, 15):
        reasons[i] = "human_too_close"
    reasons[40] = reasons[41] = "deadline"
    reasons[70] = "human_too_close"
    m = compute_metrics(make_log(straight(), np.zeros((101, 0, 2)), stops=stops, reasons=reasons))
    assert m.protective_stops == 3
    assert m.stops_by_reason == {"human_too_close": 2, "deadline": 1}
    assert m.stop_time == pytest.approx(0.8)
    assert m.as_row()["stops[deadline]"] == 1


def test_timeout_and_planner_time_statistics() -> None:
    m = compute_metrics(make_log(straight(), np.zeros((101, 0, 2)), reached=False))
    assert m.timeout and not m.success and np.isnan(m.time_to_goal)
    assert m.planner_ms_mean == pytest.approx(1.5)
    assert m.planner_ms_max == pytest.approx(2.0)
    assert 1.98 < m.planner_ms_p99 < 2.0


def test_rising_edges_include_a_series_that_starts_on() -> None:
    np.testing.assert_array_equal(rising_edges(np.array([1, 1, 0, 1, 0, 0, 1], dtype=bool)), [0, 3, 6])


# Contact attribution. Contact: centre distance < 0.2 + 0.25 = 0.45 m. The robot's fault: it moves
# faster than 0.05 m/s with the person strictly within +-90 degrees of its heading.


def test_driving_into_a_standing_person_is_the_robots_fault_until_it_is_past_them() -> None:
    # 1 m/s along x past a person standing at (5.05, 0.1): in contact while |x - 5.05| < sqrt(0.45^2 - 0.1^2)
    # = 0.4387, x in {4.7, ..., 5.4} (8 samples); the person is ahead for x < 5.05 (4 samples), behind after.
    m = compute_metrics(make_log(straight(), np.tile([[5.05, 0.1]], (101, 1, 1)), speed=1.0))
    assert (m.robot_fault_contacts, m.person_fault_contacts) == (1, 0)
    assert (m.robot_fault_steps, m.person_fault_steps) == (4, 4)


def test_a_person_walking_into_a_standing_robot_is_the_persons_fault() -> None:
    # the robot stands at the origin facing the person, who walks at it at 1 m/s from x = 2 and stops at 0.3
    xh = np.maximum(2.0 - 0.1 * np.arange(31), 0.3)
    humans = np.column_stack([xh, np.zeros(31)])[:, None, :]
    m = compute_metrics(make_log(np.zeros((31, 2)), humans, speed=0.0))
    # in contact from x = 0.4 (sample 16) to the end (sample 30): 15 samples
    assert (m.robot_fault_contacts, m.person_fault_contacts) == (0, 1)
    assert (m.robot_fault_steps, m.person_fault_steps) == (0, 15)


def test_a_person_catching_up_from_behind_a_moving_robot_is_the_persons_fault() -> None:
    # robot at 0.2 m/s (x = 0.02 i), person behind at 1 m/s (x = -1 + 0.1 i): gap 1 - 0.08 i, in contact
    # for 0.55 < 0.08 i, i = 7..12 (the log ends before they would pass through)
    i = np.arange(13)
    xy = np.column_stack([0.02 * i, np.zeros(13)])
    humans = np.column_stack([-1.0 + 0.1 * i, np.zeros(13)])[:, None, :]
    m = compute_metrics(make_log(xy, humans, speed=0.2))
    assert (m.robot_fault_contacts, m.person_fault_contacts) == (0, 1)
    assert (m.robot_fault_steps, m.person_fault_steps) == (0, 6)


@pytest.mark.parametrize(("speed", "robot_fault"), [(0.04, False), (0.06, True)])
def test_the_robot_is_at_fault_only_above_the_moving_speed(speed: float, robot_fault: bool) -> None:
    # a person 0.3 m ahead of a robot that creeps at `speed` (positions held: only the speed matters here)
    m = compute_metrics(make_log(np.zeros((5, 2)), np.tile([[0.3, 0.0]], (5, 1, 1)), speed=speed))
    assert (m.robot_fault_contacts, m.person_fault_contacts) == ((1, 0) if robot_fault else (0, 1))
    assert (m.robot_fault_steps, m.person_fault_steps) == ((5, 0) if robot_fault else (0, 5))


def test_a_person_exactly_beside_the_robot_is_not_ahead_of_it() -> None:
    # 90 degrees off the heading is outside the strict +-90 degrees
    m = compute_metrics(make_log(np.zeros((3, 2)), np.tile([[0.0, 0.3]], (3, 1, 1)), speed=1.0))
    assert (m.robot_fault_contacts, m.person_fault_contacts, m.person_fault_steps) == (0, 1, 3)


def test_touching_two_people_at_once_is_two_events_and_one_collision() -> None:
    humans = np.tile([[[5.05, 0.1], [5.05, -0.1]]], (101, 1, 1))
    m = compute_metrics(make_log(straight(), humans, speed=1.0))
    assert m.human_collisions == 1
    assert (m.robot_fault_contacts, m.person_fault_contacts) == (2, 0)
    # a sample counts once: the robot's fault if it is towards anyone it touches
    assert (m.robot_fault_steps, m.person_fault_steps) == (4, 4)


def test_absent_people_count_in_no_metric() -> None:
    # a person stands on the path at x = 5.05 but is only there from sample 60 on (robot at x = 6.0)
    humans = np.tile([[5.05, 0.1]], (101, 1, 1))
    present = np.zeros((101, 1), dtype=bool)
    present[60:] = True
    humans[~present] = np.nan
    m = compute_metrics(make_log(straight(), humans, speed=1.0, present=present))
    assert m.collisions == 0 and m.robot_fault_contacts == 0 and m.person_fault_steps == 0 and m.success
    assert m.min_human_distance == pytest.approx(np.hypot(0.95, 0.1))
    # d < 1.0 m: x - 5.05 < sqrt(1 - 0.01) = 0.995, x in {6.0} only
    assert m.time_within_dth == pytest.approx(0.1)


def test_a_log_with_absent_people_needs_their_mask() -> None:
    humans = np.full((101, 1, 2), np.nan)
    with pytest.raises(ValueError, match="present_mask"):
        make_log(straight(), humans)
    with pytest.raises(ValueError, match="present has a non-finite position"):
        make_log(straight(), humans, present=np.ones((101, 1), dtype=bool))


# Freezing: progress is coming 0.1 m closer to the goal than at the last progress; a stretch without it
# longer than 5 s is a freezing event.


def _stop_and_go(stop_from: int, go_at: int, n: int = 201) -> np.ndarray:
    """1.3 m/s along x (0.13 m per sample: every sample is progress), standing from sample stop_from on
    and moving again at sample go_at."""
    moved = np.concatenate([np.arange(stop_from + 1), np.full(go_at - stop_from - 1, stop_from),
                            stop_from + 1 + np.arange(n - go_at)])
    return np.column_stack([0.13 * moved, np.zeros(n)])


def test_standing_for_more_than_five_seconds_is_one_freezing_event() -> None:
    xy = _stop_and_go(30, 96)  # last progress at 3.0 s, the next at 9.6 s
    m = compute_metrics(make_log(xy, np.zeros((201, 0, 2)), goal=(40.0, 0.0), reached=False))
    assert m.freezing_events == 1 and m.freezing_time == pytest.approx(6.6)


@pytest.mark.parametrize(("go_at", "events", "time"), [(79, 0, 0.0), (81, 1, 5.1)])
def test_freezing_needs_more_than_five_seconds(go_at: int, events: int, time: float) -> None:
    xy = _stop_and_go(30, go_at)  # without progress for 4.9 s, then 5.1 s
    m = compute_metrics(make_log(xy, np.zeros((201, 0, 2)), goal=(40.0, 0.0), reached=False))
    assert (m.freezing_events, m.freezing_time) == (events, pytest.approx(time))


def test_creeping_towards_the_goal_is_not_progress() -> None:
    # 0.015 m/s: 0.1 m closer only at samples 67 (0.1005 m) and 134 (0.201 m); the stretches 0-67, 67-134 and
    # 134-200 (to the end) last 6.7, 6.7 and 6.6 s
    xy = np.column_stack([0.0015 * np.arange(201), np.zeros(201)])
    assert freezing(DT * np.arange(201), xy, np.array([10.0, 0.0])) == (3, pytest.approx(20.0))


def test_moving_away_from_the_goal_is_not_progress() -> None:
    # 3 s towards the goal at 1 m/s (to x = 3.0), 6 s away from it (to x = -3.0), then back at 1.3 m/s: no
    # progress from 3.0 s until x >= 3.1, 47 samples after the turn (x = 3.11): at 9.0 + 4.7 = 13.7 s
    x = np.concatenate([0.1 * np.arange(31), 3.0 - 0.1 * np.arange(1, 61), -3.0 + 0.13 * np.arange(1, 71)])
    xy = np.column_stack([x, np.zeros_like(x)])
    events, time = freezing(DT * np.arange(x.size), xy, np.array([20.0, 0.0]))
    assert events == 1 and time == pytest.approx(10.7)


def test_a_run_that_never_stops_does_not_freeze() -> None:
    m = compute_metrics(make_log(straight(), np.zeros((101, 0, 2)), speed=1.0))
    assert m.freezing_events == 0 and m.freezing_time == 0.0


# SPL, time to collision, Hall's social space and the people's disturbance (issue 21), by hand.


def test_spl_is_the_straight_distance_to_the_goal_circle_over_the_path_taken() -> None:
    # goal 10.3 m ahead, tolerance 0.3 m: the shortest path is 10.0 m, the straight run takes exactly it
    m = compute_metrics(make_log(straight(), np.zeros((101, 0, 2)), goal=(10.3, 0.0)))
    assert m.spl == pytest.approx(1.0)
    # a detour (0, 0) -> (3, 4) -> (6, 0), 5 + 5 m, to a goal at (6.3, 0): 6.0 / 10.0
    leg = np.linspace(0.0, 1.0, 51)[:, None]
    xy = np.vstack([leg * [3.0, 4.0], [3.0, 4.0] + leg[1:] * [3.0, -4.0]])
    m = compute_metrics(make_log(xy, np.zeros((101, 0, 2)), goal=(6.3, 0.0)))
    assert m.path_length == pytest.approx(10.0) and m.spl == pytest.approx(0.6)
    # no success, no SPL: the same detour that touched someone, or that timed out
    touched = compute_metrics(make_log(xy, np.tile([[3.0, 4.1]], (101, 1, 1)), goal=(6.3, 0.0)))
    assert not touched.success and touched.spl == 0.0
    assert compute_metrics(make_log(xy, np.zeros((101, 0, 2)), goal=(6.3, 0.0), reached=False)).spl == 0.0


def test_time_to_collision_of_discs_at_constant_velocities() -> None:
    r = 0.45
    # head-on: 5 m apart, closing at 1 m/s, touching at 5 - 0.45 m
    assert time_to_collision(np.array([5.0, 0.0]), np.array([-1.0, 0.0]), r) == pytest.approx(4.55)
    # passing 0.3 m aside: (5 - t)^2 + 0.3^2 = 0.45^2  =>  t = 5 - sqrt(0.1125)
    assert time_to_collision(np.array([5.0, 0.3]), np.array([-1.0, 0.0]), r) == pytest.approx(5 - np.sqrt(0.1125))
    # passing 1 m aside, moving apart, standing still: never; touching: 0
    assert np.isinf(time_to_collision(np.array([5.0, 1.0]), np.array([-1.0, 0.0]), r))
    assert np.isinf(time_to_collision(np.array([5.0, 0.0]), np.array([1.0, 0.0]), r))
    assert np.isinf(time_to_collision(np.array([5.0, 0.0]), np.array([0.0, 0.0]), r))
    assert time_to_collision(np.array([0.3, 0.0]), np.array([1.0, 0.0]), r) == 0.0


def test_min_time_to_collision_takes_the_robots_velocity_and_the_persons_tracked_one() -> None:
    # the robot drives at 0.5 m/s along x from the origin; a person walks towards it at 1 m/s from x = 6
    # (0.1 m per sample). Sample 0: the person's velocity is unknown (0): gap 6, closing 0.5 -> 11.1 s;
    # from sample 1 on closing at 1.5 m/s: (6 - 0.15 t - 0.45) / 1.5 = 3.7 - 0.1 t s at sample t
    n = 11
    xy = np.column_stack([0.05 * np.arange(n), np.zeros(n)])
    humans = np.column_stack([6.0 - 0.1 * np.arange(n), np.zeros(n)])[:, None, :]
    m = compute_metrics(make_log(xy, humans, speed=0.5))
    assert m.min_time_to_collision == pytest.approx(3.7 - 0.1 * (n - 1))
    # the same person 2 m aside never comes within 0.45 m: the cap
    aside = humans + np.array([0.0, 2.0])
    assert compute_metrics(make_log(xy, aside, speed=0.5)).min_time_to_collision == TTC_CAP


def test_time_in_hall_s_social_space_counts_samples_between_1_2_and_3_6_m() -> None:
    # a person standing 2 m beside x = 5.05: 1.2 <= d always, d < 3.6 <=> |x - 5.05| < sqrt(3.6^2 - 2^2)
    # = 2.993: x in {2.1, ..., 8.0}, 60 samples of 0.1 s
    m = compute_metrics(make_log(straight(), np.tile([[5.05, 2.0]], (101, 1, 1))))
    assert m.time_social == pytest.approx(6.0)
    assert m.time_personal == 0.0 and m.time_intimate == 0.0


def test_the_people_s_disturbance_sums_the_speed_and_heading_changes_the_robot_caused() -> None:
    # one person walking at 1 m/s along x; v0: what they would have done without the robot
    n = 6
    v0 = np.tile([[1.0, 0.0]], (n, 1, 1))
    v = v0.copy()
    v[2, 0] = [0.6, 0.0]  # slowed by 0.4 m/s
    v[3, 0] = [np.cos(np.pi / 6), np.sin(np.pi / 6)]  # turned by 30 degrees at the same speed
    v0[4, 0] = v[4, 0] = [0.0, 0.01]  # standing: the direction is not compared
    v[4, 0] = [0.03, 0.0]  # but the speed is: 0.02 m/s
    speed, heading = people_disturbance(v, v0)
    assert speed == pytest.approx(0.4 + 0.02)
    assert heading == pytest.approx(np.pi / 6)
    # sample 0 (the start) is no step and counts nothing
    v[0, 0] = [0.0, 2.0]
    assert people_disturbance(v, v0) == (pytest.approx(speed), pytest.approx(heading))
    humans = np.cumsum(v * DT, axis=0)
    m = compute_metrics(make_log(straight(n), humans, velocities=v, undisturbed=v0))
    assert (m.people_speed_change, m.people_heading_change) == (pytest.approx(speed), pytest.approx(heading))
    # people who do not react to the robot (recorded ones) have no disturbance
    m = compute_metrics(make_log(straight(n), humans))
    assert np.isnan(m.people_speed_change) and np.isnan(m.people_heading_change)
