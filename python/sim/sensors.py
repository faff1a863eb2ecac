"""What the robot's obstacle sensor returns: occupied points near it.

A planner stack hands its local planner obstacles as points (a laser scan's returns, a costmap's
occupied cells). The simulated sensor returns the static obstacles' boundary, sampled every
``1 / resolution`` metres, within ``max_range`` of the robot, the nearest first, at most
``max_points`` of them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .world import World

FloatArray = NDArray[np.float64]


class ObstacleSensor:
    """Boundary points of ``world`` within range (samples made once per world)."""

    def __init__(self, world: World, max_points: int, max_range: float = 5.0, resolution: float = 20.0) -> None:
        if max_points < 1 or not max_range > 0 or not resolution > 0:
            raise ValueError(f"ObstacleSensor needs max_points >= 1, max_range > 0 and resolution > 0 [1/m], got "
                             f"{max_points}, {max_range}, {resolution}")
        self.world = world
        self.max_points = max_points
        self.max_range = max_range
        self._samples = world.boundary_samples(resolution) if not world.is_empty else np.zeros((0, 2))

    def points(self, position: ArrayLike) -> FloatArray:
        """The sensed points (m, 2), nearest first, m <= max_points."""
        if not len(self._samples):
            return np.zeros((0, 2))
        p = np.asarray(position, dtype=float).reshape(2)
        d = np.linalg.norm(self._samples - p, axis=1)
        near = np.flatnonzero(d <= self.max_range)
        if len(near) > self.max_points:
            near = near[np.argpartition(d[near], self.max_points - 1)[: self.max_points]]
        return self._samples[near[np.argsort(d[near])]]
