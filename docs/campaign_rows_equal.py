"""Compare the rows of two campaign results folders on the episodes they share (docs/evaluation.md, round 5).

Every column must be equal except the measured ones (planner times, the episode's wall time, the worker
that ran it: humanmpc.eval.worker.MEASURED_COLUMNS). Prints the count of equal episodes and every episode
that differs, with its deadline stops in each folder and the columns that differ; exits 1 if one differs
or no episode is shared.

An episode of an MPC planner is deterministic except through the wall clock: a solver step that misses
the controller's deadline (monitor.deadline_ms, 20 ms by default; a busy machine can hold a process at
nice 19 that long) is a protective stop, and a recovery SQP stops at the deadline. Campaigns compared for
equality run with a deadline no step meets (``--grid deadline_ms=1000``).

    .venv/bin/python docs/campaign_rows_equal.py out/unclocked-w2 out/unclocked-w0
"""

from __future__ import annotations

import math
import sys

from humanmpc.eval.store import ResultStore
from humanmpc.eval.worker import MEASURED_COLUMNS


def differences(a: dict[str, object], b: dict[str, object]) -> list[str]:
    out = []
    for col in sorted(set(a) | set(b)):
        absent = 0 if col.startswith("stops[") else None  # no stop of that reason in a whole folder: no column
        x, y = a.get(col, absent), b.get(col, absent)
        nan = isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y)
        if col not in MEASURED_COLUMNS and x != y and not nan:
            out.append(col)
    return out


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    first, second = ({str(r["key"]): r for r in ResultStore(path).read_rows()} for path in sys.argv[1:])
    shared = sorted(set(first) & set(second))
    differing = [(key, differences(first[key], second[key])) for key in shared]
    differing = [(key, cols) for key, cols in differing if cols]
    columns = len(set().union(*(first[k].keys() for k in shared))) if shared else 0
    print(f"{len(shared)} shared episodes ({len(first)} and {len(second)} in the folders), {columns} columns "
          f"({len(MEASURED_COLUMNS)} measured ones not compared): {len(shared) - len(differing)} equal, "
          f"{len(differing)} differ")
    for key, cols in differing:
        stops = [int(rows[key].get("stops[deadline]") or 0) for rows in (first, second)]
        print(f"  {key}: deadline stops {stops[0]} / {stops[1]}; differs in {', '.join(cols)}")
    return 1 if differing or not shared else 0


if __name__ == "__main__":
    sys.exit(main())
