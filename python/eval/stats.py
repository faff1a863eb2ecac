"""Confidence intervals of the campaign report.

- a rate k / n: the Wilson score interval (Wilson 1927), which keeps within [0, 1] and stays honest at
  k = 0 or k = n where the normal approximation collapses to a point:
  ``(p + z^2/2n -+ z sqrt(p(1 - p)/n + z^2/4n^2)) / (1 + z^2/n)`` with p = k / n, z = 1.96 for 95 %;
- a mean of n values: Student's t interval ``mean -+ t_{0.975, n-1} s / sqrt(n)`` (s the sample standard
  deviation), clipped to the quantity's range (a distance is never below 0, SPL never above 1) and then
  marked as clipped; none for n < ``MIN_N``, where t intervals of skewed episode metrics are wider than
  the quantity's whole range (2 episodes: t = 12.7) and say nothing.

Every interval contains its estimate and lies within the quantity's range.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .extras import require

LEVEL = 0.95
MIN_N = 5  # fewer values: a mean without an interval


@dataclass(frozen=True)
class Interval:
    """An estimate and its confidence interval at ``LEVEL`` (NaN bounds: not enough data)."""

    value: float
    low: float
    high: float
    n: int
    clipped: bool = False  # a bound was moved to the quantity's range


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
    # rounding leaves 1 - 1e-16 above p = 1 (and 1e-17 below p = 0): the bounds hold p by definition
    return Interval(p, min(p, max(0.0, centre - half)), max(p, min(1.0, centre + half)), n)


def mean_interval(values: Sequence[float], level: float = LEVEL,
                  bounds: tuple[float, float] = (-math.inf, math.inf)) -> Interval:
    """The mean of the finite values and its Student t interval clipped to ``bounds``, the quantity's range
    (NaN bounds for fewer than ``MIN_N`` values)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return Interval(math.nan, math.nan, math.nan, 0)
    mean = float(np.mean(v))
    if v.size < MIN_N:
        return Interval(mean, math.nan, math.nan, int(v.size))
    t = require("scipy.stats", "the report's intervals").t
    half = float(t.ppf(0.5 + level / 2, v.size - 1)) * float(np.std(v, ddof=1)) / math.sqrt(v.size)
    low, high = max(bounds[0], mean - half), min(bounds[1], mean + half)
    return Interval(mean, low, high, int(v.size), clipped=(low, high) != (mean - half, mean + half))


def format_rate(iv: Interval) -> str:
    """``85.0 [79.1, 89.6]`` (per cent)."""
    if math.isnan(iv.value):
        return "n/a"
    return f"{100 * iv.value:.1f} [{100 * iv.low:.1f}, {100 * iv.high:.1f}]"


def format_mean(iv: Interval, digits: int = 3) -> str:
    """``0.832 [0.791, 0.873]`` to ``digits`` significant digits (the bounds to the mean's decimals);
    ``0.832 [0.791, 1.000]*`` when clipped to the quantity's range; ``0.832 (n=3)`` below ``MIN_N``."""
    if math.isnan(iv.value):
        return "n/a"
    decimals = max(0, digits - 1 - math.floor(math.log10(abs(iv.value)))) if iv.value != 0 else digits - 1
    decimals = min(decimals, 4)
    if math.isnan(iv.low):
        return f"{iv.value:.{decimals}f} (n={iv.n})"
    mark = "*" if iv.clipped else ""
    return f"{iv.value:.{decimals}f} [{iv.low:.{decimals}f}, {iv.high:.{decimals}f}]{mark}"
