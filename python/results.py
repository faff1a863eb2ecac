"""What one solver step returns, as Python sees it: StepResult, a view of one copy of the C output struct."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from .status import QP_STATUS_NAMES, STATUS_NAMES, STOP_REASONS

FloatArray = NDArray[np.float64]


def _field(key: str, convert: type) -> property:
    """A scalar field of the output record, as a Python bool, int or float."""
    return property(lambda self: convert(self._rec[key]), doc=f"the output's {key}")


class StepResult:
    """What one solver step returns: a copy of the C output struct, taken in one memcpy, whose fields
    are read on access (so a step costs no per-field conversion). Arrays are float64 and stay valid
    after the next step; they are read-only.

    stop                a protective stop is in force: u0 brakes to standstill without turning
    stop_reason         0 none; see STOP_REASONS and ``reason``
    u0, command         control to apply now [a, omega]; the same as [v after one interval, omega]
    x, u                planned states (N+1, 4) and controls (N, 2)
    status, qp_status   see ``status_name``, ``qp_status_name``
    qp_iterations, sqp_iterations, qp_solves (QPs solved: row screening re-solves, the braking retry)
    cost, kkt_stat, kkt_eq, kkt_ineq, kkt_comp, min_human_distance (inf: no human)
    time_prepare_ms, time_feedback_ms, time_total_ms
    """

    __slots__ = ("_rec",)

    def __init__(self, record: Any) -> None:
        self._rec = record

    def _array(self, key: str) -> FloatArray:
        a = self._rec[key]
        return a if a.dtype == np.float64 else a.astype(np.float64)

    @property
    def u0(self) -> FloatArray:
        return self._array("u0")

    @property
    def command(self) -> FloatArray:
        return self._array("command")

    @property
    def x(self) -> FloatArray:
        return self._array("x")

    @property
    def u(self) -> FloatArray:
        return self._array("u")

    stop = _field("stop", bool)
    stop_reason = _field("stop_reason", int)
    status = _field("status", int)
    qp_status = _field("qp_status", int)
    qp_iterations = _field("qp_iterations", int)
    sqp_iterations = _field("sqp_iterations", int)
    qp_solves = _field("qp_solves", int)
    cost = _field("cost", float)
    kkt_stat = _field("kkt_stat", float)
    kkt_eq = _field("kkt_eq", float)
    kkt_ineq = _field("kkt_ineq", float)
    kkt_comp = _field("kkt_comp", float)
    min_human_distance = _field("min_human_distance", float)
    time_prepare_ms = _field("time_prepare_ms", float)
    time_feedback_ms = _field("time_feedback_ms", float)
    time_total_ms = _field("time_total_ms", float)

    def __repr__(self) -> str:
        return (f"StepResult(stop={self.stop}, reason={self.reason}, status={self.status_name}, "
                f"qp_status={self.qp_status_name}, u0={self.u0.tolist()}, time_total_ms={self.time_total_ms:.4f})")

    @property
    def reason(self) -> str | None:
        """Why the stop is in force (None without a stop): one of the names in STOP_REASONS."""
        return STOP_REASONS.get(self.stop_reason, f"unknown({self.stop_reason})")

    @property
    def status_name(self) -> str:
        return STATUS_NAMES.get(self.status, f"unknown({self.status})")

    @property
    def qp_status_name(self) -> str:
        return QP_STATUS_NAMES.get(self.qp_status, f"unknown({self.qp_status})")

    @property
    def kkt(self) -> float:
        """The largest of the four KKT residuals."""
        return max(self.kkt_stat, self.kkt_eq, self.kkt_ineq, self.kkt_comp)
