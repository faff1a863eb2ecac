"""Metrics on hand-made episodes with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from humanmpc.eval.episode import EpisodeLog
from humanmpc.eval.metrics import compute_metrics, mean_jerk, rising_edges
from humanmpc.sim.robot import RobotModel
from humanmpc.sim.world import Circle, World

DT = 0.1


def make_log(
    xy: np.ndarray,
    humans: np.ndarray,
    *,
    theta: np.ndarray | None = None,
    world: World | None = None,
    goal: tuple[float, float] = (10.0, 0.0),
    reached: bool = True,
    stops: np.ndarray | None = None,
    reasons: list[str | None] | None = None,
) -> EpisodeLog:
    n = xy.shape[0]
    th = np.zeros(n) if theta is None else theta
    states = np.column_stack([xy, th, np.zeros(n)])
    T = n - 1
    return EpisodeLog(
        scenario="hand", seed=0, planner="test", dt=DT, world=world or World(),
        robot=RobotModel(), goal=np.array([*goal, 0.0, 0.8]), goal_tolerance=0.3, time_limit=60.0,
        times=DT * np.arange(n), states=states, humans=humans, controls=np.zeros((T, 2)),
        obstacle_points=np.zeros((T, 2)),
        stops=np.zeros(T, dtype=bool) if stops is None else stops,
        reasons=[None] * T if reasons is None else reasons,
        solve_ms=np.linspace(1.0, 2.0, T), plans=[None] * T,
        reached_goal=reached, ended_by="goal" if reached else "time_limit",
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
