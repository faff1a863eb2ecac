"""Confidence intervals of the campaign report.

- a rate k / n: the Wilson score interval (Wilson 1927), which keeps within [0, 1] and stays honest at
  k = 0 or k = n where the normal approximation collapses to a point:
  ``(p + z^2/2n -+ z sqrt(p(1 - p)/n + z^2/4n^2)) / (1 + z^2/n)`` with p = k / n, z = 1.96 for 95 %;
- a mean of n values: Student's t interval ``mean -+ t_{0.975, n-1} s / sqrt(n)`` (s the sample standard
  deviation); none for n < 2.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .extras import require

LEVEL = 0.95


@dataclass(frozen=True)
class Interval:
    """An estimate and its confidence interval at ``LEVEL`` (NaN bounds: not enough data)."""

    value: float
    low: float
    high: float
    n: int


def wilson(successes: int, n: int, level: float = LEVEL) -> Interval:
    """The rate ``successes / n`` and its Wilson score interval; NaN for n = 0."""
    if n == 0:
        return Interval(math.nan, math.nan, math.nan, 0)
    if not 0 <= successes <= n:
        raise ValueError(f"wilson: need 0 <= successes <= n, got {successes} of {n}")
    z = float(require("scipy.stats", "the report's intervals").norm.ppf(0.5 + level / 2))
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return Interval(p, max(0.0, centre - half), min(1.0, centre + half), n)


def mean_interval(values: Sequence[float], level: float = LEVEL) -> Interval:
    """The mean of the finite values and its Student t interval (NaN bounds for fewer than two)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return Interval(math.nan, math.nan, math.nan, 0)
    mean = float(np.mean(v))
    if v.size < 2:
        return Interval(mean, math.nan, math.nan, 1)
    t = require("scipy.stats", "the report's intervals").t
    half = float(t.ppf(0.5 + level / 2, v.size - 1)) * float(np.std(v, ddof=1)) / math.sqrt(v.size)
    return Interval(mean, mean - half, mean + half, int(v.size))


def format_rate(iv: Interval) -> str:
    """``85.0 [79.1, 89.6]`` (per cent)."""
    if math.isnan(iv.value):
        return "n/a"
    return f"{100 * iv.value:.1f} [{100 * iv.low:.1f}, {100 * iv.high:.1f}]"


def format_mean(iv: Interval, digits: int = 3) -> str:
    """``0.832 [0.791, 0.873]`` to ``digits`` significant digits (the bounds to the mean's decimals)."""
    if math.isnan(iv.value):
        return "n/a"
    decimals = max(0, digits - 1 - math.floor(math.log10(abs(iv.value)))) if iv.value != 0 else digits - 1
    decimals = min(decimals, 4)
    if math.isnan(iv.low):
        return f"{iv.value:.{decimals}f}"
    return f"{iv.value:.{decimals}f} [{iv.low:.{decimals}f}, {iv.high:.{decimals}f}]"
