"""Global path on an inflated grid (A*), the role NavFn plays for nav2's DWB.

The grid covers the world's bounds. A cell is lethal if a robot centred there would touch an
obstacle (or a human given as an obstacle); near obstacles a costmap-style inflation cost
``weight * exp(-scaling * clearance)`` (nav2's ``cost_scaling_factor``) is added to the
travel cost, so paths keep some distance where they can.
"""

from __future__ import annotations

import heapq
import itertools
import time as _time
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..sim.world import World

FloatArray = NDArray[np.float64]

_NEIGHBOURS = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]


@dataclass(frozen=True)
class GridConfig:
    """Grid resolution (m) and inflation of the path search."""

    resolution: float = 0.2
    inflation_radius: float = 0.55
    cost_scaling: float = 3.0
    cost_weight: float = 3.0

    def __post_init__(self) -> None:
        if self.resolution <= 0 or self.inflation_radius < 0 or self.cost_scaling < 0 or self.cost_weight < 0:
            raise ValueError(f"GridConfig: invalid values {self}")


def clearance_grid(
    world: World,
    robot_radius: float,
    humans: FloatArray | None,
    human_radius: float,
    config: GridConfig,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Clearance (m) of a robot centred on each cell (ny, nx), and the cell centre axes."""
    xmin, xmax, ymin, ymax = world.bounds
    xs = np.arange(xmin + config.resolution / 2, xmax, config.resolution)
    ys = np.arange(ymin + config.resolution / 2, ymax, config.resolution)
    gx, gy = np.meshgrid(xs, ys)
    pts = np.stack([gx, gy], axis=-1)
    clear = world.signed_distance(pts) - robot_radius
    if humans is not None and len(humans):
        d = np.linalg.norm(pts[:, :, None, :] - np.asarray(humans)[None, None], axis=-1).min(axis=-1)
        clear = np.minimum(clear, d - robot_radius - human_radius)
    return clear, xs, ys


def plan_path(
    world: World,
    start: ArrayLike,
    goal: ArrayLike,
    robot_radius: float,
    humans: ArrayLike | None = None,
    human_radius: float = 0.25,
    config: GridConfig | None = None,
) -> FloatArray:
    """Shortest inflated-cost path from start to goal as an (M, 2) polyline, start and goal
    included, points about ``resolution`` apart. Falls back to the straight segment when the
    goal is unreachable on the grid (the local planner then does what it can)."""
    cfg = config or GridConfig()
    s = np.asarray(start, dtype=float).reshape(2)
    g = np.asarray(goal, dtype=float).reshape(2)
    hum = None if humans is None else np.asarray(humans, dtype=float).reshape(-1, 2)
    clear, xs, ys = clearance_grid(world, robot_radius, hum, human_radius, cfg)
    ny, nx = clear.shape
    lethal = clear < 0.0
    inflation = cfg.cost_weight * np.exp(-cfg.cost_scaling * np.maximum(clear, 0))
    extra = np.where(clear < cfg.inflation_radius, inflation, 0)

    def cell(p: FloatArray) -> tuple[int, int]:
        i = int(np.clip(np.floor((p[1] - ys[0]) / cfg.resolution + 0.5), 0, ny - 1))
        j = int(np.clip(np.floor((p[0] - xs[0]) / cfg.resolution + 0.5), 0, nx - 1))
        return i, j

    s_cell, g_cell = cell(s), cell(g)
    # The robot may start (or the goal may lie) inside an inflated region: never block those.
    lethal[s_cell] = False
    lethal[g_cell] = False
    cells = _astar(lethal, extra, s_cell, g_cell)
    if cells is None:
        return _densify(np.stack([s, g]), cfg.resolution)
    pts = np.array([[xs[j], ys[i]] for i, j in cells])
    pts = np.vstack([s, pts[1:-1], g]) if len(pts) > 2 else np.stack([s, g])
    return _densify(pts, cfg.resolution)


def _astar(
    lethal: NDArray[np.bool_], extra: FloatArray, start: tuple[int, int], goal: tuple[int, int]
) -> list[tuple[int, int]] | None:
    ny, nx = lethal.shape
    best = np.full((ny, nx), np.inf)
    parent: dict[tuple[int, int], tuple[int, int]] = {}
    best[start] = 0.0
    gi, gj = goal
    heap: list[tuple[float, float, tuple[int, int]]] = [(0.0, 0.0, start)]
    while heap:
        _, cost, node = heapq.heappop(heap)
        if node == goal:
            path = [node]
            while node in parent:
                node = parent[node]
                path.append(node)
            return path[::-1]
        if cost > best[node]:
            continue
        i, j = node
        for di, dj in _NEIGHBOURS:
            ni, nj = i + di, j + dj
            if not (0 <= ni < ny and 0 <= nj < nx) or lethal[ni, nj]:
                continue
            step = (1.4142135623730951 if di and dj else 1.0) * (1.0 + 0.5 * (extra[i, j] + extra[ni, nj]))
            new = cost + step
            if new < best[ni, nj]:
                best[ni, nj] = new
                parent[(ni, nj)] = node
                h = float(np.hypot(ni - gi, nj - gj))
                heapq.heappush(heap, (new + h, new, (ni, nj)))
    return None


def _densify(pts: FloatArray, spacing: float) -> FloatArray:
    out = [pts[0]]
    for a, b in itertools.pairwise(pts):
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / spacing)))
        t = np.arange(1, n + 1) / n
        out.extend(a + t[:, None] * (b - a))
    return np.array(out)


def path_length(path: FloatArray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))


def local_segment(path: FloatArray, position: ArrayLike, lookahead: float) -> FloatArray:
    """The part of ``path`` from the point closest to ``position`` up to ``lookahead`` metres
    further along it (at least two points); its last point is the local goal (carrot)."""
    p = np.asarray(position, dtype=float).reshape(2)
    i0 = int(np.argmin(np.linalg.norm(path - p, axis=1)))
    seg = path[i0:]
    if len(seg) < 2:
        return np.vstack([path[-1], path[-1]])
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(seg, axis=0), axis=1))])
    end = int(np.searchsorted(cum, lookahead, side="right"))
    return seg[: max(2, end)]


class GlobalPlanner:
    """The global planner every local planner of the evaluation shares (nav2's planner server feeding
    its controller): an A* path from the robot to the goal, replanned every ``replan_period`` seconds
    and whenever the goal changes, with the humans' current positions as obstacles when they are given
    (the DWB gives them: nav2's default behaviour tree replans at 1 Hz on a costmap whose obstacle layer
    sees the people; the MPC does not: its OCP has their predictions)."""

    def __init__(self, grid: GridConfig | None = None, replan_period: float = 1.0) -> None:
        if not replan_period > 0:
            raise ValueError(f"GlobalPlanner: replan_period must be > 0, got {replan_period}")
        self.grid = grid or GridConfig()
        self.replan_period = replan_period
        self.reset()

    def reset(self) -> None:
        self._path: FloatArray | None = None
        self._goal: FloatArray | None = None
        self._planned_at = -np.inf

    @property
    def path(self) -> FloatArray | None:
        return None if self._path is None else self._path.copy()

    def update(
        self, time: float, world: World, position: ArrayLike, goal: ArrayLike, robot_radius: float,
        humans: ArrayLike | None, human_radius: float,
    ) -> float:
        """Replan if the path is stale or the goal moved; returns the time spent planning (ms)."""
        goal_xy = np.asarray(goal, dtype=float).reshape(-1)[:2]
        stale = time - self._planned_at >= self.replan_period - 1e-9
        if self._path is None or self._goal is None or stale or not np.array_equal(goal_xy, self._goal):
            t0 = _time.perf_counter()
            self._path = plan_path(world, position, goal_xy, robot_radius, humans, human_radius, self.grid)
            self._goal = goal_xy
            self._planned_at = time
            return (_time.perf_counter() - t0) * 1e3
        return 0.0
