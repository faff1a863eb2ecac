"""The status codes and stop reasons: read from their single source, the C runtime's hm_status.h.

The runtime's enums and messages expand the rows of hm_status.h's X-macro tables; this module reads
the same rows for the generated header's public constants, the manifest and the Python enums
(humanmpc.status), so no code or message is written twice.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache

from .resources import runtime_dir

TABLES = {"qp_status": "HM_QP_STATUS_TABLE", "status": "HM_STATUS_TABLE", "stop_reason": "HM_STOP_REASON_TABLE",
          "outcome": "HM_OUTCOME_TABLE"}
_ROW = re.compile(r'^\s*X\(([A-Z][A-Z0-9_]*), (-?\d+), ([a-z][a-z0-9_]*), "([^"\\]*)"\)\s*\\?\s*$')


@dataclass(frozen=True)
class Code:
    id: str       # C: HM_<id> in the runtime, <NAME>_<id> in the generated header
    value: int
    name: str     # Python: the enum member's name (lower case here)
    message: str


class StatusTableError(ValueError):
    """hm_status.h does not hold the tables in the form this module reads."""


def parse_tables(text: str) -> dict[str, tuple[Code, ...]]:
    """The rows of every table in hm_status.h's text, checked: one table each, unique ids and values."""
    out: dict[str, tuple[Code, ...]] = {}
    lines = text.splitlines()
    for key, macro in TABLES.items():
        starts = [i for i, line in enumerate(lines) if line.startswith(f"#define {macro}(X)")]
        if len(starts) != 1:
            raise StatusTableError(f"hm_status.h: expected one #define {macro}(X), found {len(starts)}")
        rows: list[Code] = []
        i = starts[0] + 1
        while i < len(lines) and lines[i].strip().startswith("X("):
            m = _ROW.match(lines[i])
            if m is None:
                raise StatusTableError(f"hm_status.h:{i + 1}: not a row X(ID, value, name, \"message\"): {lines[i]!r}")
            if "*/" in m.group(4):
                raise StatusTableError(f"hm_status.h:{i + 1}: a message may not hold '*/'")
            rows.append(Code(m.group(1), int(m.group(2)), m.group(3), m.group(4)))
            i += 1
        if not rows:
            raise StatusTableError(f"hm_status.h: {macro} has no rows")
        for attr in ("id", "value", "name"):
            seen = [getattr(r, attr) for r in rows]
            if len(set(seen)) != len(seen):
                raise StatusTableError(f"hm_status.h: {macro} repeats a {attr}: {seen}")
        out[key] = tuple(rows)
    return out


@cache
def status_tables() -> dict[str, tuple[Code, ...]]:
    """qp_status, status and stop_reason: their rows, from the runtime this generator ships."""
    return parse_tables((runtime_dir() / "hm_status.h").read_text())
