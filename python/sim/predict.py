"""People as tracks, and their motion predicted from them.

A :class:`Tracker` is fed the humans' *observed* positions once per control step and returns their
tracks: the velocity it estimates for each person, ``(k, 2)``, in the order of the observation. It
never sees the simulator's velocities. The evaluation hands planners tracks (positions, velocities,
ids), not predicted paths: the MPC planner's controller predicts in C, once; a planner that wants
predicted paths calls :func:`predict_constant_velocity` (or a :class:`Predictor`) itself.

The people observed may change from one step to the next (recorded crowds: people enter and
leave the scene). An observation then carries their ids, ``(k,)`` integers that name the same
person across steps; a person's velocity comes from that person's own observations only.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


@runtime_checkable
class Tracker(Protocol):
    """Turns a stream of observed positions into the people's velocities."""

    def reset(self) -> None:
        """Forget every past observation (new episode)."""

    def observe(self, time: float, positions: ArrayLike, ids: ArrayLike | None = None) -> FloatArray:
        """Record the humans' positions (k, 2) seen at ``time`` (with their ids (k,), if the people
        present may change) and return their velocities (k, 2) [m/s], in the observation's order."""
        ...


@runtime_checkable
class Predictor(Protocol):
    """Turns a stream of observations into predictions at the horizon's nodes."""

    horizon: int
    dt: float

    def reset(self) -> None:
        """Forget every past observation (new episode)."""

    def observe(self, time: float, positions: ArrayLike, ids: ArrayLike | None = None) -> FloatArray:
        """Record the humans' positions (k, 2) seen at ``time`` (with their ids (k,), if the
        people present may change) and return the prediction (horizon + 1, k, 2)."""
        ...


def predict_constant_velocity(positions: ArrayLike, velocities: ArrayLike, horizon: int, dt: float) -> FloatArray:
    """Tracks' positions (k, 2) and velocities (k, 2) walked on at constant velocity: their positions at
    the nodes 0..horizon, ``dt`` apart, (horizon + 1, k, 2) (node 0: the positions)."""
    now = np.asarray(positions, dtype=float).reshape(-1, 2)
    vel = np.asarray(velocities, dtype=float).reshape(-1, 2)
    if vel.shape != now.shape:
        raise ValueError(f"predict_constant_velocity: {now.shape[0]} positions but {vel.shape[0]} velocities")
    t = dt * np.arange(horizon + 1)
    return now[None, :, :] + t[:, None, None] * vel[None, :, :]


class ConstantVelocityTracker:
    """Velocities by finite differences (the constant velocity model, Schöller et al. 2020).

    A person's velocity is the finite difference of their last two observations (over the last
    ``window`` intervals if ``window > 1``, or as many as they have); with a single observation
    a person stands still.

    Without ids the people are the same ones, in the same order, at every step, and their number
    must not change within an episode. With ids, people may appear and disappear: a person not
    in an observation is forgotten (if the same id comes back, it starts again from one
    observation), and a new id starts with one.
    """

    def __init__(self, window: int = 1) -> None:
        if window < 1:
            raise ValueError("ConstantVelocityTracker needs window >= 1")
        self.window = window
        self._last_time: float | None = None
        self._count: int | None = None  # people of the id-less stream
        self._ids = np.zeros(0, dtype=np.int64)  # of the last observation, in its order
        self._history: dict[int, list[tuple[float, FloatArray]]] = {}  # id -> its last window + 1 observations

    def reset(self) -> None:
        self._last_time = None
        self._count = None
        self._ids = np.zeros(0, dtype=np.int64)
        self._history.clear()

    def observe(self, time: float, positions: ArrayLike, ids: ArrayLike | None = None) -> FloatArray:
        pos = np.asarray(positions, dtype=float)
        if pos.ndim != 2 or pos.shape[1] != 2:
            raise ValueError(f"observe: positions must have shape (k, 2), got {pos.shape}")
        if ids is None:
            if self._count is not None and pos.shape[0] != self._count:
                raise ValueError(
                    f"observe: the number of humans changed from {self._count} to {pos.shape[0]}; "
                    "call reset() between episodes, or pass the people's ids if the crowd changes"
                )
            self._count = pos.shape[0]
            who = np.arange(pos.shape[0], dtype=np.int64)
        else:
            who = np.asarray(ids).reshape(-1)
            if who.shape[0] != pos.shape[0] or not np.issubdtype(who.dtype, np.integer):
                raise ValueError(f"observe: ids must be {pos.shape[0]} integers (one per position), got {who!r}")
            if np.unique(who).size != who.size:
                raise ValueError(f"observe: ids must be distinct, got {who.tolist()}")
            who = who.astype(np.int64)
        if self._last_time is not None and time <= self._last_time:
            raise ValueError(f"observe: time must increase, got {time} after {self._last_time}")
        self._last_time = float(time)
        keep = self.window + 1
        history: dict[int, list[tuple[float, FloatArray]]] = {}
        for i, p in zip(who.tolist(), pos, strict=True):
            past = self._history.get(i, [])
            history[i] = [*past[-(keep - 1):], (float(time), p.copy())]  # keep >= 2
        self._history = history
        self._ids = who
        return self.velocities()

    @property
    def observed(self) -> bool:
        """True once observe() was called (since the last reset)."""
        return self._last_time is not None

    @property
    def ids(self) -> NDArray[np.int64]:
        """The ids of the last observation, in its order."""
        return self._ids

    def positions(self) -> FloatArray:
        """The last observed positions (k, 2), in its order."""
        if self._last_time is None:
            raise RuntimeError("positions: no observation yet; call observe() first")
        return np.array([self._history[i][-1][1] for i in self._ids.tolist()]).reshape(-1, 2)

    def velocities(self) -> FloatArray:
        """Estimated velocities (k, 2) of the people of the last observation, in its order."""
        out = np.zeros((self._ids.size, 2))
        for j, i in enumerate(self._ids.tolist()):
            obs = self._history[i]
            if len(obs) >= 2:
                (t_old, p_old), (t_new, p_new) = obs[0], obs[-1]
                out[j] = (p_new - p_old) / (t_new - t_old)
        return out


class ConstantVelocityPredictor:
    """Predicted paths for planners that want them: a :class:`ConstantVelocityTracker`'s tracks walked on
    at constant velocity over ``horizon`` intervals of ``dt`` (:func:`predict_constant_velocity`)."""

    def __init__(self, horizon: int = 50, dt: float = 0.1, window: int = 1) -> None:
        if horizon < 1 or dt <= 0 or window < 1:
            raise ValueError("ConstantVelocityPredictor needs horizon >= 1, dt > 0 and window >= 1")
        self.horizon = horizon
        self.dt = dt
        self.tracker = ConstantVelocityTracker(window)

    @property
    def window(self) -> int:
        return self.tracker.window

    def reset(self) -> None:
        self.tracker.reset()

    def observe(self, time: float, positions: ArrayLike, ids: ArrayLike | None = None) -> FloatArray:
        self.tracker.observe(time, positions, ids)
        return self.predict()

    def velocities(self) -> FloatArray:
        """Estimated velocities (k, 2) of the people of the last observation, in its order."""
        return self.tracker.velocities()

    def predict(self) -> FloatArray:
        if not self.tracker.observed:
            raise RuntimeError("predict: no observation yet; call observe() first")
        return predict_constant_velocity(self.tracker.positions(), self.tracker.velocities(), self.horizon, self.dt)
