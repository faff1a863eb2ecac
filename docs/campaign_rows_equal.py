"""Compare the rows of two campaign results folders on the episodes they share (docs/evaluation.md, round 5).

Every column must be equal except the measured ones (planner times, the episode's wall time, the worker
that ran it: humanmpc.eval.worker.MEASURED_COLUMNS). Prints the number of shared episodes and every
difference; exits 1 if there is one, or if no episode is shared.

    .venv/bin/python docs/campaign_rows_equal.py out/campaign out/campaign-sequential
"""

from __future__ import annotations

import math
import sys

from humanmpc.eval.store import ResultStore
from humanmpc.eval.worker import MEASURED_COLUMNS


def differences(a: dict[str, object], b: dict[str, object]) -> list[str]:
    out = []
    for col in sorted(set(a) | set(b)):
        x, y = a.get(col), b.get(col)
        nan = isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y)
        if col not in MEASURED_COLUMNS and x != y and not nan:
            out.append(f"{col}: {x!r} != {y!r}")
    return out


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    first, second = ({str(r["key"]): r for r in ResultStore(path).read_rows()} for path in sys.argv[1:])
    shared = sorted(set(first) & set(second))
    found = 0
    for key in shared:
        for diff in differences(first[key], second[key]):
            print(f"{key}: {diff}")
            found += 1
    columns = len(set().union(*(first[k].keys() for k in shared))) if shared else 0
    print(f"{len(shared)} shared episodes ({len(first)} and {len(second)} in the folders), {columns} columns, "
          f"{len(MEASURED_COLUMNS)} of them measured and not compared: {found} differences")
    return 1 if found or not shared else 0


if __name__ == "__main__":
    sys.exit(main())
