"""The CrowdNav table of docs/evaluation.md: two campaigns' `mpc` rows (after, before) against the `dwb` rows of
the first, per scenario and crowd model. Success with its Wilson 95 % interval; path length and time to goal of
the successful episodes as ratios to DWB's in the same cell; mean freezing time; contacts by fault. Run from the
repository root after the two campaigns (the commands are in docs/evaluation.md):

    .venv/bin/python docs/campaign_compare.py out/heldout out/heldout_before
"""

from __future__ import annotations

import csv
import math
import sys
from collections import defaultdict
from pathlib import Path

Row = dict[str, str]


def rows(folder: str) -> list[Row]:
    with open(Path(folder) / "runs.csv", newline="") as f:
        return list(csv.DictReader(f))


def number(x: str) -> float:
    return 1.0 if x == "True" else 0.0 if x == "False" else float(x)


def mean(values: list[float]) -> float:
    return sum(values) / len(values) if values else math.nan


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    if n == 0:
        return math.nan, math.nan
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def cells(data: list[Row], planner: str | None) -> dict[tuple[str, str], list[Row]]:
    out: dict[tuple[str, str], list[Row]] = defaultdict(list)
    for r in data:
        if (planner is None and r["planner"] != "dwb") or r["planner"] == planner:
            out[(r["scenario"], r["crowd"])].append(r)
    return out


def summary(group: list[Row], dwb: list[Row]) -> dict[str, float]:
    ok = [r for r in group if r["success"] == "True"]
    ok_dwb = [r for r in dwb if r["success"] == "True"]
    return {
        "n": len(group), "k": len(ok), "success": len(ok) / len(group),
        "path": mean([number(r["path_length"]) for r in ok]) / mean([number(r["path_length"]) for r in ok_dwb]),
        "time": mean([number(r["time_to_goal"]) for r in ok]) / mean([number(r["time_to_goal"]) for r in ok_dwb]),
        "freezing": mean([number(r["freezing_time"]) for r in group]),
        "robot_fault": sum(number(r["robot_fault_contacts"]) for r in group),
        "person_fault": sum(number(r["person_fault_contacts"]) for r in group),
        "timeout": mean([number(r["timeout"]) for r in group]),
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
        lo, hi = wilson(int(a["k"]), int(a["n"]))
        print(f"| {key[0]} | {key[1]} | {a['success']:.2f} [{lo:.2f}, {hi:.2f}] | {b['success']:.2f} | "
              f"{d['success']:.2f} | {a['path']:.2f} ({b['path']:.2f}) | {a['time']:.2f} ({b['time']:.2f}) | "
              f"{a['freezing']:.1f} ({b['freezing']:.1f}) | {a['robot_fault']:.0f} / {a['person_fault']:.0f} "
              f"({b['robot_fault']:.0f} / {b['person_fault']:.0f}) |")
    for name, t in totals.items():
        k, n = sum(int(x["k"]) for x in t), sum(int(x["n"]) for x in t)
        lo, hi = wilson(k, n)
        print(f"{name}: {n} episodes, success {k / n:.3f} [{lo:.3f}, {hi:.3f}], timeouts "
              f"{mean([x['timeout'] for x in t]):.3f}, path / DWB {mean([x['path'] for x in t]):.2f} "
              f"(worst cell {max(x['path'] for x in t):.2f}), time / DWB {mean([x['time'] for x in t]):.2f} "
              f"(worst cell {max(x['time'] for x in t):.2f}), freezing {mean([x['freezing'] for x in t]):.2f} s, "
              f"contacts {sum(x['robot_fault'] for x in t):.0f} robot's / {sum(x['person_fault'] for x in t):.0f} "
              "person's fault")


if __name__ == "__main__":
    main()
