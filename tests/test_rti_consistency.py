"""A real-time iteration sees consistent data: parameters changed between the preparation and the
feedback are those the feedback solves with."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import humanmpc

from .conftest import make_solver


@pytest.fixture(scope="module")
def rti_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_solver(tmp_path_factory.mktemp("rti"), {"preset": "paper", "name": "rti", "humans": {"max": 2}})


def scene(t: int, n: int) -> dict:
    now = np.array([[4.0 - 0.05 * t, 0.6]])
    return {"goal": [9.0, 1.0, 0.0, 0.8], "humans_now": now, "humans_pred": np.repeat(now[None], n + 1, axis=0),
            "obstacle": [5.0, -1.0]}


@pytest.mark.parametrize("change", [{"omega_bounds": [-0.3, 0.3]}, {"v_bounds": [0.0, 0.75]},
                                    {"a_bounds": [-0.5, 0.2]}, {"q": 6.0, "w_goal": [1.0, 1.0, 0.0, 50.0]}])
def test_parameters_changed_after_prepare_are_the_ones_feedback_solves_with(rti_dir: Path, change: dict) -> None:
    late, early = humanmpc.load(rti_dir), humanmpc.load(rti_dir)
    n = late.dims.N
    x = np.array([0.0, 0.0, 0.3, 0.6])
    for t in range(8):  # the same warm history for both
        for s in (late, early):
            r = s.step(x, **scene(t, n))
        x = r.x[1]
    late.prepare(**scene(8, n))
    late.set_params(**change)  # after the preparation
    a = late.feedback(x)
    early.set_params(**change)  # before it
    early.prepare(**scene(8, n))
    b = early.feedback(x)
    assert (a.stop, a.stop_reason, a.qp_iterations) == (b.stop, b.stop_reason, b.qp_iterations)
    assert not a.stop, a
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-12)
    p = late.params
    lo_w, hi_w = p["omega_bounds"]
    lo_a, hi_a = p["a_bounds"]
    assert lo_w - 1e-9 <= a.u0[1] <= hi_w + 1e-9 and lo_a - 1e-9 <= a.u0[0] <= hi_a + 1e-9
    assert np.all(a.x[1:, 3] <= p["v_bounds"][1] + 1e-6)
