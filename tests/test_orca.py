"""The ORCA crowd (the real RVO2 library through pyrvo), and what the robot changes in either crowd model."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from humanmpc.eval.episode import EpisodeConfig, run_episode
from humanmpc.eval.metrics import compute_metrics
from humanmpc.sim.crowd import Crowd, CrowdSpec, ReactiveCrowd
from humanmpc.sim.orca import OrcaCrowd, OrcaParams, obstacle_polygons
from humanmpc.sim.scenarios import CROWDNAV_SCENARIOS, SIMULATED_SCENARIOS, make_scenario
from humanmpc.sim.world import Circle, Polygon, World

from .conftest import Recorder, needs_data

RADIUS = OrcaParams().radius


def _run(crowd: OrcaCrowd | Crowd, steps: int, robot: np.ndarray | None = None) -> np.ndarray:
    track = [crowd.positions]
    for _ in range(steps):
        crowd.step(robot_position=robot, robot_velocity=None if robot is None else np.zeros(2))
        track.append(crowd.positions)
    return np.array(track)


def test_a_lone_person_walks_to_their_goal_at_their_speed_and_stays_there() -> None:
    crowd = OrcaCrowd(CrowdSpec.build([[0.0, 0.0]], [[[6.0, 3.0]]], 1.2))
    track = _run(crowd, 120)
    speeds = np.linalg.norm(np.diff(track[:, 0], axis=0), axis=1) / 0.1
    assert speeds.max() <= 1.2 + 1e-4 and speeds[5:30].min() > 1.19  # their desired speed, never faster
    assert np.linalg.norm(track[-1, 0] - [6.0, 3.0]) < 0.05  # slows onto the goal (1 s time constant)
    assert np.linalg.norm(track[-1, 0] - track[-10, 0]) < 1e-3


@pytest.mark.parametrize("angle", [0.0, np.pi / 2, 3 * np.pi / 4])
def test_two_people_facing_each_other_keep_their_radii_apart(angle: float) -> None:
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    pos = np.array([[-5.0, 0.05], [5.0, -0.05]]) @ rot.T
    track = _run(OrcaCrowd(CrowdSpec.build(pos, [g[None] for g in -pos], 1.0)), 150)
    gap = np.linalg.norm(track[:, 0] - track[:, 1], axis=1)
    assert gap.min() > 2 * RADIUS - 0.01  # ORCA's guarantee (float32 arithmetic)
    assert np.all(np.linalg.norm(track[-1] - -pos, axis=1) < 0.1)


def test_people_walk_around_a_standing_robot_on_their_way() -> None:
    spec = CrowdSpec.build([[-4.0, 0.02], [-4.0, 0.9]], [[[4.0, 0.02]], [[4.0, 0.9]]], 1.0)
    track = _run(OrcaCrowd(spec), 120, robot=np.array([0.0, 0.0]))
    assert np.linalg.norm(track[:, :] - [0.0, 0.0], axis=-1).min() > RADIUS + OrcaParams().robot_radius - 0.01
    assert np.all(track[-1, :, 0] > 3.5)  # and still get where they go


def test_people_never_enter_an_obstacle_polygons_or_circles() -> None:
    world = World((Polygon.rectangle((0.0, 0.0), 1.0, 3.0), Circle((0.0, 3.5), 0.6)))
    pos = np.array([[-4.0, 0.3], [-4.0, 3.3], [4.0, -0.5]])
    track = _run(OrcaCrowd(CrowdSpec.build(pos, [[[4.0, 0.3]], [[4.0, 3.6]], [[-4.0, -0.4]]], 1.0), world), 200)
    assert world.signed_distance(track.reshape(-1, 2)).min() > RADIUS - 0.01
    # ORCA is local: the two whose straight way the box blocks stay behind it; the one beside the disc arrives
    assert np.linalg.norm(track[-1, 1] - [4.0, 3.6]) < 0.2


def test_obstacles_reach_rvo2_counter_clockwise_and_circles_inside_their_polygon() -> None:
    clockwise = Polygon(((0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)))
    circle, square = obstacle_polygons(World((clockwise, Circle((5.0, 5.0), 1.0))), circle_sides=8)
    area = 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(square, square[1:] + square[:1], strict=True))
    assert area > 0
    # the octagon's edges are tangent to the circle: their midpoints at the radius
    mids = [np.hypot((x0 + x1) / 2 - 5.0, (y0 + y1) / 2 - 5.0) for (x0, y0), (x1, y1) in
            zip(circle, circle[1:] + circle[:1], strict=True)]
    np.testing.assert_allclose(mids, 1.0)


@pytest.mark.parametrize("name", [*SIMULATED_SCENARIOS, "crowdnav_circle_20", "crowdnav_square_20"])
def test_orca_runs_every_simulated_scenario_without_people_entering_obstacles(name: str) -> None:
    scenario = make_scenario(name, 3)
    crowd = scenario.start_crowd(model="orca")
    assert isinstance(crowd, OrcaCrowd) and isinstance(crowd, ReactiveCrowd)
    track = _run(crowd, 100)
    assert np.all(np.isfinite(track))
    if not scenario.world.is_empty:
        assert scenario.world.signed_distance(track.reshape(-1, 2)).min() > 0.25


def test_the_social_force_crowd_s_undisturbed_velocities_are_a_step_of_the_same_crowd_without_the_robot() -> None:
    crowd = make_scenario("crowdnav_circle_10", 2).start_crowd()
    robot = np.array([0.0, -1.0])
    for _ in range(30):
        twin = copy.deepcopy(crowd)
        crowd.step(robot_position=robot, robot_velocity=np.array([0.0, 0.5]))
        twin.step()  # no robot
        assert isinstance(crowd, Crowd)
        np.testing.assert_array_equal(crowd.undisturbed_velocities, twin.velocities)
        robot = robot + np.array([0.0, 0.05])
    assert not np.array_equal(crowd.velocities, crowd.undisturbed_velocities)  # the robot changed something


@pytest.mark.parametrize("model", ["social_force", "orca"])
def test_the_robot_far_away_disturbs_nobody_and_in_the_way_it_does(model: str) -> None:
    """The robot (the Recorder planner, straight on at 0.5 m/s) crosses a CrowdNav circle; the same scene
    with the robot started 1 km away (out of everyone's sight) has no disturbance at all."""
    scenario = make_scenario("crowdnav_circle_10", 4)
    config = EpisodeConfig(crowd_model=model)
    crossing = compute_metrics(run_episode(scenario, Recorder(), config))
    assert crossing.people_speed_change > 0.1 and crossing.people_heading_change > 0.1
    far = type(scenario)(scenario.name, scenario.seed, scenario.world, scenario.crowd,
                         scenario.robot_start + np.array([1000.0, 0.0, 0.0, 0.0]), scenario.goal, 5.0)
    away = compute_metrics(run_episode(far, Recorder(), config))
    assert (away.people_speed_change, away.people_heading_change) == (0.0, 0.0)


@needs_data
def test_recorded_people_ignore_the_crowd_model() -> None:
    scenario = make_scenario("biwi_hotel", 0)
    assert scenario.recorded and not isinstance(scenario.start_crowd(model="orca"), ReactiveCrowd)


def test_an_unknown_crowd_model_names_the_valid_ones() -> None:
    with pytest.raises(ValueError, match="crowd models: social_force, orca"):
        make_scenario(CROWDNAV_SCENARIOS[0], 0).start_crowd(model="boids")
    with pytest.raises(ValueError, match="crowd models: social_force, orca"):
        EpisodeConfig(crowd_model="boids")
