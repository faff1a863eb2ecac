"""The solver's status codes, QP status codes and stop reasons, and the controller's outcomes as Python enums.

Built from status tables (rows of value, name, message; :func:`status_enums`): a loaded package's
enums from its manifest (``Solver.statuses``), and the module's own (``humanmpc.Status``, ...) from the
tables this humanmpc writes into every manifest (runtime/hm_status.h, read by humanmpc.codegen.status).
A package whose tables differ from the module's is refused at load (:func:`check_package_tables`), so
the module's enums hold for every loaded package. Member names in upper case
(``StopReason.HUMAN_TOO_CLOSE``), ``.message`` the C message.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from enum import IntEnum

from .codegen.manifest import StatusRow
from .codegen.status import status_tables

TABLE_KEYS = ("qp_status", "status", "stop_reason", "outcome")


class _Coded(IntEnum):
    @property
    def message(self) -> str:
        return _MESSAGES[id(type(self))][int(self)]


_MESSAGES: dict[int, dict[int, str]] = {}


def _enum(class_name: str, rows: Sequence[StatusRow]) -> type[_Coded]:
    members = [(r.name.upper(), r.value) for r in rows]
    cls = _Coded(class_name, members)  # type: ignore[call-arg, arg-type]
    _MESSAGES[id(cls)] = {r.value: r.message for r in rows}
    return cls  # type: ignore[return-value]


@dataclass(frozen=True)
class StatusEnums:
    """The four enums of one set of status tables."""

    qp_status: type[_Coded]
    status: type[_Coded]
    stop_reason: type[_Coded]
    outcome: type[_Coded]


def status_enums(tables: Mapping[str, Sequence[StatusRow]], where: str = "the status tables") -> StatusEnums:
    """The enums of ``tables`` (a manifest's ``statuses``); ValueError naming a missing table."""
    missing = [k for k in TABLE_KEYS if k not in tables]
    if missing:
        raise ValueError(f"{where} lack the status tables {missing}: regenerate the package")
    return StatusEnums(_enum("QpStatus", tables["qp_status"]), _enum("Status", tables["status"]),
                       _enum("StopReason", tables["stop_reason"]), _enum("Outcome", tables["outcome"]))


GENERATOR_TABLES: dict[str, tuple[StatusRow, ...]] = {
    key: tuple(StatusRow(r.value, r.name, r.message) for r in rows) for key, rows in status_tables().items()
}
_OWN = status_enums(GENERATOR_TABLES, "humanmpc.codegen.status")
QpStatus = _OWN.qp_status
Status = _OWN.status
StopReason = _OWN.stop_reason
Outcome = _OWN.outcome


def check_package_tables(tables: Mapping[str, Sequence[StatusRow]], where: str) -> None:
    """ValueError when a package's status tables are not this humanmpc's (values or names differ): the
    enums above, StepResult's names and the logs would misread its codes."""
    for key in TABLE_KEYS:
        own = [(r.value, r.name) for r in GENERATOR_TABLES[key]]
        got = [(r.value, r.name) for r in tables.get(key, ())]
        if got != own:
            raise ValueError(f"{where}: its '{key}' table {got} is not this humanmpc's {own}: "
                             "regenerate the package with this humanmpc")


# Lower-case names by value, as StepResult and the logs print them (no stop: None).
STATUS_NAMES: dict[int, str] = {int(s): s.name.lower() for s in Status}
QP_STATUS_NAMES: dict[int, str] = {int(s): s.name.lower() for s in QpStatus}
STOP_REASONS: dict[int, str | None] = {int(s): (None if s == 0 else s.name.lower()) for s in StopReason}
OUTCOME_NAMES: dict[int, str] = {int(s): s.name.lower() for s in Outcome}
