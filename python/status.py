"""The solver's status codes, QP status codes and stop reasons, and the controller's outcomes as Python enums.

From their single source, the C runtime's table (runtime/hm_status.h, read by
humanmpc.codegen.status): the same values and messages as the generated C, member names in upper
case (``StopReason.HUMAN_TOO_CLOSE``), ``.message`` the C message.
"""

from __future__ import annotations

from enum import IntEnum

from .codegen.status import status_tables


class _Coded(IntEnum):
    @property
    def message(self) -> str:
        return _MESSAGES[type(self).__name__][int(self)]


_MESSAGES: dict[str, dict[int, str]] = {}


def _enum(class_name: str, key: str) -> type[_Coded]:
    rows = status_tables()[key]
    _MESSAGES[class_name] = {r.value: r.message for r in rows}
    members = [(r.name.upper(), r.value) for r in rows]
    return _Coded(class_name, members)  # type: ignore[call-arg, arg-type, return-value]


QpStatus = _enum("QpStatus", "qp_status")
Status = _enum("Status", "status")
StopReason = _enum("StopReason", "stop_reason")
Outcome = _enum("Outcome", "outcome")

# Lower-case names by value, as StepResult and the logs print them (no stop: None).
STATUS_NAMES: dict[int, str] = {int(s): s.name.lower() for s in Status}
QP_STATUS_NAMES: dict[int, str] = {int(s): s.name.lower() for s in QpStatus}
STOP_REASONS: dict[int, str | None] = {int(s): (None if s == 0 else s.name.lower()) for s in StopReason}
OUTCOME_NAMES: dict[int, str] = {int(s): s.name.lower() for s in Outcome}
