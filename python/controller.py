"""The navigation controller of a loaded package: ``humanmpc.load(DIR).controller()``.

A thin face over the generated C controller (``<name>_controller_step``): per control period it
copies the robot's odometry, its path or goal, the tracked people and the obstacle points into the C
input struct, makes one C call and returns the output as a :class:`ControllerResult`. Everything the
controller decides (the carrot, the people it hands the OCP, the approach, the speed limit, loop and
stall recovery, braking at the goal) is the C's; firmware and the ROS node run the same code.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .codegen.params import Param
from .results import ControllerResult, c_array_view, record_dtype
from .runtime_params import RuntimeParams

# The most tracks one step takes before the nearest max_tracks are kept (a bound on the copy, not on
# the controller: a tracker reporting more than this is broken).
MAX_TRACKS_GIVEN = 100_000


def _points(what: str, value: ArrayLike | None, columns: int, capacity: int, key: str) -> np.ndarray:
    """value as an (n, columns) float64 array with n <= capacity (an empty one for None)."""
    if value is None:
        return np.zeros((0, columns))
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != columns:
        raise ValueError(f"{what} must have shape (n, {columns}), got {arr.shape}")
    if arr.shape[0] > capacity:
        raise ValueError(f"{what} holds {arr.shape[0]} rows, but this controller takes at most {capacity} "
                         f"(the spec's {key}): regenerate with a larger {key}, or thin them out")
    return arr


class Controller:
    """A generated navigation controller (C memory owned by this object)."""

    def __init__(self, name: str, dims: Any, ffi: Any, lib: Any, params_table: tuple[Param, ...]) -> None:
        fn = lambda suffix: getattr(lib, f"{name}_{suffix}")  # noqa: E731
        self.name = name
        self.dims = dims
        self._ffi = ffi
        self._lib = lib
        self.memsize = int(fn("controller_memsize")())
        sizes = ffi.new("size_t[3]")
        fn("controller_struct_sizes")(sizes + 0, sizes + 1, sizes + 2)
        declared = [ffi.sizeof(f"{name}_controller_{s}") for s in ("params", "input", "output")]
        if list(sizes) != declared:
            raise ValueError(f"{name}_cffi.h declares the controller's params/input/output as {declared} bytes, the "
                             f"library was compiled with {list(sizes)}: regenerate and rebuild the package")
        self._mem = ffi.new("char[]", self.memsize)
        self._ctl = fn("controller_create")(self._mem)
        self._c_step = fn("controller_step")
        self._c_set_tracks = fn("controller_set_tracks")
        self._c_reset = fn("controller_reset")
        self._lock = threading.Lock()
        # the controller's own parameters and its solver's, set and read by name alike
        solver_rows = [p for p in params_table if not p.controller]
        own_rows = [p for p in params_table if p.controller]
        self._params = RuntimeParams(ffi, lib, (
            (f"{name}_params", fn("controller_solver_params")(self._ctl), solver_rows),
            (f"{name}_controller_params", fn("controller_own_params")(self._ctl), own_rows),
        ), self._lock)
        self._in = ffi.new(f"{name}_controller_input *")
        self._out = ffi.new(f"{name}_controller_output *")
        self._out_buffer = ffi.buffer(self._out)
        self._out_dtype = record_dtype(ffi, f"{name}_controller_output")
        self.dtype = np.dtype(np.float32 if ffi.sizeof(f"{name}_real") == 4 else np.float64)
        c = self._in
        self.max_tracks = len(c.track_ids)
        self.max_path_points = len(c.path)
        self.max_obstacle_points = len(c.obstacles)

        rt = self.dtype
        self._pose = c_array_view(ffi, c.pose, (3,), rt)
        self._goal = c_array_view(ffi, c.goal, (3,), rt)
        self._path = c_array_view(ffi, c.path, (self.max_path_points, 2), rt)
        self._tracks = c_array_view(ffi, c.tracks, (self.max_tracks, 4), rt)
        self._ids = c_array_view(ffi, c.track_ids, (self.max_tracks,), np.int32)
        self._has_cov = c_array_view(ffi, c.track_has_covariance, (self.max_tracks,), np.int32)
        self._cov = c_array_view(ffi, c.track_covariances, (self.max_tracks, 3), rt)
        self._obstacles = c_array_view(ffi, c.obstacles, (self.max_obstacle_points, 2), rt)

    # -- parameters ---------------------------------------------------------------------------
    @property
    def params(self) -> dict[str, Any]:
        """The runtime parameters now in force, by name: the solver's (``<name>_params``) and the controller's
        own (``<name>_controller_params``)."""
        return self._params.values

    def set_params(self, **values: Any) -> None:
        """Change runtime parameters by name, the solver's and the controller's alike (checked by their rules;
        on any error nothing changes in either)."""
        self._params.set(**values)

    def reset(self) -> None:
        """A new episode: a cold solver and no progress history; the parameters are kept."""
        with self._lock:
            self._c_reset(self._ctl)

    # -- one control period -------------------------------------------------------------------
    def step(self, t: float, pose: ArrayLike, v: float, omega: float = 0.0, *, path: ArrayLike | None = None,
             goal: ArrayLike | None = None, people: ArrayLike | None = None, ids: ArrayLike | None = None,
             covariances: ArrayLike | None = None, obstacles: ArrayLike | None = None) -> ControllerResult:
        """One control period.

        t: time stamp [s]; pose: (x, y, theta) [m, m, rad]; v [m/s], omega [rad/s]: odometry;
        path: (n, 2) waypoints to the goal, and/or goal: (x, y, theta), the final pose (alone: a straight
        path; with a path: its final heading); people: (k, 4) tracks [x, y, vx, vy] [m, m/s] with
        optional ids (k,) (default 0..k-1) and covariances (k, 3) [sxx, sxy, syy] [m^2] (NaN rows: none);
        more than max_tracks people: the nearest max_tracks are kept (the C's <name>_controller_set_tracks,
        as in every face) and the result's n_tracks_dropped says how many were left out;
        obstacles: (m, 2) occupied points [m]. All in one world frame.
        """
        pose_a = np.asarray(pose, dtype=np.float64)
        if pose_a.shape != (3,):
            raise ValueError(f"pose must be (x, y, theta), got shape {pose_a.shape}")
        P = _points("path", path, 2, self.max_path_points, "controller.max_path_points")
        Q = _points("people", people, 4, MAX_TRACKS_GIVEN, "people given to one step")
        K = _points("obstacles", obstacles, 2, self.max_obstacle_points, "controller.max_obstacle_points")
        k = Q.shape[0]
        if ids is None:
            id_a = np.arange(k, dtype=np.int64)
        else:
            id_a = np.asarray(ids)
            if id_a.shape != (k,) or not np.issubdtype(id_a.dtype, np.integer):
                raise ValueError(f"ids must be {k} integers (one per person), got {id_a!r}")
            if k and (id_a.min() < -2**31 or id_a.max() >= 2**31):
                raise ValueError("ids must fit in 32 bits")
        cov = None
        if covariances is not None:
            cov = np.asarray(covariances, dtype=np.float64)
            if cov.shape != (k, 3):
                raise ValueError(f"covariances must have shape ({k}, 3) = [sxx, sxy, syy] per person, got {cov.shape}")
        if goal is not None:
            goal_a = np.asarray(goal, dtype=np.float64)
            if goal_a.shape != (3,):
                raise ValueError(f"goal must be (x, y, theta), got shape {goal_a.shape}")
        with self._lock:
            c = self._in
            c.time = float(t)
            self._pose[...] = pose_a
            c.v = float(v)
            c.omega = float(omega)
            c.n_path = P.shape[0]
            self._path[: P.shape[0]] = P
            c.has_goal = int(goal is not None)
            if goal is not None:
                self._goal[...] = goal_a
            self._set_tracks(Q, id_a, cov)
            c.n_obstacles = K.shape[0]
            self._obstacles[: K.shape[0]] = K
            self._c_step(self._ctl, self._in, self._out)
            return ControllerResult(np.ndarray((), self._out_dtype, self._out_buffer[:]))

    def _set_tracks(self, tracks: np.ndarray, ids: np.ndarray, cov: np.ndarray | None) -> None:
        """The input's tracks through the C (the nearest max_tracks of more); the pose must be set."""
        ffi, real = self._ffi, f"{self.name}_real"
        k = tracks.shape[0]
        t = np.ascontiguousarray(tracks, dtype=self.dtype)
        i = np.ascontiguousarray(ids, dtype=np.int32)
        if cov is None:
            c_ptr, h_ptr = ffi.NULL, ffi.NULL
        else:
            given = np.all(np.isfinite(cov), axis=1)
            c = np.ascontiguousarray(np.where(given[:, None], cov, 0.0), dtype=self.dtype)
            h = np.ascontiguousarray(given, dtype=np.int32)
            c_ptr = ffi.cast(f"{real} (*)[3]", ffi.from_buffer(c))
            h_ptr = ffi.cast("int *", ffi.from_buffer(h))
        t_ptr = ffi.cast(f"{real} (*)[4]", ffi.from_buffer(t)) if k else ffi.NULL
        i_ptr = ffi.cast("int *", ffi.from_buffer(i)) if k else ffi.NULL
        if self._c_set_tracks(self._in, k, t_ptr, i_ptr, c_ptr if k else ffi.NULL, h_ptr if k else ffi.NULL) < 0:
            raise RuntimeError(f"{self.name}_controller_set_tracks refused {k} tracks")

    def __repr__(self) -> str:
        return (f"<humanmpc.Controller {self.name!r} N={self.dims.N} nh={self.dims.nh} tracks<={self.max_tracks} "
                f"path<={self.max_path_points} obstacles<={self.max_obstacle_points}>")
