"""The MPC as a planner of the evaluation: the goal it hands the OCP, its speed limit, its goal
approach, its restart out of loops, its runtime parameters, and the paper configuration kept beside it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.eval.episode import run_episode
from humanmpc.eval.metrics import compute_metrics
from humanmpc.planners.global_path import GlobalPlanner
from humanmpc.planners.interface import Observation
from humanmpc.planners.mpc import EVALUATION_PARAMS, MPCPlanner, MPCPlannerConfig, is_loop, with_params
from humanmpc.sim.crowd import CrowdSpec
from humanmpc.sim.scenarios import Scenario
from humanmpc.sim.world import Polygon, World

PAPER_SPEED_WEIGHT = with_params(MPCPlannerConfig(), w_goal=(0.5, 0.5, 0.0, 250.0))  # the paper's w_goal
NOBODY = CrowdSpec.build(np.zeros((0, 2)), [], 1.0)
# A wall across the straight line from (-4, 0) to (4, 0), open above y = 2.
WALL = World((Polygon.rectangle((0.0, -1.0), 0.4, 6.0),), (-6.0, 6.0, -6.0, 6.0))


def planner(paper_dir: Path, config: MPCPlannerConfig | None = None) -> MPCPlanner:
    # A solver of its own: the planner writes runtime parameters into it.
    return MPCPlanner(humanmpc.load(paper_dir), config)


def observation(x: list[float] | np.ndarray, goal: list[float], world: World = WALL, time: float = 0.0,
                humans: np.ndarray | None = None) -> Observation:
    now = np.zeros((0, 2)) if humans is None else humans
    return Observation(
        time=time, x=np.array(x), goal=np.array(goal), humans_now=now,
        humans_pred=np.repeat(now[None], 51, axis=0), obstacle=world.obstacle_parameter(np.asarray(x[:2])),
        world=world, dt=0.1,
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


def test_the_carrot_goes_through_a_person_on_the_way_and_only_the_dwb_style_path_goes_around(
    paper_dir: Path,
) -> None:
    """The OCP handles the people with their predictions; a global path around where they stand now
    would send the carrot across their way."""
    obs = observation([-4.0, 0.0, 0.0, 0.0], [4.0, 0.0, 0.0, 0.8], World(), humans=np.array([[-1.0, 0.0]]))
    assert abs(planner(paper_dir).ocp_goal(obs)[1]) <= 0.1 + 1e-9  # the grid's cell centres
    around = planner(paper_dir, replace(MPCPlannerConfig(), path_humans=True)).ocp_goal(obs)
    assert abs(around[1]) > 0.5


def test_the_goal_handed_over_near_the_end_is_the_final_goal_to_arrive_at_at_rest(paper_dir: Path) -> None:
    obs = observation([3.0, 3.0, 0.0, 0.5], [4.0, 3.0, 0.3, 0.8], World())
    mpc = planner(paper_dir)
    np.testing.assert_allclose(mpc.ocp_goal(obs), [4.0, 3.0, 0.3, 0.0])
    assert mpc.solver.params["w_goal"] == (5.0, 5.0, 0.0, 0.0)  # the position now, no speed to track
    assert mpc.solver.params["w_goal_terminal"] == (40.0, 40.0, 2.0, 40.0)  # at rest at the end
    tapered = planner(paper_dir, replace(MPCPlannerConfig(), approach_stop=None)).ocp_goal(obs)
    np.testing.assert_allclose(tapered, [4.0, 3.0, 0.3, 0.5])  # v_ref = 0.5 m/s per metre left


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
    """Cruising 2 m before a goal 0.8 m aside, between walls: tracking v_ref (with the paper's weight)
    over the whole horizon makes the plan spend its length in a loop to the goal; the approach drops
    that weight near the goal."""
    scene = Scenario("t", 0, CORRIDOR, NOBODY, np.array([6.5, 0.8, 0.0, 0.8]), np.array([8.5, 0.0, 0.0, 0.8]), 20.0)
    direct = np.hypot(2.0, 0.8)
    approach = compute_metrics(run_episode(scene, planner(paper_dir, PAPER_SPEED_WEIGHT)))
    assert approach.reached_goal and approach.path_length < direct and approach.time_to_goal < 3.0
    without = compute_metrics(run_episode(scene, planner(paper_dir, replace(PAPER_SPEED_WEIGHT, approach=False))))
    assert without.path_length > 1.25 * direct and without.time_to_goal > 4.0


def test_the_approach_reaches_a_goal_2_m_from_a_standing_person_where_the_paper_weights_stop_short(
    paper_dir: Path,
) -> None:
    """The tail of the collision potential (q = 50 at 2 m) outweighs the paper's stage weight on the
    position (0.5) near the goal: the robot comes to rest short of it; the approach's weight reaches it."""
    person = CrowdSpec.build(np.array([[2.5, 0.0]]), [np.array([[2.5, 0.0]])], 0.0)
    scene = Scenario("t", 0, World(), person, np.array([-2.0, 0.6, 0.0, 0.8]), np.array([0.5, 0.0, 0.0, 0.8]), 20.0)
    arrives = compute_metrics(run_episode(scene, planner(paper_dir)))
    assert arrives.reached_goal and arrives.time_to_goal < 4.0
    paper_weights = replace(MPCPlannerConfig(), approach_position=None, approach_stop=None)
    assert not run_episode(scene, planner(paper_dir, paper_weights)).reached_goal


def test_a_plan_is_a_loop_when_it_ends_nearer_its_start_than_half_its_length() -> None:
    a = np.linspace(0.0, 2 * np.pi, 51)
    circle = np.stack([0.6 * np.sin(a), 0.6 - 0.6 * np.cos(a)], axis=1)  # 3.8 m back to the start
    straight = np.stack([np.linspace(0.0, 4.0, 51), np.zeros(51)], axis=1)
    b = np.linspace(0.0, np.pi, 20)
    u_turn = np.vstack([np.stack([0.53 * np.sin(b), 0.53 - 0.53 * np.cos(b)], axis=1),
                        np.stack([np.linspace(0.0, -2.3, 31), np.full(31, 1.06)], axis=1)])
    assert is_loop(circle) and not is_loop(straight) and not is_loop(u_turn)
    assert not is_loop(0.1 * circle)  # 0.38 m: stopping or arriving, not cruising in a loop


def test_a_loop_after_the_goal_jumps_behind_is_replaced_by_a_cold_sqp_plan(paper_dir: Path) -> None:
    """Cruising at 0.8 m/s with the goal 10 m ahead, the goal jumps 10 m behind: with the paper's speed
    weight the real-time iterations continue the forward plan into a loop and stay there for several
    steps (a local solution); the restart replaces the first loop by a cold full SQP, and no plan
    handed out is a loop."""
    def loops(config: MPCPlannerConfig) -> tuple[list[bool], int]:
        mpc = planner(paper_dir, replace(config, global_path=False, approach=False))
        x, t, out = np.array([0.0, 0.0, 0.0, 0.8]), 0.0, []
        for k in range(30):
            goal = [x[0] + 10.0, 0.0, 0.0, 0.8] if k < 20 else [x[0] - 10.0, x[1], np.pi, 0.8]
            r = mpc.plan(observation(x, goal, World(), time=t))
            assert r.path is not None
            out.append(is_loop(r.path))
            x, t = r.path[1], t + 0.1
        return out, mpc.restarts

    without, _ = loops(replace(PAPER_SPEED_WEIGHT, loop_restart=None))
    assert sum(without) >= 3
    with_restart, restarts = loops(PAPER_SPEED_WEIGHT)
    assert restarts >= 1 and not any(with_restart)


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
