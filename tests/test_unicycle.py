"""One unicycle model in Python (humanmpc.sim.unicycle), for the simulation and the benches, with the
numbers of the models it replaced."""

from __future__ import annotations

import numpy as np

from humanmpc.sim import robot, unicycle


def _old_bench_euler(x: np.ndarray, u: np.ndarray, dt: float, substeps: int = 10) -> np.ndarray:
    """The benches' plant as compare/bench.py wrote it before the model was shared."""
    h = dt / substeps
    for _ in range(substeps):
        x = x + h * np.array([x[3] * np.cos(x[2]), x[3] * np.sin(x[2]), u[1], u[0]])
    return x


def _old_rk4_step(x: np.ndarray, u: np.ndarray, h: float) -> np.ndarray:
    def f(z: np.ndarray) -> np.ndarray:
        return np.array([z[3] * np.cos(z[2]), z[3] * np.sin(z[2]), u[1], u[0]])

    k1 = f(x)
    k2 = f(x + 0.5 * h * k1)
    k3 = f(x + 0.5 * h * k2)
    k4 = f(x + h * k3)
    return x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


def test_the_benches_euler_plant_takes_the_same_steps_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    for dtype in (np.float64, np.float32):  # a float solver hands float32 commands
        x = np.array([0.3, -1.2, 2.9, 0.7])
        for _ in range(200):
            u = rng.uniform([-1.0, -1.5], [1.0, 1.5]).astype(dtype)
            new, old = unicycle.euler(x, u, 0.1), _old_bench_euler(x, u, 0.1)
            assert new.tobytes() == old.tobytes()
            x = new


def test_the_simulations_rk4_is_the_classical_scheme_of_the_same_dynamics() -> None:
    rng = np.random.default_rng(4)
    x = np.array([1.0, 2.0, -0.4, 0.5])
    for _ in range(50):
        u = rng.uniform([-1.0, -1.5], [1.0, 1.5])
        h = 0.025
        expected = x
        for _ in range(4):
            expected = _old_rk4_step(expected, u, h)
        np.testing.assert_allclose(unicycle.integrate(x, u, 0.1, 4), expected, rtol=0, atol=1e-15)
        x = expected


def test_the_robot_module_uses_the_shared_model() -> None:
    assert robot.integrate is unicycle.integrate
    assert robot.wrap_angle is unicycle.wrap_angle and robot.velocity_vector is unicycle.velocity_vector


def test_euler_and_rk4_agree_on_a_straight_line_and_differ_on_a_turn() -> None:
    """Proves the two are distinct schemes of one model: exact alike where the dynamics are linear."""
    x = np.array([0.0, 0.0, 0.0, 1.0])
    straight = np.array([0.0, 0.0])
    np.testing.assert_allclose(unicycle.euler(x, straight, 1.0), unicycle.integrate(x, straight, 1.0), atol=1e-15)
    turn = np.array([0.0, 1.0])
    assert np.max(np.abs(unicycle.euler(x, turn, 1.0) - unicycle.integrate(x, turn, 1.0))) > 1e-3
