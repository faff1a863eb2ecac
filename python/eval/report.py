"""The campaign report: one Markdown file and its figures, from a campaign's results folder.

``humanmpc-gen report DIR`` (and ``evaluate`` when it finishes) writes ``DIR/report.md`` and
``DIR/figures/``. Per cell (scenario, crowd model, planner with its parameters), over its episodes:
rates as per cent of the episodes with their 95 % Wilson score intervals, means with their 95 % Student t
intervals (:mod:`humanmpc.eval.stats`), protective stops by reason, and the figures: the success rate
against the number of people per scenario family and crowd model, and the first seed's episodes of every
scenario and crowd model that kept traces, one map per planner (:func:`humanmpc.eval.plots.plot_episodes`).
Every header carries its unit. The metrics are defined in :mod:`humanmpc.eval.metrics`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

from ..sim.robot import RobotModel
from ..sim.scenarios import make_scenario
from .metrics import TTC_CAP
from .plots import planner_colour, plot_episodes
from .stats import MIN_N, Interval, format_mean, format_rate, mean_interval, wilson
from .store import ResultStore
from .traces import trace_to_log

Row = dict[str, Any]

# (header with its unit, the episodes it counts)
RATES: list[tuple[str, Callable[[Row], bool]]] = [
    ("success [%]", lambda r: bool(r["success"])),
    ("goal reached [%]", lambda r: bool(r["reached_goal"])),
    ("timeout [%]", lambda r: bool(r["timeout"])),
    ("any contact [%]", lambda r: int(r["collisions"]) > 0),
    ("contact, robot's fault [%]", lambda r: int(r["robot_fault_contacts"]) > 0),
    ("contact, person's fault [%]", lambda r: int(r["person_fault_contacts"]) > 0),
    ("freezing [%]", lambda r: int(r["freezing_events"]) > 0),
    ("protective stop [%]", lambda r: int(r["protective_stops"]) > 0),
]
# (header with its unit, column, the quantity's range); time to goal over the episodes that reached it (NaN
# otherwise). The t intervals are clipped to the range.
POSITIVE = (0.0, math.inf)
MEANS: list[tuple[str, str, tuple[float, float]]] = [
    ("SPL [0..1]", "spl", (0.0, 1.0)),
    ("time to goal [s]", "time_to_goal", POSITIVE),
    ("path length [m]", "path_length", POSITIVE),
    ("min distance [m]", "min_human_distance", POSITIVE),
    ("min time to collision [s]", "min_time_to_collision", (0.0, TTC_CAP)),
    ("intimate < 0.45 m [s]", "time_intimate", POSITIVE),
    ("personal 0.45-1.2 m [s]", "time_personal", POSITIVE),
    ("social 1.2-3.6 m [s]", "time_social", POSITIVE),
    ("path irregularity [rad/m]", "path_irregularity", POSITIVE),
    ("jerk [m/s³]", "mean_jerk", POSITIVE),
    ("freezing [s]", "freezing_time", POSITIVE),
    ("protective stops [per episode]", "protective_stops", POSITIVE),
    ("people's speed change [m/s]", "people_speed_change", POSITIVE),
    ("people's heading change [rad]", "people_heading_change", POSITIVE),
]
HEADLINE_RATES = ("success [%]", "contact, robot's fault [%]")
HEADLINE_MEANS = ("SPL [0..1]", "time to goal [s]", "min distance [m]", "people's speed change [m/s]")


@dataclass(frozen=True)
class Cell:
    scenario: str
    crowd: str
    planner: str
    rows: tuple[Row, ...]

    @property
    def people(self) -> str:
        counts = sorted({int(r["people"]) for r in self.rows})
        return str(counts[0]) if len(counts) == 1 else f"{counts[0]}-{counts[-1]}"

    def rate(self, header: str) -> Interval:
        test = dict(RATES)[header]
        return wilson(sum(1 for r in self.rows if test(r)), len(self.rows))

    def mean(self, column: str) -> Interval:
        bounds = next((b for _, c, b in MEANS if c == column), POSITIVE)
        return mean_interval([float(r[column]) for r in self.rows], bounds=bounds)


def cells(rows: Sequence[Row], description: dict[str, Any] | None = None) -> list[Cell]:
    """The rows by (scenario, crowd, planner), in the campaign's order of scenarios, crowds and planners."""
    groups: dict[tuple[str, str, str], list[Row]] = {}
    for r in rows:
        groups.setdefault((str(r["scenario"]), str(r["crowd"]), str(r["planner"])), []).append(r)
    d = description or {}
    scen = {s: i for i, s in enumerate(d.get("scenarios", []))}
    crowd = {c: i for i, c in enumerate([*d.get("crowds", []), "recorded"])}
    plan = {p: i for i, p in enumerate(d.get("planners", []))}

    def order(k: tuple[str, str, str]) -> tuple[Any, ...]:
        return (scen.get(k[0], len(scen)), k[0], crowd.get(k[1], len(crowd)), k[1],
                plan.get(k[2].split("[")[0], len(plan)), k[2])

    return [Cell(*k, tuple(sorted(groups[k], key=lambda r: int(r["seed"])))) for k in sorted(groups, key=order)]


def _table(header: Sequence[str], lines: Sequence[Sequence[str]]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out.extend("| " + " | ".join(line) + " |" for line in lines)
    return "\n".join(out) + "\n"


def headline_table(cs: Sequence[Cell]) -> str:
    header = ["scenario", "crowd", "people", "planner", "episodes", *HEADLINE_RATES, *HEADLINE_MEANS]
    means = {h: c for h, c, _ in MEANS}
    return _table(header, [[c.scenario, c.crowd, c.people, c.planner, str(len(c.rows)),
                            *(format_rate(c.rate(h)) for h in HEADLINE_RATES),
                            *(format_mean(c.mean(means[h])) for h in HEADLINE_MEANS)] for c in cs])


def rates_table(cs: Sequence[Cell]) -> str:
    header = ["scenario", "crowd", "planner", "episodes", *(h for h, _ in RATES)]
    return _table(header, [[c.scenario, c.crowd, c.planner, str(len(c.rows)),
                            *(format_rate(c.rate(h)) for h, _ in RATES)] for c in cs])


def means_table(cs: Sequence[Cell]) -> str:
    header = ["scenario", "crowd", "planner", *(h for h, _, _ in MEANS)]
    return _table(header, [[c.scenario, c.crowd, c.planner, *(format_mean(c.mean(col)) for _, col, _ in MEANS)]
                           for c in cs])


def stops_table(cs: Sequence[Cell]) -> str:
    reasons = sorted({k[len("stops["):-1] for c in cs for r in c.rows for k in r if k.startswith("stops[")})
    if not reasons:
        return "No protective stop in any episode.\n"
    header = ["scenario", "crowd", "planner", *(f"{reason} [events]" for reason in reasons)]
    return _table(header, [[c.scenario, c.crowd, c.planner,
                            *(str(sum(int(r.get(f"stops[{x}]") or 0) for r in c.rows)) for x in reasons)]
                           for c in cs])


def runs_table(runs: Sequence[dict[str, Any]]) -> str:
    header = ["started (UTC)", "engine", "workers", "episodes run", "wall time [s]", "episodes/s",
              "cluster start-up [s]", "interrupted"]
    return _table(header, [[str(r["started"]), str(r["engine"]), str(r["workers"]), str(r["ran"]),
                            f"{float(r['wall_s']):.1f}", f"{float(r['episodes_per_s']):.2f}",
                            f"{float(r['startup_s']):.1f}", "yes" if r["interrupted"] else "no"] for r in runs])


def _family(scenario: str, people: int) -> str:
    """``crowdnav_circle_10`` with 10 people -> ``crowdnav_circle``; any other name stays."""
    return re.sub(rf"_{people}$", "", scenario)


def success_figure(cs: Sequence[Cell], path: Path) -> Path:
    """Success rate [%] against the number of people, one panel per scenario family and crowd model, one line
    per planner, 95 % Wilson intervals as error bars."""
    panels: dict[tuple[str, str], dict[str, list[tuple[int, Interval]]]] = {}
    for c in cs:
        people = int(c.rows[0]["people"])
        panels.setdefault((_family(c.scenario, people), c.crowd), {}).setdefault(c.planner, []).append(
            (people, c.rate("success [%]")))
    n = len(panels)
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.6 * rows), squeeze=False)
    for ax, ((family, crowd), lines) in zip(axes.flat, panels.items(), strict=False):
        counts = sorted({p for points in lines.values() for p, _ in points})
        dodge = 0.3 / max(len(lines), 1)
        for i, (planner, points) in enumerate(lines.items()):
            points.sort()
            x = [counts.index(p) + (i - (len(lines) - 1) / 2) * dodge for p, _ in points]
            y = [100 * iv.value for _, iv in points]
            err = [[max(0.0, 100 * (iv.value - iv.low)) for _, iv in points],
                   [max(0.0, 100 * (iv.high - iv.value)) for _, iv in points]]
            ax.errorbar(x, y, yerr=err, marker="o", capsize=3, color=planner_colour(planner, i), label=planner)
        ax.set_xticks(range(len(counts)), [str(c) for c in counts])
        ax.set_xlim(-0.5, len(counts) - 0.5)
        ax.set_title(f"{family}, {crowd}", fontsize=10)
        ax.set_xlabel("people [count]")
        ax.set_ylabel("success [% of episodes]")
        ax.set_ylim(0, 105)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def episode_figures(store: ResultStore, rows: Sequence[Row], description: dict[str, Any], out: Path) -> list[Path]:
    """The first seed's episodes of every (scenario, crowd) that kept traces, planners side by side."""
    keys = store.trace_keys()
    episode = description.get("episode", {})
    robot_data = episode.get("robot", {})
    robot = RobotModel(radius=robot_data.get("radius", 0.2), human_radius=robot_data.get("human_radius", 0.25))
    dt = float(episode.get("dt", 0.1))
    by_cell: dict[tuple[str, str, int], list[Row]] = {}
    for r in rows:
        if r["key"] in keys:
            by_cell.setdefault((str(r["scenario"]), str(r["crowd"]), int(r["seed"])), []).append(r)
    written: list[Path] = []
    firsts: dict[tuple[str, str], int] = {}
    for scenario, crowd, seed in sorted(by_cell):
        firsts.setdefault((scenario, crowd), seed)
    for (scenario, crowd), seed in firsts.items():
        logs = []
        order = {p: i for i, p in enumerate(description.get("planners", []))}
        for r in sorted(by_cell[(scenario, crowd, seed)],
                        key=lambda r: (order.get(str(r["planner"]).split("[")[0], len(order)), str(r["planner"]))):
            trace = store.read_trace(str(r["key"]))
            assert trace is not None
            logs.append(trace_to_log(trace, make_scenario(scenario, seed), str(r["planner"]), str(r["ended_by"]),
                                     dt, robot))
        written.append(plot_episodes(logs, out / f"{scenario}_{crowd}_seed{seed}.png",
                                     title=f"{scenario}, {crowd} crowd, seed {seed}"))
    return written


def write_report(folder: str | Path, out: str | Path | None = None, figures: bool = True) -> Path:
    """Write the report of the campaign in ``folder`` (module docstring) to ``out`` (default
    ``folder/report.md``) and return its path; ``ValueError`` if the folder holds no campaign results."""
    store = ResultStore(folder)
    description = store.description()
    rows = store.read_rows()
    if description is None or not rows:
        raise ValueError(f"{folder} holds no campaign results (campaign.json and episodes/*.parquet): run "
                         f"humanmpc-gen evaluate --out {folder} first")
    target = Path(out) if out is not None else store.root / "report.md"
    fig_dir = target.parent / "figures"
    cs = cells(rows, description)
    seeds = description.get("seeds", [])
    lines = [
        "# Campaign report", "",
        f"{len(rows)} episodes in `{store.root}`: scenarios {', '.join(description['scenarios'])}; crowd models "
        f"{', '.join(description['crowds'])} (recorded scenes replay their people); planners "
        f"{', '.join(description['planners'])}"
        + (f", runtime parameter grid {description['grid']}" if description.get("grid") else "")
        + f"; seeds {seeds[0]}..{seeds[-1]} ({len(seeds)}); solver spec sha256 {description['spec_digest'][:12]}.",
        "",
        "Rates are per cent of the cell's episodes with their 95 % Wilson score interval [low, high]; means "
        "are over the cell's episodes with their 95 % Student t interval (time to goal over the episodes that "
        f"reached it). A mean of fewer than {MIN_N} values has no interval and shows its count, `0.440 (n=2)`; "
        "a t interval that reaches beyond the quantity's range (below 0, SPL above 1, time to collision above "
        f"{TTC_CAP:g} s) is clipped to it and marked `*`: with few episodes it is then a rough bound, not a 95 % "
        "interval. Distances are centre to centre; contacts at robot radius + person radius; the metrics "
        "are defined in python/eval/metrics.py.", "",
        "## Runs", "", runs_table(store.runs()),
        "## Headline", "", headline_table(cs),
        "## Rates [% of episodes, 95 % Wilson interval]", "", rates_table(cs),
        f"## Means [95 % t interval, clipped to the range: *; none below {MIN_N} episodes]", "", means_table(cs),
        "## Protective stops by reason [events, all episodes of the cell]", "", stops_table(cs),
    ]
    if figures:
        written = [success_figure(cs, fig_dir / "success_vs_people.png"),
                   *episode_figures(store, rows, description, fig_dir)]
        lines += ["## Figures", ""]
        lines += [f"![{p.stem}]({p.relative_to(target.parent).as_posix()})" + "\n" for p in written]
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text("\n".join(lines))
    return target
