"""Relative cumulative sub-optimality (RCSO, as in the acados paper): every solver's plans costed by one
function (the reference NLP's), against the best of Ipopt's runs (see humanmpc.compare.report)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..codegen.ocp import DIST_EPS
from ..codegen.reference_nlp import ReferenceNlp
from .replay import Replay

FloatArray = NDArray[np.float64]


def plan_costs(nlp: ReferenceNlp, replay: Replay, u: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Per step: the objective of the controls u[t] (N, 2) simulated from x0_t, and the largest
    violation of the hard human rows by that trajectory (m, 0 when none). NaN where u is not finite."""
    T = replay.steps
    costs = np.full(T, np.nan)
    violation = np.full(T, np.nan)
    for t in range(T):
        ut = np.asarray(u[t], dtype=np.float64)
        if not np.all(np.isfinite(ut)):
            continue
        inputs = replay.inputs(t)
        p = nlp.params.pack(**inputs, params=replay.params)
        X = np.asarray(nlp.rollout(inputs["x0"], ut))
        costs[t] = float(nlp.plan_cost(X, ut, p))
        now = inputs["humans_now"]
        if now.shape[0]:
            # the problem's smoothed distance, as in the constraint rows
            d = np.sqrt(np.sum((X[1:, None, :2] - now[None, :, :]) ** 2, axis=2) + DIST_EPS**2)
            violation[t] = max(0.0, float(np.max(float(np.asarray(replay.params["d_h"]).reshape(-1)[0]) - d)))
        else:
            violation[t] = 0.0
    return costs, violation


def reference_costs(costs: Sequence[FloatArray], success: Sequence[NDArray[np.bool_]]) -> FloatArray:
    """J*_t: the lowest cost among the reference runs that succeeded at step t (NaN where none did).

    ``costs[k]`` are run k's plan costs (``plan_costs``, the same function as for every solver),
    ``success[k]`` its per-step success."""
    if not costs or len(costs) != len(success):
        raise ValueError("give the costs and the success flags of at least one reference run")
    stacked = np.stack([np.where(np.asarray(ok, dtype=bool), np.asarray(c, dtype=np.float64), np.nan)
                        for c, ok in zip(costs, success, strict=True)])
    out = np.full(stacked.shape[1], np.nan)
    ok = np.any(np.isfinite(stacked), axis=0)
    out[ok] = np.nanmin(stacked[:, ok], axis=0)
    return out


def rcso(costs: Sequence[float] | FloatArray, optimal: Sequence[float] | FloatArray) -> tuple[float, int]:
    """Relative cumulative sub-optimality and the number of steps it covers.

    sum_t (costs_t - optimal_t) / sum_t optimal_t over the steps where both are finite.
    """
    c = np.asarray(costs, dtype=np.float64)
    o = np.asarray(optimal, dtype=np.float64)
    if c.shape != o.shape:
        raise ValueError(f"costs {c.shape} and optimal costs {o.shape} must have the same shape")
    ok = np.isfinite(c) & np.isfinite(o)
    if not np.any(ok):
        return float("nan"), 0
    total = float(np.sum(o[ok]))
    if total <= 0.0:
        raise ValueError(f"the optimal costs sum to {total}: RCSO needs a positive total")
    return float(np.sum(c[ok] - o[ok]) / total), int(np.count_nonzero(ok))
