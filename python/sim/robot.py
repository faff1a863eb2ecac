"""The unicycle robot of the MPC and its exact-enough simulation.

State ``x = [px, py, theta, v]``, control ``u = [a, omega]`` held constant over a control
period; ``px' = v cos theta, py' = v sin theta, theta' = omega, v' = a``. The simulator
integrates with RK4 substeps and enforces the limits the real base would: the control is
clipped to the box, and v is kept in ``[v_min, v_max]`` by integrating up to the moment the
bound is hit (the wheel controller saturates, it does not overshoot).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

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


def unicycle_rhs(x: FloatArray, u: FloatArray) -> FloatArray:
    """Time derivative of the state, vectorised over leading axes (u broadcasts against x)."""
    theta, v = x[..., 2], x[..., 3]
    a = np.broadcast_to(u[..., 0], v.shape)
    omega = np.broadcast_to(u[..., 1], v.shape)
    return np.stack([v * np.cos(theta), v * np.sin(theta), omega, a], axis=-1)


def rk4(x: FloatArray, u: FloatArray, h: float) -> FloatArray:
    """One classical Runge-Kutta step of length h with u held constant."""
    k1 = unicycle_rhs(x, u)
    k2 = unicycle_rhs(x + 0.5 * h * k1, u)
    k3 = unicycle_rhs(x + 0.5 * h * k2, u)
    k4 = unicycle_rhs(x + h * k3, u)
    return x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


def integrate(x: FloatArray, u: FloatArray, dt: float, substeps: int = 4) -> FloatArray:
    """Unconstrained RK4 over dt (vectorised), ``substeps`` equal substeps."""
    h = dt / substeps
    for _ in range(substeps):
        x = rk4(x, u, h)
    return x


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


def wrap_angle(angle: ArrayLike) -> FloatArray:
    """Angle(s) wrapped into (-pi, pi]."""
    return np.pi - np.mod(np.pi - np.asarray(angle, dtype=float), 2 * np.pi)


def velocity_vector(x: ArrayLike) -> FloatArray:
    """World-frame velocity (vx, vy) of a state."""
    x = np.asarray(x, dtype=float)
    return np.stack([x[..., 3] * np.cos(x[..., 2]), x[..., 3] * np.sin(x[..., 2])], axis=-1)
