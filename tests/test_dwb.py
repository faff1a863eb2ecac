"""The DWB baseline: competent in open and cluttered scenes, consistent outputs."""

from __future__ import annotations

import numpy as np

from humanmpc.eval.episode import run_episode
from humanmpc.planners.dwb import DWBConfig, DWBPlanner, sample_window
from humanmpc.planners.interface import Observation, Planner
from humanmpc.sim.crowd import CrowdSpec
from humanmpc.sim.robot import RobotModel
from humanmpc.sim.scenarios import Scenario
from humanmpc.sim.world import Circle, Polygon, World

NOBODY = CrowdSpec.build(np.zeros((0, 2)), [], 1.0)


def _scene(world: World, start: tuple[float, float], goal: tuple[float, float], crowd: CrowdSpec = NOBODY) -> Scenario:
    th = float(np.arctan2(goal[1] - start[1], goal[0] - start[0]))
    return Scenario("test", 0, world, crowd, np.array([*start, th, 0.0]), np.array([*goal, th, 0.8]), 40.0)


def _obs(x: list[float], humans: np.ndarray, world: World | None = None) -> Observation:
    return Observation(
        time=0.0, x=np.array(x), goal=np.array([5.0, 0.0, 0.0, 0.8]), humans_now=humans,
        humans_velocity=np.zeros_like(humans), obstacle=np.array([1e3, 0.0]),
        world=world or World(), dt=0.1,
    )


def test_dwb_reaches_a_goal_in_an_open_scene_at_cruising_speed() -> None:
    planner = DWBPlanner()
    assert isinstance(planner, Planner)
    log = run_episode(_scene(World(), (-5.0, -1.0), (5.0, 2.0)), planner)
    assert log.ended_by == "goal"
    straight = np.hypot(10.0, 3.0)
    assert log.times[-1] < straight / 0.8 + 3.0  # accelerating and a little turning, no dawdling
    assert np.max(log.states[:, 3]) <= 0.8 + 1e-9  # never above v_ref
    assert not np.any(log.stops)


def test_dwb_goes_around_a_static_obstacle_without_touching_it() -> None:
    world = World((Circle((0.0, 0.0), 1.0), Polygon.rectangle((3.0, 1.5), 0.6, 2.0)), (-8.0, 8.0, -8.0, 8.0))
    log = run_episode(_scene(world, (-5.0, 0.0), (5.0, 0.0)), DWBPlanner())
    assert log.ended_by == "goal"
    clearance = world.signed_distance(log.states[:, :2]) - RobotModel().radius
    assert clearance.min() > 0.0


def test_dwb_control_is_the_acceleration_to_the_commanded_speed() -> None:
    planner = DWBPlanner()
    res = planner.plan(_obs([0.0, 0.0, 0.0, 0.35], np.zeros((0, 2))))
    assert res.command is not None and res.path is not None
    a, omega = res.u
    assert a == np.float64((res.command[0] - 0.35) / 0.1)
    assert omega == res.command[1]
    assert -1.0 <= a <= 1.0 and res.command[0] <= 0.8
    assert res.path.shape == (18, 4)  # 1.7 s rollout at 0.1 s
    assert res.timings["local_ms"] > 0.0


def test_dynamic_window_respects_the_acceleration_limits() -> None:
    samples = sample_window(_obs([0.0, 0.0, 0.0, 0.5], np.zeros((0, 2))), DWBConfig())
    assert samples[:, 0].min() == np.float64(0.4) and samples[:, 0].max() == np.float64(0.6)
    assert samples[:, 1].min() == -1.5 and samples[:, 1].max() == 1.5


def test_dwb_stops_protectively_when_every_rollout_hits_a_human() -> None:
    ring = np.array([[0.46 * np.cos(a), 0.46 * np.sin(a)] for a in np.linspace(0, 2 * np.pi, 12, endpoint=False)])
    res = DWBPlanner().plan(_obs([0.0, 0.0, 0.0, 0.5], ring))
    assert res.stop and res.reason == "no_valid_trajectory"
    assert res.u[0] < 0 and res.u[1] == 0.0


def test_dwb_keeps_clear_of_a_person_standing_on_its_path() -> None:
    crowd = CrowdSpec.build([[0.0, 0.0]], [[[0.0, 0.0]]], 0.0)
    log = run_episode(_scene(World(), (-5.0, 0.0), (5.0, 0.0), crowd), DWBPlanner())
    assert log.ended_by == "goal"
    gap = np.linalg.norm(log.states[:, :2] - log.humans[:, 0], axis=1)
    assert gap.min() > RobotModel().radius + RobotModel().human_radius
