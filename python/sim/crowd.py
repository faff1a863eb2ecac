"""Crowd simulator: humans driven by the social force model, walking through waypoints.

Integration is pysocialforce's semi-implicit Euler step (``v <- cap(v + dt F)``, then
``r <- r + dt v``) with the speed capped at ``max_speed_factor * desired_speed``. A human whose
last waypoint is final (no loop) stops dead within ``arrival_radius`` of it, as in
pysocialforce. A human with more waypoints switches to the next one within
``waypoint_radius``; looping humans cycle through theirs forever (walking back and forth with
two waypoints).

The robot is an agent for the humans: pass its position and velocity to :meth:`Crowd.step`
and it enters the human-human repulsion like any other person (it is not moved by forces).

What the robot changes (the people's disturbance, :mod:`humanmpc.eval.metrics`): each step with the
robot also computes, from the same state, the velocities the people would have taken without it
(the same forces less the robot's repulsion), :attr:`Crowd.undisturbed_velocities`. The step itself
is computed exactly as without that bookkeeping.

:class:`HumanCrowd` is what a closed loop needs of any crowd: this simulated one (a fixed set of
people, ids ``0..k-1``) and the replay of recorded people (:mod:`humanmpc.sim.recorded`, whose
set changes as people enter and leave).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .social_force import (
    SocialForceParams,
    desired_force,
    group_forces,
    normalize,
    obstacle_force,
    obstacle_force_samples,
    social_force,
)
from .world import World

FloatArray = NDArray[np.float64]


@runtime_checkable
class HumanCrowd(Protocol):
    """The people of an episode as the closed loop sees them, one period per :meth:`step`.

    ``ids`` (k,) names the people present now, ``positions`` (k, 2) gives their positions in
    the same order (m); an id always means the same person within an episode, and the people
    present may change from one step to the next. Nobody absent appears in either.
    """

    @property
    def time(self) -> float: ...

    @property
    def ids(self) -> NDArray[np.int64]: ...

    @property
    def positions(self) -> FloatArray: ...

    def step(self, robot_position: ArrayLike | None = None, robot_velocity: ArrayLike | None = None) -> None:
        """Advance one period; the robot's state is there for crowds that react to it."""


@runtime_checkable
class ReactiveCrowd(HumanCrowd, Protocol):
    """A crowd whose people react to the robot (the simulated ones): their velocities (k, 2) [m/s] now, and
    those the last step would have given them without the robot, from the same state (None before a step
    with the robot)."""

    @property
    def velocities(self) -> FloatArray: ...

    @property
    def undisturbed_velocities(self) -> FloatArray | None: ...


@dataclass(frozen=True)
class CrowdSpec:
    """Initial state and intentions of k humans.

    ``waypoints[i]`` is an (W_i, 2) array of goals visited in order; ``loop[i]`` makes human i
    cycle through them. ``groups`` lists the member indices of each group (disjoint).
    """

    positions: FloatArray
    velocities: FloatArray
    waypoints: tuple[FloatArray, ...]
    desired_speeds: FloatArray
    loop: NDArray[np.bool_]
    groups: tuple[tuple[int, ...], ...] = ()

    def __post_init__(self) -> None:
        k = self.positions.shape[0]
        if self.positions.shape != (k, 2) or self.velocities.shape != (k, 2):
            raise ValueError("CrowdSpec positions and velocities must both have shape (k, 2)")
        if len(self.waypoints) != k or any(w.ndim != 2 or w.shape[1] != 2 or len(w) == 0 for w in self.waypoints):
            raise ValueError("CrowdSpec needs one non-empty (W, 2) waypoint array per human")
        if self.desired_speeds.shape != (k,) or self.loop.shape != (k,):
            raise ValueError("CrowdSpec desired_speeds and loop must have shape (k,)")
        if np.any(self.desired_speeds < 0) or not np.all(np.isfinite(self.desired_speeds)):
            raise ValueError("CrowdSpec desired_speeds must be finite and >= 0")
        seen: set[int] = set()
        for g in self.groups:
            for i in g:
                if not 0 <= i < k or i in seen:
                    raise ValueError(f"CrowdSpec groups must be disjoint indices in [0, {k}), got {self.groups}")
                seen.add(i)

    @property
    def size(self) -> int:
        return int(self.positions.shape[0])

    @staticmethod
    def build(
        positions: ArrayLike,
        waypoints: Sequence[ArrayLike],
        desired_speeds: ArrayLike | float,
        *,
        velocities: ArrayLike | None = None,
        loop: ArrayLike | bool = False,
        groups: Sequence[Sequence[int]] = (),
    ) -> CrowdSpec:
        """Build a spec from plain sequences (velocities default to zero)."""
        pos = np.asarray(positions, dtype=float).reshape(-1, 2)
        k = pos.shape[0]
        vel = np.zeros((k, 2)) if velocities is None else np.asarray(velocities, dtype=float).reshape(k, 2)
        wps = tuple(np.asarray(w, dtype=float).reshape(-1, 2) for w in waypoints)
        speeds = np.broadcast_to(np.asarray(desired_speeds, dtype=float), (k,)).copy()
        loops = np.broadcast_to(np.asarray(loop, dtype=bool), (k,)).copy()
        return CrowdSpec(pos, vel, wps, speeds, loops, tuple(tuple(int(i) for i in g) for g in groups))



class Route:
    """Every person's waypoints and the one each walks to now: how both crowd models (social force
    here, ORCA in :mod:`humanmpc.sim.orca`) follow a :class:`CrowdSpec`'s routes."""

    def __init__(self, spec: CrowdSpec) -> None:
        k = spec.size
        self._loop = spec.loop
        self._count = np.array([len(w) for w in spec.waypoints], dtype=np.int64)
        self._table = np.zeros((k, int(self._count.max()) if k else 1, 2))
        for i, w in enumerate(spec.waypoints):
            self._table[i, : len(w)] = w
        self._index = np.zeros(k, dtype=np.int64)

    @property
    def goals(self) -> FloatArray:
        """The waypoint each person walks to now, (k, 2)."""
        return self._table[np.arange(self._index.size), self._index].copy()

    @property
    def final(self) -> NDArray[np.bool_]:
        """(k,): walking to a last waypoint that does not loop."""
        return ~(self._index + 1 < self._count) & ~self._loop

    def advance(self, positions: FloatArray, radius: float) -> None:
        """Everyone within ``radius`` of their waypoint moves on to the next (cycling when they loop)."""
        reached = np.linalg.norm(self.goals - positions, axis=1) < radius
        move_on = reached & ((self._index + 1 < self._count) | self._loop)
        self._index = np.where(move_on, (self._index + 1) % self._count, self._index)


class SimulatedCrowd:
    """What the simulated crowd models share: a fixed set of people (ids ``0..k-1``) following their
    :class:`Route`, with positions, velocities and the last step's undisturbed velocities."""

    spec: CrowdSpec
    _route: Route
    _pos: FloatArray
    _vel: FloatArray
    _undisturbed: FloatArray | None

    @property
    def size(self) -> int:
        return self.spec.size

    @property
    def ids(self) -> NDArray[np.int64]:
        """Everyone, always: ``0..k-1`` (a simulated crowd's people never leave)."""
        return np.arange(self.size, dtype=np.int64)

    @property
    def positions(self) -> FloatArray:
        return self._pos.copy()

    @property
    def velocities(self) -> FloatArray:
        return self._vel.copy()

    @property
    def goals(self) -> FloatArray:
        """The waypoint each person walks to now, (k, 2)."""
        return self._route.goals

    @property
    def undisturbed_velocities(self) -> FloatArray | None:
        """The velocities (k, 2) the last step would have given the people without the robot, from the same
        state; None before a step with a robot the people see."""
        return None if self._undisturbed is None else self._undisturbed.copy()


@dataclass
class Crowd(SimulatedCrowd):
    """The running simulation of a :class:`CrowdSpec` in a :class:`World`."""

    spec: CrowdSpec
    world: World = field(default_factory=World)
    params: SocialForceParams = field(default_factory=SocialForceParams)
    waypoint_radius: float = 0.5
    time: float = field(init=False, default=0.0)

    def __post_init__(self) -> None:
        k = self.spec.size
        self._pos = self.spec.positions.copy()
        self._vel = self.spec.velocities.copy()
        self._route = Route(self.spec)
        self._group_id = np.full(k, -1, dtype=np.int64)
        for g_index, members in enumerate(self.spec.groups):
            self._group_id[list(members)] = g_index
        self._obstacle_samples = self.world.boundary_samples(self.params.obstacle_resolution)
        self._max_speed = self.params.max_speed_factor * self.spec.desired_speeds
        self._undisturbed: FloatArray | None = None

    def forces(self, robot_position: ArrayLike | None = None, robot_velocity: ArrayLike | None = None) -> FloatArray:
        """Total social force on every human, (k, 2)."""
        return self._forces(robot_position, robot_velocity)[0]

    def _forces(self, robot_position: ArrayLike | None, robot_velocity: ArrayLike | None,
                without_robot: bool = False) -> tuple[FloatArray, FloatArray | None]:
        """The total force, and (``without_robot``, with a robot given) the total force less the robot's
        repulsion, summed in the same order."""
        p = self.params
        goals = self.goals
        others_pos, others_vel = self._pos, self._vel
        if robot_position is not None:
            rv = np.zeros(2) if robot_velocity is None else np.asarray(robot_velocity, dtype=float).reshape(2)
            others_pos = np.vstack([self._pos, np.asarray(robot_position, dtype=float).reshape(1, 2)])
            others_vel = np.vstack([self._vel, rv.reshape(1, 2)])
        desired = desired_force(self._pos, self._vel, goals, self.spec.desired_speeds, p)
        f = desired.copy()
        f += social_force(self._pos, self._vel, others_pos, others_vel, np.arange(self.size), p)
        f0: FloatArray | None = None
        if without_robot and robot_position is not None:
            f0 = desired.copy()
            f0 += social_force(self._pos, self._vel, self._pos, self._vel, np.arange(self.size), p)
        rest = np.zeros_like(f)
        if p.pysocialforce_compat:
            rest = obstacle_force_samples(self._pos, self._obstacle_samples, p)
        elif not self.world.is_empty:
            signed, nearest = self.world.per_obstacle(self._pos)
            rest = obstacle_force(self._pos, signed, nearest, p)
        group = group_forces(self._pos, goals, self._group_id, p)
        for total in (f, f0):
            if total is not None:
                if p.pysocialforce_compat or not self.world.is_empty:
                    total += rest
                total += group
        return f, f0

    def _velocities(self, force: FloatArray) -> FloatArray:
        """The step's velocities from ``force``: capped, zero for people who arrived at a final waypoint."""
        vel = self._vel + self.params.dt * force
        direction, speed = normalize(vel)
        vel = direction * np.minimum(speed, self._max_speed)[:, None]
        arrived = self._route.final & (np.linalg.norm(self.goals - self._pos, axis=1) < self.params.arrival_radius)
        vel[arrived] = 0.0
        return vel

    def step(self, robot_position: ArrayLike | None = None, robot_velocity: ArrayLike | None = None) -> None:
        """Advance the crowd by one ``params.dt``; the robot (if given) repels the humans."""
        if self.size == 0:
            self.time += self.params.dt
            return
        self._route.advance(self._pos, self.waypoint_radius)
        force, force0 = self._forces(robot_position, robot_velocity, without_robot=True)
        if not np.all(np.isfinite(force)):
            raise FloatingPointError("social force model produced a non-finite force; check the crowd state")
        vel = self._velocities(force)
        self._undisturbed = None if force0 is None else self._velocities(force0)
        self._pos = self._pos + self.params.dt * vel
        self._vel = vel
        self.time += self.params.dt
