"""The unicycle of the MPC in numpy: the one Python model of the robot, for the simulation and the benches.

State ``x = [px, py, theta, v]``, control ``u = [a, omega]`` held constant over an interval;
``px' = v cos theta, py' = v sin theta, theta' = omega, v' = a``. The OCP's own model is the CasADi
one (humanmpc.codegen.ocp: RK4, the generated C); :func:`integrate` is the same scheme in numpy, and
:func:`euler` the benches' plant (explicit Euler substeps, a plant that is not the OCP's model).
No limits here: humanmpc.sim.robot adds those of a real base.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


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


def euler(x: FloatArray, u: FloatArray, dt: float, substeps: int = 10) -> FloatArray:
    """Explicit Euler over dt in ``substeps`` equal substeps, u held constant (vectorised)."""
    h = dt / substeps
    for _ in range(substeps):
        x = x + h * unicycle_rhs(x, u)
    return x


def wrap_angle(angle: ArrayLike) -> FloatArray:
    """Angle(s) wrapped into (-pi, pi]."""
    return np.pi - np.mod(np.pi - np.asarray(angle, dtype=float), 2 * np.pi)


def velocity_vector(x: ArrayLike) -> FloatArray:
    """World-frame velocity (vx, vy) of a state."""
    x = np.asarray(x, dtype=float)
    return np.stack([x[..., 3] * np.cos(x[..., 2]), x[..., 3] * np.sin(x[..., 2])], axis=-1)
