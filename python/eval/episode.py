"""The closed loop: robot + planner + crowd, one control period at a time.

Per step (period ``dt``, 0.1 s by default):

1. observe the humans' positions (exact, no sensor noise) and track them: each person's velocity
   from their observations only (the tracker); the planner gets tracks (positions, velocities,
   ids), never predicted paths: the MPC planner's controller predicts in C, a planner that wants
   predictions makes them itself;
2. select the obstacle point: the nearest point of the nearest static obstacle to the robot,
   chosen anew every step;
3. call the planner with an :class:`~humanmpc.planners.interface.Observation`;
4. apply ``u`` to the robot for one period and step the crowd once, the robot taking part in
   the social force model as an agent at its state at the start of the period;
5. log everything the metrics and plots need; for a crowd that reacts to the robot (a simulated one),
   also the people's velocities and those the crowd model would have given them without the robot
   (the disturbance metrics).

Simulated people move by the crowd model of :attr:`EpisodeConfig.crowd_model` (social force or ORCA);
recorded people are replayed whatever it says.

The people present may change within an episode (recorded crowds: people enter and leave as
recorded). The log keeps everyone who was ever present, in the order of their ids: ``humans``
(T + 1, K, 2) holds NaN where a person is absent and ``present`` (T + 1, K) says who is there;
metrics and figures use the mask (the NaN makes any use that forgets it visible, where a
placeholder position would silently count). The tracker is given the ids, so a person's
velocity is estimated from that person's own observations.

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
from ..sim.crowd import ReactiveCrowd
from ..sim.orca import OrcaParams
from ..sim.predict import ConstantVelocityTracker, Tracker
from ..sim.robot import RobotModel, step, velocity_vector
from ..sim.scenarios import CROWD_MODELS, Scenario
from ..sim.social_force import SocialForceParams
from ..sim.world import World

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class EpisodeConfig:
    """Loop settings shared by every planner of an evaluation."""

    dt: float = 0.1
    robot: RobotModel = field(default_factory=RobotModel)
    social_force: SocialForceParams = field(default_factory=SocialForceParams)
    stop_on_collision: bool = False
    keep_plans: bool = True
    crowd_model: str = "social_force"  # how simulated people move: CROWD_MODELS (recorded people are replayed)
    orca: OrcaParams = field(default_factory=OrcaParams)

    def __post_init__(self) -> None:
        if abs(self.social_force.dt - self.dt) > 1e-12:
            raise ValueError(
                f"EpisodeConfig: the crowd's dt {self.social_force.dt} must equal the control dt {self.dt}"
            )
        if abs(self.orca.dt - self.dt) > 1e-12:
            raise ValueError(f"EpisodeConfig: ORCA's dt {self.orca.dt} must equal the control dt {self.dt}")
        if self.crowd_model not in CROWD_MODELS:
            raise ValueError(f"EpisodeConfig: unknown crowd model {self.crowd_model!r}; crowd models: "
                             f"{', '.join(CROWD_MODELS)}")


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
    humans: FloatArray  # (T + 1, K, 2), NaN where absent; K: everyone present at some sample
    controls: FloatArray  # (T, 2)
    obstacle_points: FloatArray  # (T, 2)
    stops: NDArray[np.bool_]  # (T,)
    reasons: list[str | None]
    solve_ms: FloatArray  # (T,)
    plans: list[FloatArray | None]  # predicted robot paths, if kept
    reached_goal: bool
    ended_by: str  # "goal", "time_limit" or "collision"
    # (T + 1, K): who is present at each sample; None: everyone at every sample (a fixed crowd)
    present_mask: NDArray[np.bool_] | None = None
    human_ids: NDArray[np.int64] | None = None  # (K,): the crowd's id of each column; None: 0..K-1
    # (T + 1, K, 2), reactive crowds only (else None): each person's velocity at every sample, and the velocity
    # the crowd model gave them over the step that ends there without the robot, from the same state (the
    # disturbance metrics); sample 0 holds the initial velocities in both
    human_velocities: FloatArray | None = None
    undisturbed_velocities: FloatArray | None = None

    def __post_init__(self) -> None:
        shape = self.humans.shape[:2]
        if self.humans.ndim != 3 or self.humans.shape[2] != 2:
            raise ValueError(f"EpisodeLog: humans must have shape (T + 1, K, 2), got {self.humans.shape}")
        if self.present_mask is not None:
            if self.present_mask.shape != shape:
                raise ValueError(f"EpisodeLog: present_mask must have shape {shape}, got {self.present_mask.shape}")
            if not np.all(np.isfinite(self.humans[self.present_mask])):
                raise ValueError("EpisodeLog: a person marked present has a non-finite position")
        elif not np.all(np.isfinite(self.humans)):
            raise ValueError("EpisodeLog: humans has non-finite positions; give present_mask for people who are absent")
        if self.human_ids is not None and self.human_ids.shape != (shape[1],):
            raise ValueError(f"EpisodeLog: human_ids must have shape ({shape[1]},), got {self.human_ids.shape}")
        for name in ("human_velocities", "undisturbed_velocities"):
            v = getattr(self, name)
            if v is not None and v.shape != self.humans.shape:
                raise ValueError(f"EpisodeLog: {name} must have the shape of humans {self.humans.shape}, got {v.shape}")

    @property
    def steps(self) -> int:
        return int(self.controls.shape[0])

    @property
    def present(self) -> NDArray[np.bool_]:
        """(T + 1, K): True where person k is present at sample t."""
        if self.present_mask is None:
            return np.ones(self.humans.shape[:2], dtype=bool)
        return self.present_mask


def _stack_people(ids: list[NDArray[np.int64]], positions: list[FloatArray]) -> tuple[
    FloatArray, NDArray[np.bool_], NDArray[np.int64]
]:
    """Per-sample (ids, positions) as (T + 1, K, 2) with NaN where absent, the mask, the ids."""
    everyone = np.unique(np.concatenate(ids)) if ids else np.zeros(0, dtype=np.int64)
    humans = np.full((len(ids), everyone.size, 2), np.nan)
    present = np.zeros((len(ids), everyone.size), dtype=bool)
    for t, (who, pos) in enumerate(zip(ids, positions, strict=True)):
        col = np.searchsorted(everyone, who)
        humans[t, col] = pos
        present[t, col] = True
    return humans, present, everyone.astype(np.int64)


def _in_contact(world: World, robot: RobotModel, x: FloatArray, humans: FloatArray) -> bool:
    """Contact of the robot at ``x`` with a person present (``humans`` (k, 2)) or an obstacle."""
    if humans.shape[0] and np.min(np.linalg.norm(humans - x[:2], axis=1)) < robot.radius + robot.human_radius:
        return True
    return bool(world.signed_distance(x[:2]) < robot.radius)


def run_episode(
    scenario: Scenario,
    planner: Planner,
    config: EpisodeConfig | None = None,
    tracker: Tracker | None = None,
) -> EpisodeLog:
    """Run ``planner`` on ``scenario`` until goal, time limit (or first contact, if asked)."""
    cfg = config or EpisodeConfig()
    tracks = tracker or ConstantVelocityTracker()
    tracks.reset()
    planner.reset()
    crowd = scenario.start_crowd(cfg.social_force, cfg.crowd_model, cfg.orca)
    reactive = crowd if isinstance(crowd, ReactiveCrowd) else None  # simulated people react to the robot
    velocities: list[FloatArray] = [reactive.velocities] if reactive else []
    undisturbed: list[FloatArray] = [reactive.velocities] if reactive else []
    world, robot, goal = scenario.world, cfg.robot, np.asarray(scenario.goal, dtype=float)
    x = np.asarray(scenario.robot_start, dtype=float).copy()
    t = 0.0
    times, states, humans, ids = [t], [x.copy()], [crowd.positions], [crowd.ids]
    controls: list[FloatArray] = []
    obstacle_points: list[FloatArray] = []
    stops: list[bool] = []
    reasons: list[str | None] = []
    solve_ms: list[float] = []
    plans: list[FloatArray | None] = []
    n_steps = round(scenario.time_limit / cfg.dt)
    ended_by = "time_limit"
    for _ in range(n_steps):
        humans_now = humans[-1].copy()
        humans_velocity = tracks.observe(t, humans_now, ids[-1])
        obstacle = world.obstacle_parameter(x[:2])
        obs = Observation(t, x.copy(), goal.copy(), humans_now, humans_velocity, obstacle, world, cfg.dt, robot,
                          human_ids=np.asarray(ids[-1], dtype=np.int64))
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
        ids.append(crowd.ids)
        if reactive is not None:
            velocities.append(reactive.velocities)
            without = reactive.undisturbed_velocities
            undisturbed.append(velocities[-1] if without is None else without)
        if np.linalg.norm(x[:2] - goal[:2]) <= scenario.goal_tolerance:
            ended_by = "goal"
            break
        if cfg.stop_on_collision and _in_contact(world, robot, x, humans[-1]):
            ended_by = "collision"
            break
    people, present, human_ids = _stack_people(ids, humans)
    everyone_always = bool(np.all(present))
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
        humans=people,
        controls=np.array(controls).reshape(-1, 2),
        obstacle_points=np.array(obstacle_points).reshape(-1, 2),
        stops=np.array(stops, dtype=bool),
        reasons=reasons,
        solve_ms=np.array(solve_ms),
        plans=plans,
        reached_goal=ended_by == "goal",
        ended_by=ended_by,
        present_mask=None if everyone_always else present,
        human_ids=human_ids,
        human_velocities=np.array(velocities).reshape(people.shape) if reactive is not None else None,
        undisturbed_velocities=np.array(undisturbed).reshape(people.shape) if reactive is not None else None,
    )
