"""The trade-off of docs/evaluation.md ("What the robot still does badly"): for each setting of the collision
potential, the time to goal in circle_10 as a ratio to the DWB's against the success among 20 and 10
social-force people. Each point is one setting; the team's bars (time <= 1.2 x DWB's, success >= 0.85 at 20
people and >= 0.95 at 10) bound the region a setting would have to reach. Run from the repository root after
the campaigns (their commands are in docs/evaluation.md):

    .venv/bin/python docs/tradeoff_plot.py out/tradeoff docs/figures/tradeoff_time_vs_dense_success.png

where out/tradeoff holds the campaigns, a folder each: circle_10 with both crowd models (the mpc with its --grid,
and the dwb) and circle_20, square_20 and square_10 with social force (the mpc with its --grid).
"""

from __future__ import annotations

import json
import math
import sys
from collections import defaultdict
from pathlib import Path
from typing import Any

import matplotlib

from humanmpc.codegen.params import PARAMS
from humanmpc.eval.stats import mean_interval, wilson
from humanmpc.eval.store import ResultStore

matplotlib.use("Agg")
import matplotlib.pyplot as plt

Row = dict[str, Any]
TIME_BAR = 1.2
SUCCESS_BAR_20 = 0.85
SUCCESS_BAR_10 = 0.95
DEFAULT = "default"
DEFAULTS = {p.name: p.default for p in PARAMS}


def setting(row: Row) -> str:
    """The grid point of an mpc row, its values at their defaults left out, and the deadline (every setting's)."""
    params = {k: v for k, v in json.loads(row["params"] or "{}").items()
              if k != "deadline_ms" and v != DEFAULTS.get(k)}
    return ", ".join(f"{k} {v:g}" for k, v in sorted(params.items())) or DEFAULT


def arrival_time(rows: list[Row]) -> float:
    return mean_interval([r["time_to_goal"] for r in rows if r["success"]]).value


def success(rows: list[Row]) -> float:
    return wilson(sum(bool(r["success"]) for r in rows), len(rows)).value


def collect(root: Path) -> tuple[dict[str, dict[str, float]], dict[str, float]]:
    """Per setting: circle_10's time / DWB's per crowd model, and the success with social-force people in circle_10
    and the dense cells; the DWB's times in circle_10."""
    c10: dict[tuple[str, str], list[Row]] = defaultdict(list)
    dense: dict[tuple[str, str], list[Row]] = defaultdict(list)
    dwb: dict[str, list[Row]] = defaultdict(list)
    for folder in sorted(p for p in root.iterdir() if p.is_dir()):
        for r in ResultStore(folder).read_rows():  # none in a folder that holds no campaign
            if r["planner"] == "dwb":
                if r["scenario"] == "crowdnav_circle_10":
                    dwb[r["crowd"]].append(r)
            elif r["scenario"] == "crowdnav_circle_10":
                c10[(setting(r), r["crowd"])].append(r)
            else:
                dense[(setting(r), r["scenario"])].append(r)
    dwb_time = {crowd: arrival_time(rs) for crowd, rs in dwb.items()}
    points: dict[str, dict[str, float]] = defaultdict(dict)
    for (name, crowd), rs in c10.items():
        points[name][f"time {crowd}"] = arrival_time(rs) / dwb_time.get(crowd, math.nan)
        if crowd == "social_force":
            points[name]["crowdnav_circle_10"] = success(rs)
    for (name, scenario), rs in dense.items():
        points[name][scenario] = success(rs)
    return points, dwb_time


def table(points: dict[str, dict[str, float]], dwb_time: dict[str, float]) -> str:
    scenes = ("crowdnav_circle_10", "crowdnav_circle_20", "crowdnav_square_20", "crowdnav_square_10")
    head = ("| setting | circle_10 time / DWB's, ORCA [-] | social force [-] | success (social force) circle_10 [-] | "
            "circle_20 [-] | square_20 [-] | square_10 [-] |\n|---|---|---|---|---|---|---|")
    lines = [head]
    for name in sorted(points, key=lambda n: (n != DEFAULT, n)):
        p = points[name]
        cells = [p.get("time orca", math.nan), p.get("time social_force", math.nan)] + [
            p.get(s, math.nan) for s in scenes]
        lines.append(f"| {name} | " + " | ".join(f"{c:.2f}" for c in cells) + " |")
    lines.append(f"DWB's mean time to goal in circle_10: ORCA {dwb_time.get('orca', math.nan):.1f} s, social force "
                 f"{dwb_time.get('social_force', math.nan):.1f} s")
    return "\n".join(lines)


def plot(points: dict[str, dict[str, float]], out: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.2), sharex=True)
    panels = (("crowdnav_circle_10", SUCCESS_BAR_10, "circle_10 itself, 10 people"),
              ("crowdnav_circle_20", SUCCESS_BAR_20, "circle_20, 20 people"))
    for ax, (scene, bar, title) in zip(axes, panels, strict=True):
        ax.axvline(TIME_BAR, color="0.4", linestyle="--", linewidth=1.0)
        ax.axhline(bar, color="0.4", linestyle="--", linewidth=1.0)
        ax.fill_between([0.9, TIME_BAR], bar, 1.03, color="tab:green", alpha=0.08, linewidth=0)
        placed = []
        for name, p in points.items():
            time = max(p.get("time orca", math.nan), p.get("time social_force", math.nan))
            y = p.get(scene, math.nan)
            if not (math.isnan(time) or math.isnan(y)):
                placed.append((time, y, name))
        # labels above and below in turns along the time axis: neighbours' labels do not overlap
        for rank, (time, y, name) in enumerate(sorted(placed)):
            is_default = name == DEFAULT
            ax.plot(time, y, "o", color="tab:red" if is_default else "tab:blue", markersize=7 if is_default else 5)
            ax.annotate(name, (time, y), textcoords="offset points", xytext=(4, 4 if rank % 2 == 0 else -10),
                        fontsize=7)
        ax.set_title(f"{title}, social force", fontsize=10)
        ax.set_xlabel("circle_10 time to goal / DWB's\n(the worse of ORCA and social force) [-]", fontsize=9)
        ax.set_ylabel("success [-]", fontsize=9)
        ax.set_xlim(0.95, 1.45)
        ax.set_ylim(0.3, 1.03)
        ax.text(0.96, bar + 0.005, "the bars' region", fontsize=7, color="tab:green", va="bottom")
    fig.suptitle("The collision potential trades circle_10's time against dense social-force crowds' success "
                 "(tuning seeds)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        print(__doc__)
        return 2
    root, out = Path(argv[1]), Path(argv[2])
    if not root.is_dir():
        print(f"{root}: no such folder of campaigns", file=sys.stderr)
        return 2
    points, dwb_time = collect(root)
    if not points or not dwb_time:
        print(f"{root}: needs the circle_10 campaigns of the mpc and the dwb, and the dense ones", file=sys.stderr)
        return 2
    print(table(points, dwb_time))
    plot(points, out)
    print(f"figure: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
