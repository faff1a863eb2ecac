"""The CrowdNav table of docs/evaluation.md: two campaigns' `mpc` rows (after, before) against the `dwb` rows of
the first, per scenario and crowd model. Success with its Wilson 95 % interval; path length and time to goal of
the successful episodes as ratios to DWB's in the same cell; mean freezing time; contacts by fault. Run from the
repository root after the two campaigns (the commands are in docs/evaluation.md):

    .venv/bin/python docs/campaign_compare.py out/heldout out/heldout_before
"""

from __future__ import annotations

import math
import sys
from collections import defaultdict
from pathlib import Path
from typing import Any

from humanmpc.eval.stats import wilson
from humanmpc.eval.store import ResultStore

Row = dict[str, Any]


def rows(folder: str) -> list[Row]:
    return ResultStore(Path(folder)).read_rows()


def mean(values: list[float]) -> float:
    """A NaN (a cell without a success) makes the mean NaN: an overall figure that skipped it would flatter."""
    return sum(values) / len(values) if values else math.nan


def cells(data: list[Row], planner: str | None) -> dict[tuple[str, str], list[Row]]:
    out: dict[tuple[str, str], list[Row]] = defaultdict(list)
    for r in data:
        if (planner is None and r["planner"] != "dwb") or r["planner"] == planner:
            out[(r["scenario"], r["crowd"])].append(r)
    return out


def summary(group: list[Row], dwb: list[Row]) -> dict[str, float]:
    ok = [r for r in group if r["success"]]
    ok_dwb = [r for r in dwb if r["success"]]
    return {
        "n": len(group), "k": len(ok), "success": len(ok) / len(group),
        "path": mean([r["path_length"] for r in ok]) / mean([r["path_length"] for r in ok_dwb]),
        "time": mean([r["time_to_goal"] for r in ok]) / mean([r["time_to_goal"] for r in ok_dwb]),
        "freezing": mean([float(r["freezing_time"]) for r in group]),
        "robot_fault": sum(float(r["robot_fault_contacts"]) for r in group),
        "person_fault": sum(float(r["person_fault_contacts"]) for r in group),
        "timeout": mean([float(r["timeout"]) for r in group]),
    }


def main() -> None:
    after, before = rows(sys.argv[1]), rows(sys.argv[2])
    dwb = cells(after, "dwb")
    new, old = cells(after, None), cells(before, None)
    print("| scene | crowd | success after [95 % CI] | before | DWB | path / DWB's after (before) | time / DWB's "
          "after (before) | freezing [s] after (before) | contacts robot's / person's fault after (before) |")
    print("|---|---|---|---|---|---|---|---|---|")
    totals: dict[str, list[dict[str, float]]] = {"after": [], "before": [], "dwb": []}
    for key in sorted(new):
        a, b = summary(new[key], dwb[key]), summary(old[key], dwb[key])
        d = summary(dwb[key], dwb[key])
        totals["after"].append(a)
        totals["before"].append(b)
        totals["dwb"].append(d)
        iv = wilson(int(a["k"]), int(a["n"]))
        print(f"| {key[0]} | {key[1]} | {a['success']:.2f} [{iv.low:.2f}, {iv.high:.2f}] | {b['success']:.2f} | "
              f"{d['success']:.2f} | {a['path']:.2f} ({b['path']:.2f}) | {a['time']:.2f} ({b['time']:.2f}) | "
              f"{a['freezing']:.1f} ({b['freezing']:.1f}) | {a['robot_fault']:.0f} / {a['person_fault']:.0f} "
              f"({b['robot_fault']:.0f} / {b['person_fault']:.0f}) |")
    for name, t in totals.items():
        k, n = sum(int(x["k"]) for x in t), sum(int(x["n"]) for x in t)
        iv = wilson(k, n)
        print(f"{name}: {n} episodes, success {k / n:.3f} [{iv.low:.3f}, {iv.high:.3f}], timeouts "
              f"{mean([x['timeout'] for x in t]):.3f}, path / DWB {mean([x['path'] for x in t]):.2f} "
              f"(worst cell {max(x['path'] for x in t):.2f}), time / DWB {mean([x['time'] for x in t]):.2f} "
              f"(worst cell {max(x['time'] for x in t):.2f}), freezing {mean([x['freezing'] for x in t]):.2f} s, "
              f"contacts {sum(x['robot_fault'] for x in t):.0f} robot's / {sum(x['person_fault'] for x in t):.0f} "
              "person's fault")


if __name__ == "__main__":
    main()
