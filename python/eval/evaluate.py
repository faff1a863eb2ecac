"""Batch evaluation: scenarios x planners x seeds in parallel, tables and figures.

Writes to ``out_dir``:

* ``runs.csv``: one row of :class:`~humanmpc.eval.metrics.EpisodeMetrics` per (scenario, planner, seed);
* ``summary.csv`` and ``summary.md``: mean and standard deviation per scenario and planner
  (rates for success / timeout, sums are not used: every number is a per-run mean);
* ``safety.md``: per scenario and planner, totals over the runs: goals reached, contacts by
  fault (events and steps), the median of the runs' minimum distances, the time in protective
  stop and freezing (:func:`safety_table`);
* ``figures/<scenario>_seed<first seed>.png``: the paths of every planner on the first seed.
"""

from __future__ import annotations

import csv
import math
import multiprocessing as mp
from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..planners.registry import make_planner, planner_names
from ..sim.scenarios import SCENARIOS, check_seeds, make_scenario
from .episode import EpisodeConfig, EpisodeLog, run_episode
from .metrics import compute_metrics
from .plots import plot_episodes

SUMMARY_COLUMNS = [
    "success", "collisions", "robot_fault_contacts", "person_fault_contacts", "timeout", "time_to_goal",
    "path_length", "min_human_distance", "time_within_dth", "time_intimate", "time_personal", "protective_stops",
    "stop_time", "freezing_time", "path_irregularity", "mean_jerk", "omega_flip_rate", "planner_ms_mean",
    "planner_ms_p99", "planner_ms_max",
]


@dataclass(frozen=True)
class Job:
    scenario: str
    planner: str
    seed: int
    keep_log: bool


Row = dict[str, float | int | bool | str]


def run_job(job: Job, config: EpisodeConfig | None = None) -> tuple[Row, EpisodeLog | None]:
    """Run one episode and return its metrics row (and its log if asked)."""
    log = run_episode(make_scenario(job.scenario, job.seed), make_planner(job.planner), config)
    log.planner = job.planner  # the registered name (a planner's own name may differ), for the figures
    row: Row = {"scenario": job.scenario, "planner": job.planner, "seed": job.seed}
    row.update(compute_metrics(log).as_row())
    return row, (log if job.keep_log else None)


def validate_names(scenarios: Sequence[str], planners: Sequence[str], seeds: Sequence[int] = ()) -> None:
    """``ValueError`` naming the valid choices for any unknown scenario or planner, or for a seed
    that a scenario does not have (a recorded scene has one seed per crossing)."""
    bad_s = [s for s in scenarios if s not in SCENARIOS]
    if bad_s:
        raise ValueError(f"unknown scenario(s) {', '.join(bad_s)}; valid scenarios: {', '.join(sorted(SCENARIOS))}")
    for scenario in scenarios:
        check_seeds(scenario, seeds)
    valid_p = planner_names()
    bad_p = [p for p in planners if p not in valid_p]
    if bad_p:
        raise ValueError(f"unknown planner(s) {', '.join(bad_p)}; valid planners: {', '.join(valid_p)}")


def summarize(rows: Sequence[Row]) -> list[Row]:
    """Mean and std (population) of the summary columns per (scenario, planner)."""
    keys = sorted({(str(r["scenario"]), str(r["planner"])) for r in rows})
    out: list[Row] = []
    for scen, plan in keys:
        group = [r for r in rows if r["scenario"] == scen and r["planner"] == plan]
        summary: Row = {"scenario": scen, "planner": plan, "runs": len(group)}
        for col in SUMMARY_COLUMNS:
            vals = np.array([float(r[col]) for r in group], dtype=float)
            vals = vals[np.isfinite(vals)]
            summary[f"{col}_mean"] = float(np.mean(vals)) if vals.size else math.nan
            summary[f"{col}_std"] = float(np.std(vals)) if vals.size else math.nan
        out.append(summary)
    return out


def write_csv(rows: Sequence[Row], path: Path) -> None:
    columns: list[str] = []
    for r in rows:
        columns.extend(c for c in r if c not in columns)
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns, restval=0)
        writer.writeheader()
        writer.writerows(rows)


def markdown_table(summary: Sequence[Row]) -> str:
    """The summary as a Markdown table, ``mean ± std`` per cell."""
    header = ["scenario", "planner", "runs", *SUMMARY_COLUMNS]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for s in summary:
        cells = [str(s["scenario"]), str(s["planner"]), str(s["runs"])]
        for col in SUMMARY_COLUMNS:
            m, sd = float(s[f"{col}_mean"]), float(s[f"{col}_std"])
            cells.append("n/a" if math.isnan(m) else f"{m:.3g} ± {sd:.2g}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


SAFETY_HEADER = (
    "| scenario | planner | runs | goals reached | robot-fault contacts: events / steps | runs with a robot-fault "
    "contact | person-fault contacts: events / steps | min distance, median of runs [m] | time in protective stop, "
    "mean [s] | freezing: events / mean time [s] |"
)


def safety_table(rows: Sequence[Row]) -> str:
    """Per (scenario, planner), over its runs: goals reached, contact events and steps (samples,
    0.1 s each) by fault, runs with a robot-fault contact, the median of the runs' minimum
    centre distances to a person, the mean time in protective stop per run, freezing events
    (total) and the mean freezing time per run. Markdown."""
    keys = sorted({(str(r["scenario"]), str(r["planner"])) for r in rows})
    lines = [SAFETY_HEADER, "|" + "---|" * SAFETY_HEADER.count(" | ") + "---|"]
    for scen, plan in keys:
        group = [r for r in rows if r["scenario"] == scen and r["planner"] == plan]

        def total(col: str, group: list[Row] = group) -> int:
            return int(sum(int(r[col]) for r in group))

        def mean(col: str, group: list[Row] = group) -> float:
            return float(np.mean([float(r[col]) for r in group]))

        cells = [
            scen, plan, str(len(group)), f"{total('reached_goal')} / {len(group)}",
            f"{total('robot_fault_contacts')} / {total('robot_fault_steps')}",
            str(sum(1 for r in group if int(r["robot_fault_contacts"]) or int(r["robot_fault_steps"]))),
            f"{total('person_fault_contacts')} / {total('person_fault_steps')}",
            f"{float(np.median([float(r['min_human_distance']) for r in group])):.2f}",
            f"{mean('stop_time'):.1f}", f"{total('freezing_events')} / {mean('freezing_time'):.1f}",
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class EvaluationResult:
    rows: list[Row]
    summary: list[Row]
    out_dir: Path
    figures: list[Path]


def evaluate(
    scenarios: Sequence[str],
    planners: Sequence[str],
    seeds: Sequence[int],
    out_dir: str | Path,
    workers: int = 2,
    figures: bool = True,
    progress: bool = True,
    config: EpisodeConfig | None = None,
) -> EvaluationResult:
    """Run every combination, write the tables (and figures) and return them; ``config``: the episodes'
    settings (default ``EpisodeConfig()``; its horizon must be the MPC solver's N)."""
    validate_names(scenarios, planners, seeds)
    if not seeds:
        raise ValueError("evaluate needs at least one seed")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    # One instance of each planner here, before the workers fork: one-time setup (the MPC generates
    # and builds its solver into the cache when missing) must not run in two workers at once.
    for name in planners:
        make_planner(name)
    first = seeds[0]
    jobs = [Job(s, p, int(seed), figures and seed == first) for s in scenarios for p in planners for seed in seeds]
    results: list[tuple[Row, EpisodeLog | None]] = []
    bar = tqdm(total=len(jobs), desc="episodes", disable=not progress)
    if workers <= 1:
        for job in jobs:
            results.append(run_job(job, config))
            bar.update()
    else:
        # fork: the workers inherit planners registered at run time and the solver chosen for the MPC
        # planners (humanmpc.planners.solver_dir.select_solver).
        ctx = mp.get_context("fork")
        with ctx.Pool(workers) as pool:
            for res in pool.imap_unordered(partial(run_job, config=config), jobs):
                results.append(res)
                bar.update()
    bar.close()
    rows = sorted((r for r, _ in results), key=lambda r: (str(r["scenario"]), str(r["planner"]), int(r["seed"])))
    summary = summarize(rows)
    write_csv(rows, out / "runs.csv")
    write_csv(summary, out / "summary.csv")
    (out / "summary.md").write_text(markdown_table(summary))
    (out / "safety.md").write_text(safety_table(rows))
    written: list[Path] = []
    if figures:
        logs = [log for _, log in results if log is not None]
        for scen in scenarios:
            mine = sorted((lg for lg in logs if lg.scenario == scen), key=lambda lg: list(planners).index(lg.planner))
            if mine:
                written.append(plot_episodes(mine, out / "figures" / f"{scen}_seed{first}.png"))
    return EvaluationResult(rows, summary, out, written)
