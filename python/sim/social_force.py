"""Vectorised social force model (the forces only; :mod:`humanmpc.crowd` integrates them).

The model and its default parameters are those of pysocialforce 1.1.2 (Helbing & Molnár 1995
with the extensions of Moussaïd et al. 2009/2010 as used by PedSim), which is what a
``pysocialforce.Simulator`` actually computes with its default configuration:

* goal attraction with relaxation time tau: ``F = (v_des * e_goal - v) / tau``, and
  ``F = -v / tau`` inside ``goal_threshold`` of the goal;
* human-human repulsion by the **Moussaïd et al. (2009) specification** (velocity-dependent,
  anisotropic: interaction vector ``D = lambda (v_b - v_a) + e_ab``, range ``B = gamma |D|``,
  a deceleration term along ``D`` and an evasion term along its left normal). This is neither
  the circular nor the elliptic Helbing-Molnár potential; it is the one pysocialforce enables;
* obstacle repulsion ``exp(-(d - radius) / sigma) e`` from the nearest point of each obstacle
  (Helbing & Molnár 1995; with pysocialforce's factor 10, sigma 0.2 m, radius 0.35 m this is
  57.5 exp(-d / 0.2) m/s^2, close to their U0/R exp(-d/R) = 50 exp(-d / 0.2));
* group forces (coherence towards the centre of mass, repulsion between members closer than
  a threshold, gaze) as pysocialforce's ``GroupCoherenceForceAlt``, ``GroupRepulsiveForce``
  and ``GroupGazeForceAlt``.

Three deliberate differences from pysocialforce 1.1.2, all defects there; ``pysocialforce_compat``
reproduces them (only for the cross-check test against pysocialforce):

1. the angle theta between the interaction direction and the direction to the other agent is
   wrapped to (-pi, pi]. pysocialforce subtracts two ``arctan2`` values without wrapping, so
   whenever the two directions straddle the -x axis theta comes out near +-2 pi and the
   repulsion vanishes (people meeting head-on along the x axis walk into each other);
2. the group coherence softening ``(tanh(|c - r| - (n - 1) / 2) + 1) / 2`` uses the distance to
   the group's centre of mass. pysocialforce computes that distance with ``stateutils.speeds``,
   which reads columns 2:4 of a two-column array, i.e. always 0, so its coherence is a
   distance-independent, nearly vanishing pull for large groups (0.03 % for 9 people);
3. obstacles repel from their nearest point. pysocialforce sums the repulsion over boundary
   samples every 0.1 m, which makes a wall about five times stronger than one point and
   dependent on the sampling resolution: in a 3 m wide corridor the walls then squeeze two
   people onto the centre line, where they walk through each other (0.27 m apart).

A fourth difference only matters on exact symmetry: an exactly head-on encounter (theta = 0)
gets the evasion of a slight right-hand one (keep right), where pysocialforce applies no
evasion at all and the two walk into each other.

All functions are pure: arrays in, forces ``(k, 2)`` out, finite for every finite input
(coincident positions and zero velocities included).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
_EPS = 1e-9
_HEAD_ON = 1e-9  # rad: |theta| below this is an exactly head-on encounter


@dataclass(frozen=True)
class SocialForceParams:
    """Parameters of the force model and its integration (defaults: pysocialforce's effective
    defaults, except dt = 0.1 s and the two fixes; see the module docstring)."""

    dt: float = 0.1
    relaxation_time: float = 0.5
    goal_threshold: float = 0.2
    desired_factor: float = 1.0
    max_speed_factor: float = 1.3
    arrival_radius: float = 0.5
    social_factor: float = 5.1
    social_lambda: float = 2.0
    social_gamma: float = 0.35
    social_n: float = 2.0
    social_n_prime: float = 3.0
    obstacle_factor: float = 10.0
    obstacle_sigma: float = 0.2
    obstacle_threshold: float = 3.0
    agent_radius: float = 0.35
    obstacle_resolution: float = 10.0
    group_coherence_factor: float = 1.0
    group_repulsive_factor: float = 1.0
    group_repulsive_threshold: float = 0.55
    group_gaze_factor: float = 1.0
    pysocialforce_compat: bool = False

    def __post_init__(self) -> None:
        positive = ("dt", "relaxation_time", "max_speed_factor", "social_gamma", "obstacle_sigma")
        for name in positive:
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"SocialForceParams.{name} must be > 0, got {value}")


def normalize(vecs: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Unit vectors and norms along the last axis; a zero vector stays zero."""
    norms = np.linalg.norm(vecs, axis=-1)
    unit = vecs / np.maximum(norms, _EPS)[..., None]
    unit = np.where(norms[..., None] > 0, unit, 0.0)
    return unit, norms


def left_normal(vecs: FloatArray) -> FloatArray:
    return np.stack([-vecs[..., 1], vecs[..., 0]], axis=-1)


def desired_force(
    pos: FloatArray, vel: FloatArray, goal: FloatArray, desired_speed: FloatArray, p: SocialForceParams
) -> FloatArray:
    """Relaxation towards ``desired_speed`` along the goal direction; brake near the goal."""
    direction, dist = normalize(goal - pos)
    far = dist > p.goal_threshold
    force = np.where(far[:, None], direction * desired_speed[:, None] - vel, -vel)
    return force / p.relaxation_time * p.desired_factor


def social_force(
    pos: FloatArray, vel: FloatArray, others_pos: FloatArray, others_vel: FloatArray,
    self_index: NDArray[np.int64], p: SocialForceParams,
) -> FloatArray:
    """Moussaïd repulsion on each of the k agents ``pos`` from every agent in ``others_pos``.

    ``self_index[a]`` is the row of agent a in ``others_*`` (its own entry is ignored), or -1
    if it is not among them.
    """
    k, m = pos.shape[0], others_pos.shape[0]
    if k == 0 or m == 0:
        return np.zeros((k, 2))
    diff_dir, diff_len = normalize(pos[:, None, :] - others_pos[None, :, :])  # (k, m): from b to a
    vel_diff = others_vel[None, :, :] - vel[:, None, :]
    inter_dir, inter_len = normalize(p.social_lambda * vel_diff + diff_dir)
    theta = np.arctan2(inter_dir[..., 1], inter_dir[..., 0]) - np.arctan2(diff_dir[..., 1], diff_dir[..., 0])
    if not p.pysocialforce_compat:
        theta = np.pi - np.mod(np.pi - theta, 2 * np.pi)  # into (-pi, pi]
    B = np.maximum(p.social_gamma * inter_len, _EPS)
    decay = -diff_len / B
    along = np.exp(decay - np.square(p.social_n_prime * B * theta))
    # Exactly head-on (theta = 0) the evasion direction is undefined and pysocialforce applies
    # none: two people on one line walk into each other. Break the tie by keeping right
    # (Moussaïd et al. 2009 report that bias), which is also the theta -> 0- limit.
    head_on = np.abs(theta) < _HEAD_ON
    side = np.sign(theta) if p.pysocialforce_compat else np.where(head_on, -1.0, np.sign(theta))
    sideways = -side * np.exp(decay - np.square(p.social_n * B * theta))
    pair = along[..., None] * inter_dir + sideways[..., None] * left_normal(inter_dir)
    not_self = np.ones((k, m), dtype=bool)
    own = self_index >= 0
    not_self[np.nonzero(own)[0], self_index[own]] = False
    return p.social_factor * np.sum(np.where(not_self[..., None], pair, 0.0), axis=1)


def obstacle_force(pos: FloatArray, signed_dist: FloatArray, nearest: FloatArray, p: SocialForceParams) -> FloatArray:
    """Helbing-Molnár border repulsion: ``exp(-(d - radius) / sigma)`` away from the nearest
    point of every obstacle within range (``signed_dist`` (k, M), ``nearest`` (k, M, 2) from
    :meth:`humanmpc.world.World.per_obstacle`; inside an obstacle it pushes outwards)."""
    if signed_dist.size == 0 or pos.shape[0] == 0:
        return np.zeros_like(pos)
    direction, _ = normalize(pos[:, None, :] - nearest)
    direction = np.where(signed_dist[..., None] < 0, -direction, direction)
    dist = signed_dist - p.agent_radius
    near = dist < p.obstacle_threshold + p.agent_radius
    weight = np.where(near, np.exp(-np.where(near, dist, 0.0) / p.obstacle_sigma), 0.0)
    return p.obstacle_factor * np.sum(weight[..., None] * direction, axis=1)


def obstacle_force_samples(pos: FloatArray, samples: FloatArray, p: SocialForceParams) -> FloatArray:
    """pysocialforce's border repulsion: the same term summed over every boundary sample
    (M, 2) within range (its strength grows with the sampling resolution)."""
    if samples.shape[0] == 0 or pos.shape[0] == 0:
        return np.zeros_like(pos)
    direction, dist = normalize(pos[:, None, :] - samples[None, :, :])
    dist = dist - p.agent_radius
    near = dist < p.obstacle_threshold + p.agent_radius
    weight = np.where(near, np.exp(-np.where(near, dist, 0.0) / p.obstacle_sigma), 0.0)
    return p.obstacle_factor * np.sum(weight[..., None] * direction, axis=1)


def group_forces(
    pos: FloatArray, goal: FloatArray, group_id: NDArray[np.int64], p: SocialForceParams
) -> FloatArray:
    """Coherence + member repulsion + gaze for humans with ``group_id >= 0`` (-1: alone)."""
    k = pos.shape[0]
    force = np.zeros((k, 2))
    member = group_id >= 0
    if not np.any(member):
        return force
    n_groups = int(group_id.max()) + 1
    onehot = (group_id[None, :] == np.arange(n_groups)[:, None]).astype(float)  # (g, k)
    size = onehot.sum(axis=1)
    gsum = onehot @ pos  # (g, 2)
    gid = np.where(member, group_id, 0)
    my_size = np.where(member, size[gid], 1.0)

    # Coherence: pull to the centre of mass, softened by tanh around (size - 1) / 2.
    to_com = gsum[gid] / my_size[:, None] - pos
    com_dist_now = np.zeros(k) if p.pysocialforce_compat else np.linalg.norm(to_com, axis=1)
    soft = (np.tanh(com_dist_now - (my_size - 1) / 2) + 1) / 2
    coherence = np.where(member[:, None], to_com * soft[:, None], 0.0)

    # Repulsion between members closer than the threshold.
    rel = pos[:, None, :] - pos[None, :, :]
    same = (group_id[:, None] == group_id[None, :]) & member[:, None] & ~np.eye(k, dtype=bool)
    close = same & (np.linalg.norm(rel, axis=-1) <= p.group_repulsive_threshold)
    repulsion = np.sum(np.where(close[..., None], rel, 0.0), axis=1)

    # Gaze: keep the other members' centre of mass in view.
    big = member & (my_size > 1)
    rel_com = (gsum[gid] - pos) / np.maximum(my_size - 1, 1)[:, None] - pos
    com_dir, com_dist = normalize(rel_com)
    goal_dir, goal_dist = normalize(goal - pos)
    cos_angle = np.sum(goal_dir * com_dir, axis=1)
    gaze_mag = com_dist * cos_angle / np.maximum(goal_dist, _EPS)
    gaze = np.where(big[:, None], gaze_mag[:, None] * goal_dir, 0.0)

    force += p.group_coherence_factor * coherence
    force += p.group_repulsive_factor * repulsion
    force += p.group_gaze_factor * gaze
    return force
