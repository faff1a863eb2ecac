"""Unicycle robot simulation."""

from __future__ import annotations

import numpy as np
import pytest

from humanmpc.sim.robot import RobotLimits, RobotModel, step

MODEL = RobotModel()


def test_constant_turn_matches_the_closed_form_arc() -> None:
    x = np.array([0.0, 0.0, 0.0, 0.8])
    for _ in range(20):
        x = step(MODEL, x, [0.0, 0.5], 0.1)
    r, th = 0.8 / 0.5, 0.5 * 2.0
    np.testing.assert_allclose(x[:2], [r * np.sin(th), r * (1 - np.cos(th))], atol=1e-8)
    assert x[2] == pytest.approx(th)


def test_acceleration_from_rest_covers_half_a_t_squared() -> None:
    x = step(MODEL, [0.0, 0.0, 0.0, 0.0], [0.5, 0.0], 0.1)
    np.testing.assert_allclose(x, [0.5 * 0.5 * 0.01, 0.0, 0.0, 0.05], atol=1e-12)


def test_speed_saturates_at_its_bounds_without_overshoot() -> None:
    x = step(MODEL, [0.0, 0.0, 0.0, 0.95], [1.0, 0.0], 0.1)
    assert x[3] == pytest.approx(1.0)
    assert x[0] == pytest.approx(0.95 * 0.05 + 0.5 * 0.05**2 + 0.05)  # accelerate 0.05 s, then cruise
    x = step(MODEL, [0.0, 0.0, 0.0, 0.05], [-1.0, 0.0], 0.1)
    assert x[3] == 0.0 and x[0] == pytest.approx(0.05 * 0.05 - 0.5 * 0.05**2)


def test_controls_are_clipped_to_the_limits_and_nan_is_refused() -> None:
    model = RobotModel(RobotLimits(omega_min=-1.0, omega_max=1.0))
    x = step(model, [0.0, 0.0, 0.0, 0.0], [0.0, 5.0], 0.1)
    assert x[2] == pytest.approx(0.1)
    with pytest.raises(ValueError, match="non-finite"):
        step(model, [0.0, 0.0, 0.0, 0.0], [np.nan, 0.0], 0.1)
