"""The simulated robot: the unicycle (humanmpc.sim.unicycle) with the limits a real base enforces.

The simulator integrates with RK4 substeps and enforces the limits the real base would: the control
is clipped to the box, and v is kept in ``[v_min, v_max]`` by integrating up to the moment the bound
is hit (the wheel controller saturates, it does not overshoot).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .unicycle import integrate as integrate
from .unicycle import velocity_vector as velocity_vector
from .unicycle import wrap_angle as wrap_angle

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class RobotLimits:
    """Box limits of the unicycle (defaults: the project's MPC defaults)."""

    v_min: float = 0.0
    v_max: float = 1.0
    a_min: float = -1.0
    a_max: float = 1.0
    omega_min: float = -1.5
    omega_max: float = 1.5

    def __post_init__(self) -> None:
        for lo, hi in (("v_min", "v_max"), ("a_min", "a_max"), ("omega_min", "omega_max")):
            if not getattr(self, lo) <= getattr(self, hi):
                raise ValueError(f"RobotLimits: {lo} must be <= {hi}, got {self}")
        if not self.a_min <= 0.0 <= self.a_max:
            raise ValueError("RobotLimits: the acceleration range must contain 0 (to be able to hold a speed)")

    def clip_control(self, u: ArrayLike) -> FloatArray:
        u = np.asarray(u, dtype=float)
        return np.stack(
            [np.clip(u[..., 0], self.a_min, self.a_max), np.clip(u[..., 1], self.omega_min, self.omega_max)], axis=-1
        )


@dataclass(frozen=True)
class RobotModel:
    """Unicycle with limits, footprint radius and the radius assumed for humans in metrics."""

    limits: RobotLimits = RobotLimits()
    radius: float = 0.2
    human_radius: float = 0.25
    substeps: int = 4

    def __post_init__(self) -> None:
        if self.radius <= 0 or self.human_radius <= 0 or self.substeps < 1:
            raise ValueError("RobotModel: radii must be > 0 and substeps >= 1")


def step(model: RobotModel, x: ArrayLike, u: ArrayLike, dt: float) -> FloatArray:
    """Apply ``u`` (clipped to the limits) for ``dt`` from state ``x`` and return the next state.

    If the speed would leave ``[v_min, v_max]`` within the period, the acceleration is applied
    only until the bound is reached and the rest of the period is driven at the bound.
    """
    x = np.asarray(x, dtype=float).reshape(4)
    u_in = np.asarray(u, dtype=float).reshape(2)
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(u_in))):
        raise ValueError(f"robot.step: non-finite state {x} or control {u_in}")
    u = model.limits.clip_control(u_in)
    lim = model.limits
    v0 = float(np.clip(x[3], lim.v_min, lim.v_max))
    x = np.array([x[0], x[1], x[2], v0])
    a = u[0]
    t_sat = dt
    if a > 0 and v0 + a * dt > lim.v_max:
        t_sat = (lim.v_max - v0) / a
    elif a < 0 and v0 + a * dt < lim.v_min:
        t_sat = (lim.v_min - v0) / a
    if t_sat < dt:
        if t_sat > 0:
            x = integrate(x, u, t_sat, model.substeps)
        x[3] = lim.v_max if a > 0 else lim.v_min
        x = integrate(x, np.array([0.0, u[1]]), dt - t_sat, model.substeps)
    else:
        x = integrate(x, u, dt, model.substeps)
    x[2] = wrap_angle(x[2])
    return x
