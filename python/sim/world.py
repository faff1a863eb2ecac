"""Static obstacles of the evaluation world and geometric queries on them.

A :class:`World` holds circles and simple polygons (convex or not) and a rectangular area
(for plots, scenario sampling and the global path search; it is not a wall). Every query is
vectorised over arbitrarily shaped batches of query points ``(..., 2)``.

Signed distance convention: positive outside every obstacle, negative inside one (the depth to
its boundary). ``nearest_point`` returns the closest point of the *boundary* of the obstacle
that is closest to the query point; it is what the MPC receives as its obstacle parameter.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

_TINY = 1e-12


@dataclass(frozen=True)
class Circle:
    """A disc obstacle."""

    center: tuple[float, float]
    radius: float

    def __post_init__(self) -> None:
        if not (np.all(np.isfinite(self.center)) and np.isfinite(self.radius) and self.radius > 0):
            raise ValueError(f"Circle needs a finite centre and a radius > 0, got {self}")


@dataclass(frozen=True)
class Polygon:
    """A simple polygon obstacle given by its vertices in order (either orientation)."""

    vertices: tuple[tuple[float, float], ...]

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3 or not np.all(np.isfinite(v)):
            raise ValueError("Polygon needs at least 3 finite (x, y) vertices")
        if abs(_shoelace_area(v)) < 1e-9:
            raise ValueError("Polygon has zero area (collinear or repeated vertices)")

    @staticmethod
    def rectangle(center: tuple[float, float], width: float, height: float, angle: float = 0.0) -> Polygon:
        """Rectangle of the given size centred at ``center`` and rotated by ``angle`` (rad)."""
        hw, hh = width / 2.0, height / 2.0
        corners = np.array([[-hw, -hh], [hw, -hh], [hw, hh], [-hw, hh]])
        c, s = np.cos(angle), np.sin(angle)
        rot = np.array([[c, -s], [s, c]])
        pts = corners @ rot.T + np.asarray(center, dtype=float)
        return Polygon(tuple((float(x), float(y)) for x, y in pts))

    @property
    def array(self) -> FloatArray:
        return np.asarray(self.vertices, dtype=float)


Obstacle = Circle | Polygon


def _shoelace_area(v: FloatArray) -> float:
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


@dataclass(frozen=True)
class World:
    """Static obstacles plus the rectangular area ``(xmin, xmax, ymin, ymax)`` of the scene."""

    obstacles: tuple[Obstacle, ...] = ()
    bounds: tuple[float, float, float, float] = (-10.0, 10.0, -10.0, 10.0)
    _circ_c: FloatArray = field(init=False, repr=False, compare=False)
    _circ_r: FloatArray = field(init=False, repr=False, compare=False)
    _seg_a: FloatArray = field(init=False, repr=False, compare=False)
    _seg_b: FloatArray = field(init=False, repr=False, compare=False)
    _seg_poly: NDArray[np.int64] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        xmin, xmax, ymin, ymax = self.bounds
        if not (xmin < xmax and ymin < ymax):
            raise ValueError(f"World bounds must be (xmin, xmax, ymin, ymax) with min < max, got {self.bounds}")
        circles = [o for o in self.obstacles if isinstance(o, Circle)]
        polys = [o for o in self.obstacles if isinstance(o, Polygon)]
        if len(circles) + len(polys) != len(self.obstacles):
            raise TypeError("World obstacles must be Circle or Polygon instances")
        circ_c = np.array([c.center for c in circles], dtype=float).reshape(-1, 2)
        circ_r = np.array([c.radius for c in circles], dtype=float)
        seg_a, seg_b, seg_poly = [], [], []
        for i, p in enumerate(polys):
            v = p.array
            seg_a.append(v)
            seg_b.append(np.roll(v, -1, axis=0))
            seg_poly.append(np.full(len(v), i))
        object.__setattr__(self, "_circ_c", circ_c)
        object.__setattr__(self, "_circ_r", circ_r)
        object.__setattr__(self, "_seg_a", np.concatenate(seg_a) if seg_a else np.zeros((0, 2)))
        object.__setattr__(self, "_seg_b", np.concatenate(seg_b) if seg_b else np.zeros((0, 2)))
        object.__setattr__(
            self, "_seg_poly", np.concatenate(seg_poly).astype(np.int64) if seg_poly else np.zeros(0, np.int64)
        )

    @property
    def circles(self) -> tuple[Circle, ...]:
        return tuple(o for o in self.obstacles if isinstance(o, Circle))

    @property
    def polygons(self) -> tuple[Polygon, ...]:
        return tuple(o for o in self.obstacles if isinstance(o, Polygon))

    @property
    def is_empty(self) -> bool:
        return len(self.obstacles) == 0

    def per_obstacle(self, points: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Signed distance (P, M) and nearest boundary point (P, M, 2) of P points (P, 2) to
        each of the M obstacles (circles first, then polygons)."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        P = pts.shape[0]
        n_c = self._circ_c.shape[0]
        n_p = len(self.polygons)
        dist = np.empty((P, n_c + n_p))
        near = np.empty((P, n_c + n_p, 2))
        if n_c:
            d = pts[:, None, :] - self._circ_c[None, :, :]  # (P, C, 2)
            r = np.linalg.norm(d, axis=-1)
            # At the exact centre every boundary point is nearest: pick the +x one.
            unit = np.where(r[..., None] > _TINY, d / np.maximum(r, _TINY)[..., None], np.array([1.0, 0.0]))
            dist[:, :n_c] = r - self._circ_r[None, :]
            near[:, :n_c] = self._circ_c[None] + self._circ_r[None, :, None] * unit
        if n_p:
            a, b = self._seg_a, self._seg_b  # (S, 2)
            ab = b - a
            ap = pts[:, None, :] - a[None]  # (P, S, 2)
            t = np.clip(np.einsum("psk,sk->ps", ap, ab) / np.einsum("sk,sk->s", ab, ab)[None], 0.0, 1.0)
            proj = a[None] + t[..., None] * ab[None]  # (P, S, 2)
            seg_d = np.linalg.norm(pts[:, None, :] - proj, axis=-1)  # (P, S)
            # Minimum over the segments of each polygon.
            onehot = self._seg_poly[None, :] == np.arange(n_p)[:, None]  # (n_p, S)
            cand = np.where(onehot[None], seg_d[:, None, :], np.inf)  # (P, n_p, S)
            arg = np.argmin(cand, axis=-1)  # (P, n_p)
            unsigned = np.take_along_axis(cand, arg[..., None], axis=2)[..., 0]
            near[:, n_c:] = np.take_along_axis(proj[:, None, :, :], arg[..., None, None], axis=2)[:, :, 0]
            # Even-odd rule: count crossings of a ray towards +x.
            ay, by = a[:, 1][None], b[:, 1][None]
            py = pts[:, 1][:, None]
            straddle = (ay > py) != (by > py)
            with np.errstate(divide="ignore", invalid="ignore"):
                x_cross = a[:, 0][None] + (py - ay) * (b[:, 0] - a[:, 0])[None] / (by - ay)
            crossing = straddle & (pts[:, 0][:, None] < x_cross)
            inside = (crossing.astype(np.int64) @ onehot.T.astype(np.int64)) % 2 == 1  # (P, n_p)
            dist[:, n_c:] = np.where(inside, -unsigned, unsigned)
        return dist, near

    def signed_distance(self, points: ArrayLike) -> FloatArray:
        """Signed distance of each point to the nearest obstacle (``inf`` in an empty world)."""
        pts, shape = _as_points(points)
        if self.is_empty:
            return np.full(shape, np.inf)
        dist, _ = self.per_obstacle(pts)
        return dist.min(axis=1).reshape(shape)

    def nearest_point(self, points: ArrayLike) -> FloatArray:
        """Closest boundary point of the closest obstacle, shape ``(..., 2)``.

        Raises ``ValueError`` in a world without obstacles (there is no such point; callers
        that feed an MPC should use :meth:`obstacle_parameter`).
        """
        pts, shape = _as_points(points)
        if self.is_empty:
            raise ValueError("nearest_point: the world has no obstacles")
        dist, near = self.per_obstacle(pts)
        idx = np.argmin(dist, axis=1)
        return near[np.arange(pts.shape[0]), idx].reshape(*shape, 2)

    def obstacle_parameter(self, point: ArrayLike, far: float = 1e3) -> FloatArray:
        """The obstacle point an MPC should see from ``point``: the nearest obstacle point, or a
        point ``far`` metres away (no effect on a distance constraint) in an empty world."""
        p = np.asarray(point, dtype=float).reshape(2)
        if self.is_empty:
            return p + np.array([far, 0.0])
        return self.nearest_point(p)

    def boundary_samples(self, resolution: float = 10.0) -> FloatArray:
        """Points along every obstacle boundary, about ``resolution`` per metre, shape (M, 2).

        Polygon edges are sampled like pysocialforce samples its line obstacles
        (``linspace(start, end, int(length * resolution))``, both ends included), so the crowd
        model sees the same obstacle points.
        """
        out: list[FloatArray] = []
        for c in self.circles:
            n = max(8, int(np.ceil(2 * np.pi * c.radius * resolution)))
            ang = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
            out.append(np.asarray(c.center) + c.radius * np.stack([np.cos(ang), np.sin(ang)], axis=1))
        for a, b in zip(self._seg_a, self._seg_b, strict=True):
            out.append(sample_segment(a, b, resolution))
        return np.concatenate(out) if out else np.zeros((0, 2))

    def contains_free_disc(self, point: ArrayLike, radius: float) -> bool:
        """True if a disc of ``radius`` at ``point`` is inside the bounds and touches no obstacle."""
        p = np.asarray(point, dtype=float).reshape(2)
        xmin, xmax, ymin, ymax = self.bounds
        if not (xmin + radius <= p[0] <= xmax - radius and ymin + radius <= p[1] <= ymax - radius):
            return False
        return bool(self.signed_distance(p) > radius)


def sample_segment(a: ArrayLike, b: ArrayLike, resolution: float) -> FloatArray:
    """pysocialforce's line sampling: ``int(length * resolution)`` points from a to b inclusive."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    n = int(np.linalg.norm(b - a) * resolution)
    return np.stack([np.linspace(a[0], b[0], n), np.linspace(a[1], b[1], n)], axis=1)


def _as_points(points: ArrayLike) -> tuple[FloatArray, tuple[int, ...]]:
    arr = np.asarray(points, dtype=float)
    if arr.shape[-1:] != (2,):
        raise ValueError(f"points must have shape (..., 2), got {arr.shape}")
    return arr.reshape(-1, 2), arr.shape[:-1]


def make_world(obstacles: Sequence[Obstacle], bounds: tuple[float, float, float, float]) -> World:
    """Convenience constructor accepting any sequence of obstacles."""
    return World(tuple(obstacles), bounds)
