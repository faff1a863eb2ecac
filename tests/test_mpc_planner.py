"""The MPC as a planner of the evaluation: the goal it hands the OCP, its speed limit, its goal
approach, its runtime parameters, and the paper configuration kept beside it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.crowd import CrowdSpec
from humanmpc.episode import run_episode
from humanmpc.global_path import GlobalPlanner
from humanmpc.metrics import compute_metrics
from humanmpc.mpc_planner import EVALUATION_PARAMS, MPCPlanner, MPCPlannerConfig, with_params
from humanmpc.planner import Observation
from humanmpc.scenarios import Scenario
from humanmpc.world import Polygon, World

NOBODY = CrowdSpec.build(np.zeros((0, 2)), [], 1.0)
# A wall across the straight line from (-4, 0) to (4, 0), open above y = 2.
WALL = World((Polygon.rectangle((0.0, -1.0), 0.4, 6.0),), (-6.0, 6.0, -6.0, 6.0))


def planner(paper_dir: Path, config: MPCPlannerConfig | None = None) -> MPCPlanner:
    # A solver of its own: the planner writes runtime parameters into it.
    return MPCPlanner(humanmpc.load(paper_dir), config)


def observation(x: list[float], goal: list[float], world: World = WALL, time: float = 0.0) -> Observation:
    return Observation(
        time=time, x=np.array(x), goal=np.array(goal), humans_now=np.zeros((0, 2)),
        humans_pred=np.zeros((51, 0, 2)), obstacle=world.obstacle_parameter(x[:2]), world=world, dt=0.1,
    )


def test_the_ocp_goal_is_a_carrot_on_the_global_path_around_the_wall(paper_dir: Path) -> None:
    mpc = planner(paper_dir)
    obs = observation([-4.0, 0.0, 0.0, 0.0], [4.0, 0.0, 0.0, 0.8])
    goal = mpc.ocp_goal(obs)
    lookahead = 0.8 * mpc.solver.dims.T  # v_ref * T
    assert np.linalg.norm(goal[:2] - obs.x[:2]) <= lookahead + 1e-9
    assert goal[1] > 0.5  # up towards the opening, not through the wall
    assert WALL.signed_distance(goal[:2]) > 0.2
    paper = planner(paper_dir, MPCPlannerConfig.paper())
    np.testing.assert_array_equal(paper.ocp_goal(obs), [4.0, 0.0, 0.0, 0.8])


def test_the_goal_handed_over_near_the_end_is_the_final_goal_with_the_tapered_speed(paper_dir: Path) -> None:
    goal = planner(paper_dir).ocp_goal(observation([3.0, 3.0, 0.0, 0.5], [4.0, 3.0, 0.3, 0.8], World()))
    np.testing.assert_allclose(goal, [4.0, 3.0, 0.3, 0.5])  # v_ref = 0.5 m/s per metre left


def test_the_speed_bound_is_the_dwb_speed_cap_and_the_paper_configuration_keeps_the_spec_bound(
    paper_dir: Path,
) -> None:
    obs = observation([-4.0, 0.0, 0.0, 0.0], [4.0, 0.0, 0.0, 0.6], World())
    mpc = planner(paper_dir)
    mpc.plan(obs)
    assert mpc.solver.params["v_bounds"] == (0.0, 0.6)
    paper = planner(paper_dir, MPCPlannerConfig.paper())
    paper.plan(obs)
    assert paper.solver.params["v_bounds"] == (0.0, 1.0)


def test_the_evaluation_configuration_sets_its_runtime_parameters_and_the_paper_one_none(paper_dir: Path) -> None:
    mpc = planner(paper_dir)
    for key, value in EVALUATION_PARAMS.items():
        assert mpc.solver.params[key] == value
    paper = planner(paper_dir, MPCPlannerConfig.paper())
    assert paper.solver.params == humanmpc.load(paper_dir).params  # the spec's values
    assert with_params(MPCPlannerConfig(), q=7.0).params["q"] == 7.0


CORRIDOR = World((Polygon.rectangle((0.0, 1.6), 20.0, 0.2), Polygon.rectangle((0.0, -1.6), 20.0, 0.2)),
                 (-10.5, 10.5, -2.5, 2.5))


def test_the_approach_brings_the_robot_to_a_goal_ahead_and_aside_without_a_loop(paper_dir: Path) -> None:
    """Cruising 2 m before a goal 0.8 m aside, between walls: tracking v_ref over the whole horizon makes
    the plan spend its length in a loop to the goal; the approach drops that weight near the goal."""
    scene = Scenario("t", 0, CORRIDOR, NOBODY, np.array([6.5, 0.8, 0.0, 0.8]), np.array([8.5, 0.0, 0.0, 0.8]), 20.0)
    direct = np.hypot(2.0, 0.8)
    approach = compute_metrics(run_episode(scene, planner(paper_dir)))
    assert approach.reached_goal and approach.path_length < direct and approach.time_to_goal < 3.0
    without = compute_metrics(run_episode(scene, planner(paper_dir, replace(MPCPlannerConfig(), approach=False))))
    assert without.path_length > 1.25 * direct and without.time_to_goal > 4.0


def test_the_mpc_goes_around_the_wall_to_the_goal_without_touching_it(paper_dir: Path) -> None:
    scene = Scenario("wall", 0, WALL, NOBODY, np.array([-4.0, 0.0, 0.0, 0.0]), np.array([4.0, 0.0, 0.0, 0.8]), 40.0)
    log = run_episode(scene, planner(paper_dir))
    assert log.ended_by == "goal"
    assert compute_metrics(log).obstacle_collisions == 0


def test_the_global_planner_replans_when_stale_or_when_the_goal_moves() -> None:
    gp = GlobalPlanner(replan_period=1.0)
    args = (World(), [0.0, 0.0], [3.0, 0.0], 0.2, None, 0.25)
    assert gp.update(0.0, *args) > 0.0
    first = gp.path
    assert gp.update(0.5, *args) == 0.0 and np.array_equal(gp.path, first)
    assert gp.update(0.6, World(), [0.0, 0.0], [3.0, 1.0], 0.2, None, 0.25) > 0.0
    assert gp.update(1.6, World(), [0.0, 0.0], [3.0, 1.0], 0.2, None, 0.25) > 0.0
    with pytest.raises(ValueError, match="replan_period"):
        GlobalPlanner(replan_period=0.0)
