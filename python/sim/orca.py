"""The second crowd model: ORCA (optimal reciprocal collision avoidance, van den Berg et al. 2011).

People are agents of the RVO2 library (PyPI ``pyrvo``, a binding of its C++ code): every step each
person takes the velocity closest to their preferred one that, for ``time_horizon`` seconds, keeps
them clear of every neighbour moving at its current velocity (each side taking half the avoidance),
and of the static obstacles for ``time_horizon_obst`` seconds. The parameters are CrowdNav's for its
ORCA people (Chen et al. 2019): neighbour distance 10 m, 10 neighbours, time horizons 5 s, radius
0.3 m (the evaluation's person radius 0.25 m plus a 0.05 m margin), maximum speed the person's
desired speed.

Preferred velocity: towards the person's current waypoint at their desired speed; towards a final
waypoint (no loop) at ``min(desired speed, distance / 1 s)``, so people slow down onto their goal
and stay there, as in CrowdNav (its pref velocity is the goal vector within 1 m). Waypoints are
visited in order and switched within ``waypoint_radius`` (0.5 m), like the social force crowd
(:mod:`humanmpc.sim.crowd`), so every scenario's :class:`~humanmpc.sim.crowd.CrowdSpec` runs in
either model (groups have no meaning in ORCA and are ignored).

The robot is an agent for the people (``robot_visible``), of radius ``robot_radius`` 0.3 m (CrowdNav's
robot; the evaluation's robot is 0.2 m, so people keep a 0.1 m margin from it): before each step it is
placed at its position with its velocity, so the people's constraints see it; its own new velocity is
discarded (it moves by its planner). Reciprocity then assumes the robot takes half the avoidance, as in
CrowdNav. Obstacles: polygons as they are (counter-clockwise, as RVO2 needs them), circles as the
regular polygon of ``circle_sides`` sides around them. ORCA is a local method: a person whose straight
way to their waypoint an obstacle blocks stays behind it (the social force model slides them along).

The people's disturbance: a second simulator of the same people without the robot is set to the
crowd's state before every step and stepped with the same preferred velocities; its velocities are
:attr:`OrcaCrowd.undisturbed_velocities`, what the people would have done without the robot from the
same state. RVO2 computes in single precision: positions and velocities come back as float32 values.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .crowd import CrowdSpec, Route, SimulatedCrowd
from .world import World

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class OrcaParams:
    """ORCA's agent parameters (CrowdNav's) and the crowd's bookkeeping; units m, s, m/s."""

    dt: float = 0.1
    neighbor_dist: float = 10.0
    max_neighbors: int = 10
    time_horizon: float = 5.0
    time_horizon_obst: float = 5.0
    radius: float = 0.3
    robot_radius: float = 0.3
    robot_visible: bool = True
    slow_down_time: float = 1.0  # s: near a final waypoint the preferred speed is distance / this
    waypoint_radius: float = 0.5
    circle_sides: int = 16

    def __post_init__(self) -> None:
        positive = ("dt", "neighbor_dist", "time_horizon", "time_horizon_obst", "radius", "robot_radius",
                    "slow_down_time", "waypoint_radius")
        for name in positive:
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"OrcaParams.{name} must be a number > 0, got {value}")
        if self.max_neighbors < 1 or self.circle_sides < 3:
            raise ValueError(f"OrcaParams: max_neighbors must be >= 1 and circle_sides >= 3, got {self}")


def _pyrvo() -> Any:
    try:
        import pyrvo
    except ImportError as err:  # the campaign extra
        raise ImportError(f"the ORCA crowd model needs pyrvo ({err}): pip install 'humanmpc[campaign]' "
                          "(or pip install pyrvo)") from None
    return pyrvo


def obstacle_polygons(world: World, circle_sides: int = 16) -> list[list[tuple[float, float]]]:
    """The world's obstacles as counter-clockwise vertex lists: polygons as they are, each circle as the
    regular polygon with ``circle_sides`` sides that contains it (its vertices at radius / cos(pi / n))."""
    out: list[list[tuple[float, float]]] = []
    for c in world.circles:
        r = c.radius / np.cos(np.pi / circle_sides)
        ang = 2 * np.pi * np.arange(circle_sides) / circle_sides
        out.append([(float(c.center[0] + r * np.cos(a)), float(c.center[1] + r * np.sin(a))) for a in ang])
    for p in world.polygons:
        v = p.array
        area = 0.5 * float(np.dot(v[:, 0], np.roll(v[:, 1], -1)) - np.dot(np.roll(v[:, 0], -1), v[:, 1]))
        if area < 0:
            v = v[::-1]
        out.append([(float(x), float(y)) for x, y in v])
    return out


class OrcaCrowd(SimulatedCrowd):
    """The people of a :class:`~humanmpc.sim.crowd.CrowdSpec` moved by ORCA in a :class:`World`.

    Implements :class:`~humanmpc.sim.crowd.HumanCrowd` (ids ``0..k-1``, everyone always present)."""

    def __init__(self, spec: CrowdSpec, world: World | None = None, params: OrcaParams | None = None) -> None:
        self.spec = spec
        self.world = world or World()
        self.params = params or OrcaParams()
        self.time = 0.0
        self._route = Route(spec)
        self._sim = self._simulator(with_robot=self.params.robot_visible)
        self._ghost = self._simulator(with_robot=False) if self.params.robot_visible else None
        self._pos = spec.positions.astype(float).copy()
        self._vel = spec.velocities.astype(float).copy()
        self._undisturbed: FloatArray | None = None

    def _simulator(self, with_robot: bool) -> Any:
        p = self.params
        sim = _pyrvo().RVOSimulator(p.dt, p.neighbor_dist, p.max_neighbors, p.time_horizon, p.time_horizon_obst,
                                    p.radius, float(np.max(self.spec.desired_speeds, initial=1.0)))
        for i in range(self.spec.size):
            sim.add_agent(tuple(map(float, self.spec.positions[i])), p.neighbor_dist, p.max_neighbors,
                          p.time_horizon, p.time_horizon_obst, p.radius, float(self.spec.desired_speeds[i]),
                          tuple(map(float, self.spec.velocities[i])))
        if with_robot:  # the last agent; placed at the robot before every step
            sim.add_agent((1e6, 1e6), p.neighbor_dist, p.max_neighbors, p.time_horizon, p.time_horizon_obst,
                          p.robot_radius, 10.0, (0.0, 0.0))
        polygons = obstacle_polygons(self.world, p.circle_sides)
        for poly in polygons:
            sim.add_obstacle(poly)
        if polygons:
            sim.process_obstacles()
        return sim

    def preferred_velocities(self) -> FloatArray:
        """Towards the current waypoint at the desired speed, slowing onto a final one (module docstring)."""
        to_goal = self.goals - self._pos
        dist = np.linalg.norm(to_goal, axis=1)
        speed = np.where(self._route.final, np.minimum(self.spec.desired_speeds, dist / self.params.slow_down_time),
                         self.spec.desired_speeds)
        return np.where(dist[:, None] > 1e-9, to_goal / np.maximum(dist, 1e-9)[:, None] * speed[:, None], 0.0)

    @staticmethod
    def _load(sim: Any, pos: FloatArray, vel: FloatArray, pref: FloatArray) -> None:
        for i in range(pos.shape[0]):
            sim.set_agent_position(i, (float(pos[i, 0]), float(pos[i, 1])))
            sim.set_agent_velocity(i, (float(vel[i, 0]), float(vel[i, 1])))
            sim.set_agent_pref_velocity(i, (float(pref[i, 0]), float(pref[i, 1])))

    @staticmethod
    def _read(sim: Any, k: int) -> tuple[FloatArray, FloatArray]:
        pos, vel = np.empty((k, 2)), np.empty((k, 2))
        for i in range(k):
            p, v = sim.get_agent_position(i), sim.get_agent_velocity(i)
            pos[i] = (p.x, p.y)
            vel[i] = (v.x, v.y)
        return pos, vel

    def step(self, robot_position: ArrayLike | None = None, robot_velocity: ArrayLike | None = None) -> None:
        """Advance one ``params.dt``; the robot (if given and visible) is an agent the people avoid."""
        k = self.size
        self.time += self.params.dt
        if k == 0:
            return
        self._route.advance(self._pos, self.params.waypoint_radius)
        pref = self.preferred_velocities()
        self._load(self._sim, self._pos, self._vel, pref)
        robot_here = robot_position is not None and self.params.robot_visible
        if self.params.robot_visible:
            rp = np.asarray(robot_position, dtype=float).reshape(2) if robot_position is not None \
                else np.array([1e6, 1e6])
            rv = np.zeros(2) if robot_velocity is None or robot_position is None \
                else np.asarray(robot_velocity, dtype=float).reshape(2)
            self._sim.set_agent_position(k, (float(rp[0]), float(rp[1])))
            self._sim.set_agent_velocity(k, (float(rv[0]), float(rv[1])))
            self._sim.set_agent_pref_velocity(k, (float(rv[0]), float(rv[1])))
        if robot_here and self._ghost is not None:
            self._load(self._ghost, self._pos, self._vel, pref)
            self._ghost.do_step()
            self._undisturbed = self._read(self._ghost, k)[1]
        else:
            self._undisturbed = None
        self._sim.do_step()
        self._pos, self._vel = self._read(self._sim, k)
        if not (np.all(np.isfinite(self._pos)) and np.all(np.isfinite(self._vel))):
            raise FloatingPointError("ORCA produced a non-finite position or velocity; check the crowd state")
