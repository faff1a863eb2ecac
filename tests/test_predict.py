"""Tracks and constant-velocity prediction from observed positions."""

from __future__ import annotations

import numpy as np
import pytest

from humanmpc.sim.predict import (
    ConstantVelocityPredictor,
    ConstantVelocityTracker,
    Predictor,
    Tracker,
    predict_constant_velocity,
)


def test_prediction_is_exact_for_constant_velocity_motion() -> None:
    pred = ConstantVelocityPredictor(horizon=50, dt=0.1)
    assert isinstance(pred, Predictor)
    p0 = np.array([[0.0, 0.0], [2.0, -1.0], [5.0, 5.0]])
    vel = np.array([[1.0, 0.5], [-0.3, 0.0], [0.0, 0.0]])
    for step in range(5):
        out = pred.observe(0.1 * step, p0 + 0.1 * step * vel)
    now = p0 + 0.4 * vel
    assert out.shape == (51, 3, 2)
    np.testing.assert_allclose(out[0], now)
    expected = now[None] + 0.1 * np.arange(51)[:, None, None] * vel[None]
    np.testing.assert_allclose(out, expected, atol=1e-12)


def test_velocity_comes_from_the_last_observations_only() -> None:
    pred = ConstantVelocityPredictor(horizon=3, dt=0.5)
    pred.observe(0.0, [[0.0, 0.0]])
    pred.observe(0.1, [[0.1, 0.0]])  # walking at 1 m/s ...
    out = pred.observe(0.2, [[0.1, 0.0]])  # ... then stopped: the prediction stands still
    np.testing.assert_allclose(out, np.full((4, 1, 2), [0.1, 0.0]), atol=1e-12)


def test_single_observation_predicts_standing_still_and_reset_forgets() -> None:
    pred = ConstantVelocityPredictor(horizon=4)
    out = pred.observe(0.0, [[1.0, 2.0]])
    np.testing.assert_allclose(out, np.tile([1.0, 2.0], (5, 1, 1)))
    pred.observe(0.1, [[1.1, 2.0]])
    pred.reset()
    out = pred.observe(5.0, [[3.0, 3.0], [4.0, 4.0]])  # a new episode may have another crowd
    assert out.shape == (5, 2, 2)


def test_changing_the_number_of_humans_within_an_episode_is_an_error() -> None:
    pred = ConstantVelocityPredictor()
    pred.observe(0.0, np.zeros((2, 2)))
    with pytest.raises(ValueError, match="number of humans changed"):
        pred.observe(0.1, np.zeros((3, 2)))
    with pytest.raises(ValueError, match="time must increase"):
        pred.observe(0.0, np.zeros((2, 2)))


def test_the_tracker_gives_velocities_and_the_predictor_walks_them_on() -> None:
    """The episode's tracker hands velocities (per id, from that person's observations only); a planner
    that wants paths walks the tracks on itself, and the predictor is exactly that."""
    tracker, pred = ConstantVelocityTracker(), ConstantVelocityPredictor(horizon=3, dt=0.5)
    assert isinstance(tracker, Tracker)
    for t, (pos, ids) in enumerate([([[0.0, 0.0], [5.0, 5.0]], [3, 8]), ([[5.0, 5.5], [0.1, 0.0]], [8, 3])]):
        vel = tracker.observe(0.1 * t, pos, ids)
        paths = pred.observe(0.1 * t, pos, ids)
    np.testing.assert_allclose(vel, [[0.0, 5.0], [1.0, 0.0]], atol=1e-12)  # in the observation's order
    np.testing.assert_array_equal(tracker.ids, [8, 3])
    np.testing.assert_array_equal(paths, predict_constant_velocity(tracker.positions(), vel, 3, 0.5))
    np.testing.assert_allclose(paths[2], [[5.0, 10.5], [1.1, 0.0]], atol=1e-12)
    with pytest.raises(ValueError, match="2 positions but 1 velocities"):
        predict_constant_velocity(np.zeros((2, 2)), np.zeros((1, 2)), 3, 0.5)
