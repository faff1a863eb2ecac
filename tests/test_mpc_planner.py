"""The evaluation's MPC planner: a thin adapter that hands the C controller a robot stack's inputs (the
global path, tracks, obstacle points, odometry) and returns its decision; the paper's configuration."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.eval.episode import run_episode
from humanmpc.eval.metrics import compute_metrics
from humanmpc.planners.global_path import GlobalPlanner
from humanmpc.planners.interface import Observation
from humanmpc.planners.mpc import MPCPlanner
from humanmpc.sim.crowd import CrowdSpec
from humanmpc.sim.scenarios import Scenario
from humanmpc.sim.world import Polygon, World

# the paper's weights, with the carrot objective they weigh (the progress objective has weights of its own)
PAPER_SPEED_WEIGHT = {"w_goal": (0.5, 0.5, 0.0, 250.0), "w_control": (0.0, 0.0), "progress": 0}
NOBODY = CrowdSpec.build(np.zeros((0, 2)), [], 1.0)
# A wall across the straight line from (-4, 0) to (4, 0), open above y = 2.
WALL = World((Polygon.rectangle((0.0, -1.0), 0.4, 6.0),), (-6.0, 6.0, -6.0, 6.0))


def planner(default_dir: Path, **kwargs: object) -> MPCPlanner:
    # A controller of its own: the planner writes runtime parameters into it.
    return MPCPlanner(humanmpc.load(default_dir), **kwargs)  # type: ignore[arg-type]


def observation(x: list[float] | np.ndarray, goal: list[float], world: World = WALL, time: float = 0.0,
                humans: np.ndarray | None = None, velocities: np.ndarray | None = None) -> Observation:
    now = np.zeros((0, 2)) if humans is None else humans
    vel = np.zeros_like(now) if velocities is None else velocities
    return Observation(
        time=time, x=np.array(x, dtype=float), goal=np.array(goal, dtype=float), humans_now=now, humans_velocity=vel,
        obstacle=world.obstacle_parameter(np.asarray(x[:2], dtype=float)), world=world, dt=0.1,
    )


def is_loop(plan: np.ndarray) -> bool:
    """The test's own criterion: a plan of at least 1 m whose end is nearer its start than half its length."""
    xy = plan[:, :2]
    length = float(np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1)))
    return length >= 1.0 and float(np.linalg.norm(xy[-1] - xy[0])) < 0.5 * length


def test_the_controller_gets_the_global_path_around_the_wall_and_the_paper_configuration_only_the_goal(
    default_dir: Path,
) -> None:
    mpc = planner(default_dir)
    obs = observation([-4.0, 0.0, 0.0, 0.0], [4.0, 0.0, 0.0, 0.8])
    mpc.plan(obs)
    assert mpc.last is not None
    carrot = mpc.last.ocp_goal
    assert np.linalg.norm(carrot[:2] - obs.x[:2]) <= 0.8 * 5.0 + 1e-9  # v_ref * T along the path
    assert carrot[1] > 0.5  # up towards the opening, not through the wall
    assert WALL.signed_distance(carrot[:2]) > 0.2
    paper = MPCPlanner.paper(humanmpc.load(default_dir))
    paper.plan(obs)
    assert paper.last is not None
    np.testing.assert_allclose(paper.last.ocp_goal[:3], [4.0, 0.0, 0.0])


def test_the_paper_configuration_sets_the_papers_runtime_values(default_dir: Path) -> None:
    """Hand-copied from the paper (Table I and Sec. IV): q = 2, w_goal = (0.5, 0.5, 0, 250), obstacle
    slack 100, Gauss-Newton; and no speed cap, no recovery."""
    p = MPCPlanner.paper(humanmpc.load(default_dir)).controller.params
    assert p["q"] == 2.0 and p["w_goal"] == (0.5, 0.5, 0.0, 250.0) and p["slack_l1"] == 100.0
    assert p["exact_hessian"] == 0 and p["recovery_iterations"] == 0 and p["approach"] == 0
    assert p["speed_limit"] >= 1.0


def test_the_tracks_carry_the_peoples_velocities_into_the_controllers_predictions(default_dir: Path) -> None:
    mpc = planner(default_dir)
    walker = np.array([[2.0, 1.0]])
    velocity = np.array([[-0.5, 0.25]])
    mpc.plan(observation([0.0, 0.0, 0.0, 0.0], [6.0, 0.0, 0.0, 0.8], World(), humans=walker, velocities=velocity))
    assert mpc.last is not None and mpc.last.n_people == 1
    pred = mpc.last.predictions[:, 0, :]
    np.testing.assert_allclose(pred[10], walker[0] + 1.0 * velocity[0], atol=1e-12)  # 1 s ahead


def test_the_episodes_cruising_speed_is_the_controllers_v_ref_and_bounds_the_command(default_dir: Path) -> None:
    mpc = planner(default_dir)
    x = np.array([-4.0, 3.0, 0.0, 0.0])
    for k in range(40):
        r = mpc.plan(observation(x, [4.0, 3.0, 0.0, 0.6], World(), time=0.1 * k))
        assert r.command is not None and r.command[0] <= 0.6 + 1e-9
        assert r.path is not None
        x = r.path[1]
    assert mpc.controller.params["v_ref"] == 0.6 and mpc.controller.params["speed_limit"] == 0.6
    assert x[3] > 0.55


CORRIDOR = World((Polygon.rectangle((0.0, 1.6), 20.0, 0.2), Polygon.rectangle((0.0, -1.6), 20.0, 0.2)),
                 (-10.5, 10.5, -2.5, 2.5))


def test_the_approach_brings_the_robot_to_a_goal_ahead_and_aside_without_a_loop(default_dir: Path) -> None:
    """Cruising 2 m before a goal 0.8 m aside, between walls: tracking v_ref (with the paper's weight)
    over the whole horizon makes the plan spend its length in a loop to the goal; the approach drops
    that weight near the goal."""
    scene = Scenario("t", 0, CORRIDOR, NOBODY, np.array([6.5, 0.8, 0.0, 0.8]), np.array([8.5, 0.0, 0.0, 0.8]), 20.0)
    direct = np.hypot(2.0, 0.8)
    approach = compute_metrics(run_episode(scene, planner(default_dir, params=PAPER_SPEED_WEIGHT)))
    assert approach.reached_goal and approach.path_length < direct and approach.time_to_goal < 3.0
    without = compute_metrics(run_episode(scene, planner(default_dir, params={**PAPER_SPEED_WEIGHT, "approach": 0,
                                                                            "recovery_iterations": 0})))
    assert without.path_length > 1.25 * direct and without.time_to_goal > 4.0


def test_the_robot_arrives_at_a_goal_2_m_from_a_standing_person(default_dir: Path) -> None:
    """The tail of the collision potential (q = 50 at 2 m) pulls against the goal's position weight near
    the goal; the robot still arrives, within 4 s."""
    person = CrowdSpec.build(np.array([[2.5, 0.0]]), [np.array([[2.5, 0.0]])], 0.0)
    scene = Scenario("t", 0, World(), person, np.array([-2.0, 0.6, 0.0, 0.8]), np.array([0.5, 0.0, 0.0, 0.8]), 20.0)
    arrives = compute_metrics(run_episode(scene, planner(default_dir)))
    assert arrives.reached_goal and arrives.time_to_goal < 4.0


def test_a_loop_after_the_goal_jumps_behind_is_replaced_by_a_recovery_plan(default_dir: Path) -> None:
    """Cruising at 0.8 m/s with the goal 10 m ahead, the goal jumps 10 m behind: with the paper's speed
    weight the real-time iterations continue the forward plan into a loop and stay there for several
    steps (a local solution); the controller's recovery replaces the loop by a full SQP plan, and no
    plan handed out is a loop."""
    def loops(params: dict[str, object]) -> tuple[list[bool], int]:
        mpc = planner(default_dir, params={**PAPER_SPEED_WEIGHT, "approach": 0, **params}, global_path=False)
        x, t, out = np.array([0.0, 0.0, 0.0, 0.8]), 0.0, []
        for k in range(30):
            goal = [x[0] + 10.0, 0.0, 0.0, 0.8] if k < 20 else [x[0] - 10.0, x[1], np.pi, 0.8]
            r = mpc.plan(observation(x, goal, World(), time=t))
            assert r.path is not None
            out.append(is_loop(r.path))
            x, t = r.path[1], t + 0.1
        return out, mpc.recoveries

    without, _ = loops({"recovery_iterations": 0})
    assert sum(without) >= 3
    with_recovery, recoveries = loops({})
    assert recoveries >= 1 and not any(with_recovery)


def test_the_mpc_goes_around_the_wall_to_the_goal_without_touching_it(default_dir: Path) -> None:
    scene = Scenario("wall", 0, WALL, NOBODY, np.array([-4.0, 0.0, 0.0, 0.0]), np.array([4.0, 0.0, 0.0, 0.8]), 40.0)
    log = run_episode(scene, planner(default_dir))
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
