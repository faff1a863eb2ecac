"""Human motion prediction from observed positions.

A :class:`Predictor` is fed the humans' *observed* positions once per control step and returns
their predicted positions at the MPC's nodes, ``(N + 1, k, 2)`` with node 0 the current
observation. It never sees the simulator's velocities.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


@runtime_checkable
class Predictor(Protocol):
    """Turns a stream of observations into predictions at the horizon's nodes."""

    horizon: int
    dt: float

    def reset(self) -> None:
        """Forget every past observation (new episode)."""

    def observe(self, time: float, positions: ArrayLike) -> FloatArray:
        """Record the humans' positions (k, 2) seen at ``time`` and return the prediction
        (horizon + 1, k, 2)."""
        ...


class ConstantVelocityPredictor:
    """Constant velocity model (Schöller et al. 2020).

    The velocity is the finite difference of the last two observations (averaged over the
    last ``window`` intervals if ``window > 1``); with a single observation the humans are
    predicted to stand still. The number of humans must not change within an episode.
    """

    def __init__(self, horizon: int = 50, dt: float = 0.1, window: int = 1) -> None:
        if horizon < 1 or dt <= 0 or window < 1:
            raise ValueError("ConstantVelocityPredictor needs horizon >= 1, dt > 0 and window >= 1")
        self.horizon = horizon
        self.dt = dt
        self.window = window
        self._times: list[float] = []
        self._positions: list[FloatArray] = []

    def reset(self) -> None:
        self._times.clear()
        self._positions.clear()

    def observe(self, time: float, positions: ArrayLike) -> FloatArray:
        pos = np.asarray(positions, dtype=float)
        if pos.ndim != 2 or pos.shape[1] != 2:
            raise ValueError(f"observe: positions must have shape (k, 2), got {pos.shape}")
        if self._positions and pos.shape != self._positions[-1].shape:
            raise ValueError(
                f"observe: the number of humans changed from {self._positions[-1].shape[0]} to {pos.shape[0]}; "
                "call reset() between episodes"
            )
        if self._times and time <= self._times[-1]:
            raise ValueError(f"observe: time must increase, got {time} after {self._times[-1]}")
        self._times.append(float(time))
        self._positions.append(pos.copy())
        keep = self.window + 1
        del self._times[:-keep]
        del self._positions[:-keep]
        return self.predict()

    def velocities(self) -> FloatArray:
        """Estimated velocities (k, 2) from the stored observations."""
        if len(self._positions) < 2:
            return np.zeros_like(self._positions[-1]) if self._positions else np.zeros((0, 2))
        span = self._times[-1] - self._times[0]
        return (self._positions[-1] - self._positions[0]) / span

    def predict(self) -> FloatArray:
        if not self._positions:
            raise RuntimeError("predict: no observation yet; call observe() first")
        t = self.dt * np.arange(self.horizon + 1)
        return self._positions[-1][None, :, :] + t[:, None, None] * self.velocities()[None, :, :]
