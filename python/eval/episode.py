"""The closed loop: robot + planner + crowd, one control period at a time.

Per step (period ``dt``, 0.1 s by default):

1. observe the humans' positions (exact, no sensor noise) and predict them over the horizon
   from the observations only;
2. select the obstacle point: the nearest point of the nearest static obstacle to the robot,
   chosen anew every step;
3. call the planner with an :class:`~humanmpc.planners.interface.Observation`;
4. apply ``u`` to the robot for one period and step the crowd once, the robot taking part in
   the social force model as an agent at its state at the start of the period;
5. log everything the metrics and plots need.

The episode ends when the robot's centre is within the scenario's ``goal_tolerance`` of the
goal position, or at the time limit. Collisions do **not** end it by default (the robot and
the people carry on, the metrics count every contact event and the time spent in contact, and
success requires none); ``stop_on_collision=True`` ends it at the first contact.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..planners.interface import Observation, Planner
from ..sim.crowd import Crowd
from ..sim.predict import ConstantVelocityPredictor, Predictor
from ..sim.robot import RobotModel, step, velocity_vector
from ..sim.scenarios import Scenario
from ..sim.social_force import SocialForceParams
from ..sim.world import World

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class EpisodeConfig:
    """Loop settings shared by every planner of an evaluation."""

    dt: float = 0.1
    horizon: int = 50
    robot: RobotModel = field(default_factory=RobotModel)
    social_force: SocialForceParams = field(default_factory=SocialForceParams)
    stop_on_collision: bool = False
    keep_plans: bool = True

    def __post_init__(self) -> None:
        if abs(self.social_force.dt - self.dt) > 1e-12:
            raise ValueError(
                f"EpisodeConfig: the crowd's dt {self.social_force.dt} must equal the control dt {self.dt}"
            )


@dataclass
class EpisodeLog:
    """Everything recorded in one episode; arrays over T control steps (T + 1 samples)."""

    scenario: str
    seed: int
    planner: str
    dt: float
    world: World
    robot: RobotModel
    goal: FloatArray
    goal_tolerance: float
    time_limit: float
    times: FloatArray  # (T + 1,)
    states: FloatArray  # (T + 1, 4)
    humans: FloatArray  # (T + 1, k, 2)
    controls: FloatArray  # (T, 2)
    obstacle_points: FloatArray  # (T, 2)
    stops: NDArray[np.bool_]  # (T,)
    reasons: list[str | None]
    solve_ms: FloatArray  # (T,)
    plans: list[FloatArray | None]  # predicted robot paths, if kept
    reached_goal: bool
    ended_by: str  # "goal", "time_limit" or "collision"

    @property
    def steps(self) -> int:
        return int(self.controls.shape[0])


def _in_contact(world: World, robot: RobotModel, x: FloatArray, humans: FloatArray) -> bool:
    if humans.shape[0] and np.min(np.linalg.norm(humans - x[:2], axis=1)) < robot.radius + robot.human_radius:
        return True
    return bool(world.signed_distance(x[:2]) < robot.radius)


def run_episode(
    scenario: Scenario,
    planner: Planner,
    config: EpisodeConfig | None = None,
    predictor: Predictor | None = None,
) -> EpisodeLog:
    """Run ``planner`` on ``scenario`` until goal, time limit (or first contact, if asked)."""
    cfg = config or EpisodeConfig()
    pred = predictor or ConstantVelocityPredictor(cfg.horizon, cfg.dt)
    pred.reset()
    planner.reset()
    crowd = Crowd(scenario.crowd, scenario.world, cfg.social_force)
    world, robot, goal = scenario.world, cfg.robot, np.asarray(scenario.goal, dtype=float)
    x = np.asarray(scenario.robot_start, dtype=float).copy()
    t = 0.0
    times, states, humans = [t], [x.copy()], [crowd.positions]
    controls: list[FloatArray] = []
    obstacle_points: list[FloatArray] = []
    stops: list[bool] = []
    reasons: list[str | None] = []
    solve_ms: list[float] = []
    plans: list[FloatArray | None] = []
    n_steps = round(scenario.time_limit / cfg.dt)
    ended_by = "time_limit"
    for _ in range(n_steps):
        humans_now = crowd.positions
        humans_pred = pred.observe(t, humans_now)
        obstacle = world.obstacle_parameter(x[:2])
        obs = Observation(t, x.copy(), goal.copy(), humans_now, humans_pred, obstacle, world, cfg.dt, robot)
        t0 = time.perf_counter()
        result = planner.plan(obs)
        wall_ms = (time.perf_counter() - t0) * 1e3
        x_next = step(robot, x, result.u, cfg.dt)
        crowd.step(robot_position=x[:2], robot_velocity=velocity_vector(x))
        x, t = x_next, t + cfg.dt
        controls.append(robot.limits.clip_control(result.u))
        obstacle_points.append(obstacle)
        stops.append(bool(result.stop))
        reasons.append(result.reason if result.stop else None)
        solve_ms.append(result.solve_time_ms if result.solve_time_ms > 0 else wall_ms)
        plans.append(None if (result.path is None or not cfg.keep_plans) else np.asarray(result.path, dtype=float))
        times.append(t)
        states.append(x.copy())
        humans.append(crowd.positions)
        if np.linalg.norm(x[:2] - goal[:2]) <= scenario.goal_tolerance:
            ended_by = "goal"
            break
        if cfg.stop_on_collision and _in_contact(world, robot, x, humans[-1]):
            ended_by = "collision"
            break
    k = scenario.crowd.size
    return EpisodeLog(
        scenario=scenario.name,
        seed=scenario.seed,
        planner=getattr(planner, "name", type(planner).__name__),
        dt=cfg.dt,
        world=world,
        robot=robot,
        goal=goal,
        goal_tolerance=scenario.goal_tolerance,
        time_limit=scenario.time_limit,
        times=np.array(times),
        states=np.array(states),
        humans=np.array(humans).reshape(len(times), k, 2),
        controls=np.array(controls).reshape(-1, 2),
        obstacle_points=np.array(obstacle_points).reshape(-1, 2),
        stops=np.array(stops, dtype=bool),
        reasons=reasons,
        solve_ms=np.array(solve_ms),
        plans=plans,
        reached_goal=ended_by == "goal",
        ended_by=ended_by,
    )
