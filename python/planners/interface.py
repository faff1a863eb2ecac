"""The interface every local planner of the evaluation implements (DWB baseline, MPC adapter).

Per control step the closed loop hands the planner an :class:`Observation` and applies the
returned :class:`PlanResult`'s ``u = (a, omega)`` for one period ``dt``. The fields mirror the
generated solver's ``step(x0, goal, humans_now, humans_pred, obstacle)`` inputs and its
``u0 / command / x / u / status / stop / reason / timings`` outputs, so an MPC adapter is a
one-to-one copy.
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

    x            robot state [px, py, theta, v] (4,)
    goal         [gx, gy, gtheta, v_ref] (4,), v_ref the preferred cruising speed
    humans_now   observed human positions (k, 2)
    humans_pred  predicted positions at the nodes n = 0..N (N + 1, k, 2), node 0 = humans_now
    obstacle     nearest point of the nearest static obstacle to the robot (2,)
    world        all static obstacles, for planners that want more than the nearest point
    dt           control period (s); the node spacing of humans_pred as well
    robot        the robot's limits and radii
    """

    time: float
    x: FloatArray
    goal: FloatArray
    humans_now: FloatArray
    humans_pred: FloatArray
    obstacle: FloatArray
    world: World
    dt: float
    robot: RobotModel = field(default_factory=RobotModel)

    @property
    def humans_velocity(self) -> FloatArray:
        """The tracker's velocity estimate of each human (k, 2) [m/s]: the slope of the constant-velocity
        prediction over its first interval."""
        if self.humans_pred.shape[0] < 2:
            return np.zeros_like(self.humans_now)
        return (self.humans_pred[1] - self.humans_pred[0]) / self.dt

    @property
    def n_humans(self) -> int:
        return int(self.humans_now.shape[0])


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
