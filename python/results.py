"""What one solver step returns, as Python sees it: StepResult, a view of one copy of the C output struct."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from .status import OUTCOME_NAMES, QP_STATUS_NAMES, STATUS_NAMES, STOP_REASONS

FloatArray = NDArray[np.float64]


def _field(key: str, convert: type) -> property:
    """A scalar field of the output record, as a Python bool, int or float."""
    return property(lambda self: convert(self._rec[key]), doc=f"the output's {key}")


def _numpy_type(t: Any) -> Any:
    """The numpy dtype of a cffi primitive or (nested) array type."""
    shape: list[int] = []
    while t.kind == "array":
        shape.append(t.length)
        t = t.item
    base = {"double": np.float64, "float": np.float32, "int": np.int32}.get(t.cname)
    if t.kind != "primitive" or base is None:
        raise TypeError(f"unexpected field type {t.cname} in the output struct")
    return (base, tuple(shape)) if shape else base


def record_dtype(ffi: Any, ctype: str) -> np.dtype:
    """A structured numpy dtype with the layout of the C struct ``ctype`` (cffi's offsets)."""
    t = ffi.typeof(ctype)
    fields = list(t.fields)
    return np.dtype({"names": [f for f, _ in fields], "formats": [_numpy_type(ft.type) for _, ft in fields],
                     "offsets": [ft.offset for _, ft in fields], "itemsize": ffi.sizeof(ctype)})


def c_array_view(ffi: Any, cdata: Any, shape: tuple[int, ...], dtype: Any = np.float64) -> Any:
    """A numpy array over a C array (of the solver's real type: float32 for a float solver), written
    in place: how the solver and the controller fill their input structs."""
    return np.frombuffer(ffi.buffer(cdata), dtype=dtype).reshape(shape)


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
    qp_rows, qp_rows_capped (the most distance rows one of the step's QPs had, and how many QPs had more
                        than the solver's capacity ``solver.qp_rows``: they held those of smallest margin)
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
    qp_rows = _field("qp_rows", int)
    qp_rows_capped = _field("qp_rows_capped", int)
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


class ControllerResult:
    """What one controller step returns: a copy of the C controller output, read on access. Arrays are
    float64 copies, valid after the next step.

    command             (v [m/s], omega [rad/s]) for the base; ``u`` the same as (a [m/s^2], omega)
    outcome             what the robot is doing (``outcome_name``: following, goal_reached, stopped,
                        stalled, no_goal)
    stop, reason        a protective stop and why (None without one); ``stop_reason`` its code
    goal_reached, stalled, recovered (a recovery SQP made this plan), loop_detected
    plan, controls      planned states (N + 1, 4) [x, y, theta, v] and controls (N, 2)
    ocp_goal            the goal the OCP tracked [x, y, theta, v_ref] (the carrot)
    people_ids, people_index, predictions (N + 1, n_people, 2): the tracks the OCP used
    n_tracks_dropped    people given beyond max_tracks and left out (the farthest)
    candidate           the plan applied (0: the main plan; k: the k-th candidate passing someone), and
                        candidates_ok, how many plans passed the monitors and the guard's tests of a moving plan
    obstacle            the obstacle point the OCP kept d_s from, or None
    distance_to_goal [m], time_without_progress [s], min_human_distance [m]
    time_ms, time_solver_ms, time_recovery_ms
    """

    __slots__ = ("_rec",)

    def __init__(self, record: Any) -> None:
        self._rec = record

    def _array(self, key: str) -> FloatArray:
        return np.asarray(self._rec[key], dtype=np.float64)

    @property
    def command(self) -> FloatArray:
        return self._array("command")

    @property
    def u(self) -> FloatArray:
        return self._array("u")

    @property
    def plan(self) -> FloatArray:
        return self._array("plan")

    @property
    def controls(self) -> FloatArray:
        return self._array("controls")

    @property
    def ocp_goal(self) -> FloatArray:
        return self._array("ocp_goal")

    @property
    def n_people(self) -> int:
        return int(self._rec["n_people"])

    @property
    def people_ids(self) -> NDArray[np.int32]:
        return np.array(self._rec["people_ids"][: self.n_people])

    @property
    def people_index(self) -> NDArray[np.int32]:
        return np.array(self._rec["people_index"][: self.n_people])

    @property
    def predictions(self) -> FloatArray:
        return self._array("predictions")[:, : self.n_people]

    @property
    def obstacle(self) -> FloatArray | None:
        return self._array("obstacle") if self._rec["has_obstacle"] else None

    outcome = _field("outcome", int)
    stop = _field("stop", bool)
    stop_reason = _field("stop_reason", int)
    goal_reached = _field("goal_reached", bool)
    stalled = _field("stalled", bool)
    recovered = _field("recovered", bool)
    n_tracks_dropped = _field("n_tracks_dropped", int)
    candidate = _field("candidate", int)
    candidates_ok = _field("candidates_ok", int)
    loop_detected = _field("loop_detected", bool)
    status = _field("status", int)
    qp_status = _field("qp_status", int)
    qp_iterations = _field("qp_iterations", int)
    sqp_iterations = _field("sqp_iterations", int)
    qp_rows = _field("qp_rows", int)
    qp_rows_capped = _field("qp_rows_capped", int)
    distance_to_goal = _field("distance_to_goal", float)
    time_without_progress = _field("time_without_progress", float)
    min_human_distance = _field("min_human_distance", float)
    time_ms = _field("time_total_ms", float)
    time_solver_ms = _field("time_solver_ms", float)
    time_recovery_ms = _field("time_recovery_ms", float)

    @property
    def outcome_name(self) -> str:
        return OUTCOME_NAMES.get(self.outcome, f"unknown({self.outcome})")

    @property
    def reason(self) -> str | None:
        """The stop reason's name (``human_too_close``, ...), None without a stop."""
        return STOP_REASONS.get(self.stop_reason, f"unknown({self.stop_reason})") if self.stop else None

    @property
    def status_name(self) -> str:
        return STATUS_NAMES.get(self.status, f"unknown({self.status})")

    def __repr__(self) -> str:
        v, w = self.command.tolist()
        return (f"ControllerResult(outcome={self.outcome_name}, command=({v:.3f}, {w:.3f}), reason={self.reason}, "
                f"goal_reached={self.goal_reached}, stalled={self.stalled}, time_ms={self.time_ms:.3f})")
