"""The interface every local planner of the evaluation implements (DWB baseline, MPC adapter).

Per control step the closed loop hands the planner an :class:`Observation` and applies the
returned :class:`PlanResult`'s ``u = (a, omega)`` for one period ``dt``. The people come as tracks
(position, velocity, id, optionally a position covariance), what a robot's tracker hands its
navigation stack; a planner that wants predicted paths makes them itself
(:func:`humanmpc.sim.predict.predict_constant_velocity`). The outputs mirror the generated
controller's ``u / command / plan / controls / stop / reason / timings``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from ..sim.robot import RobotModel
from ..sim.world import World

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Observation:
    """What a planner knows at one control step.

    x                  robot state [px, py, theta, v] (4,)
    goal               [gx, gy, gtheta, v_ref] (4,), v_ref the preferred cruising speed
    humans_now         the people's tracked positions (k, 2) [m]
    humans_velocity    their tracked velocities (k, 2) [m/s]
    obstacle           nearest point of the nearest static obstacle to the robot (2,)
    world              all static obstacles, for planners that want more than the nearest point
    dt                 control period (s)
    robot              the robot's limits and radii
    human_ids          the tracker's id of each person (k,); None: 0..k-1
    human_covariances  position covariances [sxx, sxy, syy] (k, 3) [m^2], if the tracker gives them
    """

    time: float
    x: FloatArray
    goal: FloatArray
    humans_now: FloatArray
    humans_velocity: FloatArray
    obstacle: FloatArray
    world: World
    dt: float
    robot: RobotModel = field(default_factory=RobotModel)
    human_ids: NDArray[np.int64] | None = None
    human_covariances: FloatArray | None = None

    def __post_init__(self) -> None:
        k = self.humans_now.shape[0]
        if self.humans_now.shape != (k, 2) or self.humans_velocity.shape != (k, 2):
            raise ValueError(f"Observation: humans_now and humans_velocity must both have shape (k, 2), got "
                             f"{self.humans_now.shape} and {self.humans_velocity.shape}")
        if self.human_ids is not None and np.shape(self.human_ids) != (k,):
            raise ValueError(f"Observation: human_ids must have shape ({k},), got {np.shape(self.human_ids)}")
        if self.human_covariances is not None and np.shape(self.human_covariances) != (k, 3):
            raise ValueError(f"Observation: human_covariances must have shape ({k}, 3), got "
                             f"{np.shape(self.human_covariances)}")

    @property
    def n_humans(self) -> int:
        return int(self.humans_now.shape[0])

    @property
    def ids(self) -> NDArray[np.int64]:
        """The people's ids (k,): the tracker's, or 0..k-1 without them."""
        if self.human_ids is None:
            return np.arange(self.n_humans, dtype=np.int64)
        return np.asarray(self.human_ids, dtype=np.int64)

    @property
    def tracks(self) -> FloatArray:
        """The people as tracks [x, y, vx, vy] (k, 4), the controller's form."""
        return np.hstack([self.humans_now, self.humans_velocity])


@dataclass(frozen=True)
class PlanResult:
    """A planner's decision for one control step.

    u              (a, omega) to apply over the next period (2,)
    command        (v, omega) the base should track, if the planner thinks in velocities
    path           predicted robot states over the horizon (N + 1, 4), if any
    controls       planned controls (N, 2), if any
    stop           True if this is a protective stop (brake, no turning)
    reason         why it stopped (or another short diagnostic), None if nothing to say
    status         the planner's own status code / word
    solve_time_ms  wall time the planner needed for this step
    timings        finer timings in ms (e.g. preparation / feedback phases)
    """

    u: FloatArray
    command: FloatArray | None = None
    path: FloatArray | None = None
    controls: FloatArray | None = None
    stop: bool = False
    reason: str | None = None
    status: int | str | None = None
    solve_time_ms: float = 0.0
    timings: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        u = np.asarray(self.u, dtype=float)
        if u.shape != (2,) or not np.all(np.isfinite(u)):
            raise ValueError(f"PlanResult.u must be two finite numbers (a, omega), got {self.u!r}")
        object.__setattr__(self, "u", u)


@runtime_checkable
class Planner(Protocol):
    """A local planner: stateful across the steps of one episode, reset between episodes."""

    name: str

    def reset(self) -> None:
        """Forget everything about the previous episode."""

    def plan(self, obs: Observation) -> PlanResult:
        """Decide the control for the next period."""
        ...


def protective_stop(obs: Observation, reason: str, solve_time_ms: float = 0.0) -> PlanResult:
    """Brake at the full deceleration limit, no turning (the paper's protective stop)."""
    lim = obs.robot.limits
    v = float(obs.x[3])
    a = max(lim.a_min, (lim.v_min - v) / obs.dt) if v > lim.v_min else 0.0
    return PlanResult(
        u=np.array([a, 0.0]),
        command=np.array([max(lim.v_min, v + a * obs.dt), 0.0]),
        stop=True,
        reason=reason,
        status="stop",
        solve_time_ms=solve_time_ms,
    )
