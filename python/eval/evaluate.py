"""Evaluation campaigns: scenarios x crowd models x planners (x a runtime parameter grid) x seeds.

:func:`evaluate` makes the campaign (:mod:`humanmpc.eval.campaign`), runs its missing episodes in this
process or on a Dask cluster (:mod:`humanmpc.eval.engines`, :mod:`humanmpc.eval.runner`), streaming
their rows to Parquet (:mod:`humanmpc.eval.store`), and writes to ``out_dir``:

* ``campaign.json``, ``episodes/*.parquet``, ``traces/*.parquet``, ``runs.jsonl``: the results folder;
  running the same campaign into it again runs only the episodes it lacks;
* ``runs.csv``: every row (one per scenario, crowd, planner and seed), for spreadsheets;
* ``summary.csv`` and ``summary.md``: mean and standard deviation per scenario, crowd and planner
  (rates for success / timeout; every number is a per-run mean);
* ``safety.md``: per scenario, crowd and planner, totals over the runs: goals reached, contacts by
  fault (events and steps), the median of the runs' minimum distances, the time in protective
  stop and freezing (:func:`safety_table`);
* ``report.md`` and ``figures/``: the report with confidence intervals (:mod:`humanmpc.eval.report`).

Tables carry a crowd column when their rows have one (every campaign row does).
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..codegen.spec import Spec
from ..planners.registry import planner_factory, planner_names
from ..planners.solver_cache import held_spec_hash, selected_solver
from ..sim.scenarios import SCENARIOS, check_seeds
from .campaign import Campaign, EpisodeTask, ParamValue, PlannerConfig, SolverRef, grid_points
from .engines import make_engine
from .episode import EpisodeConfig
from .extras import arrow, require
from .metrics import unit, with_unit
from .report import write_report
from .runner import run_campaign
from .store import ResultStore
from .worker import make_task_planner

SUMMARY_COLUMNS = [
    "success", "spl", "collisions", "robot_fault_contacts", "person_fault_contacts", "timeout", "time_to_goal",
    "path_length", "min_human_distance", "min_time_to_collision", "time_within_dth", "time_intimate",
    "time_personal", "time_social", "protective_stops", "stop_time", "freezing_time", "path_irregularity",
    "mean_jerk", "omega_flip_rate", "people_speed_change", "people_heading_change", "planner_ms_mean",
    "planner_ms_p99", "planner_ms_max",
]

Row = dict[str, float | int | bool | str]


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


def _group_keys(rows: Sequence[Row]) -> list[tuple[str, ...]]:
    """(scenario, crowd, planner) of the rows, or (scenario, planner) when they carry no crowd."""
    if any("crowd" in r for r in rows):
        return sorted({(str(r["scenario"]), str(r.get("crowd", "")), str(r["planner"])) for r in rows})
    return sorted({(str(r["scenario"]), str(r["planner"])) for r in rows})


def _group(rows: Sequence[Row], key: tuple[str, ...]) -> list[Row]:
    if len(key) == 3:
        return [r for r in rows if (r["scenario"], r.get("crowd", ""), r["planner"]) == key]
    return [r for r in rows if (r["scenario"], r["planner"]) == key]


def _key_names(keys: Sequence[tuple[str, ...]]) -> list[str]:
    return ["scenario", "crowd", "planner"] if keys and len(keys[0]) == 3 else ["scenario", "planner"]


def summarize(rows: Sequence[Row]) -> list[Row]:
    """Mean and std (population) of the summary columns per (scenario, crowd, planner)."""
    keys = _group_keys(rows)
    names = _key_names(keys)
    out: list[Row] = []
    for key in keys:
        group = _group(rows, key)
        summary: Row = {**dict(zip(names, key, strict=True)), "runs": len(group)}
        for col in SUMMARY_COLUMNS:
            vals = np.array([float(r.get(col, math.nan)) for r in group], dtype=float)
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


SUMMARY_NOTE = ("Each cell: mean ± standard deviation over the runs (the spread of the episodes, not a "
                "confidence interval: report.md has those); yes/no columns as the fraction of runs [0..1].")


def _summary_header(column: str) -> str:
    return f"{column} [0..1]" if unit(column) == "yes/no" else with_unit(column)


def markdown_table(summary: Sequence[Row]) -> str:
    """The summary as a Markdown table, ``mean ± std`` per cell (explained by :data:`SUMMARY_NOTE`, its
    first line), every header with its unit."""
    names = ["scenario", "crowd", "planner"] if summary and "crowd" in summary[0] else ["scenario", "planner"]
    header = [*names, "runs [count]", *(_summary_header(c) for c in SUMMARY_COLUMNS)]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for s in summary:
        cells = [*(str(s[n]) for n in names), str(s["runs"])]
        for col in SUMMARY_COLUMNS:
            m, sd = float(s[f"{col}_mean"]), float(s[f"{col}_std"])
            cells.append("n/a" if math.isnan(m) else f"{m:.3g} ± {sd:.2g}")
        lines.append("| " + " | ".join(cells) + " |")
    return SUMMARY_NOTE + "\n\n" + "\n".join(lines) + "\n"


SAFETY_HEADER = (
    "| scenario | planner | runs [count] | goals reached [runs] | robot-fault contacts [events / steps] "
    "| runs with a robot-fault contact [runs] | person-fault contacts [events / steps] "
    "| min distance, median of runs [m] | time in protective stop, mean [s] | freezing [events / mean s] |"
)


def safety_table(rows: Sequence[Row]) -> str:
    """Per (scenario, planner), over its runs: goals reached, contact events and steps (samples,
    0.1 s each) by fault, runs with a robot-fault contact, the median of the runs' minimum
    centre distances to a person, the mean time in protective stop per run, freezing events
    (total) and the mean freezing time per run. Markdown."""
    keys = _group_keys(rows)
    header = SAFETY_HEADER.replace("| scenario | planner |", "| scenario | crowd | planner |") \
        if keys and len(keys[0]) == 3 else SAFETY_HEADER
    lines = [header, "|" + "---|" * header.count(" | ") + "---|"]
    for key in keys:
        group = _group(rows, key)

        def total(col: str, group: list[Row] = group) -> int:
            return int(sum(int(r[col]) for r in group))

        def mean(col: str, group: list[Row] = group) -> float:
            return float(np.mean([float(r[col]) for r in group]))

        cells = [
            *key, str(len(group)), f"{total('reached_goal')} / {len(group)}",
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


def solver_ref() -> SolverRef:
    """The solver this process's MPC planners load (:func:`humanmpc.planners.solver_cache.select_solver`), as
    workers elsewhere can find it again."""
    choice = selected_solver()
    if choice.solver_dir is not None:
        digest = held_spec_hash(choice.solver_dir) or ""
        return SolverRef(digest, choice.spec, str(choice.solver_dir.resolve()), choice.source)
    spec = choice.spec or Spec()
    return SolverRef(spec.digest(), choice.spec, None, choice.source)


def check_planners(planners: Sequence[str], grid: Sequence[tuple[str, Sequence[ParamValue]]],
                   solver: SolverRef, config: EpisodeConfig) -> frozenset[str]:
    """Make every planner once here, with every grid point for those that take runtime parameters, before
    any episode: an MPC planner generates and builds its solver into this machine's cache if needed (so
    local workers find it built), and a grid value that breaks its parameter's rule is told now. Returns
    the planners that take runtime parameters."""
    tunable: set[str] = set()
    for name in planners:
        task = EpisodeTask("", "social_force", PlannerConfig(name), 0, solver, config)
        controller = getattr(make_task_planner(task), "controller", None)
        if controller is not None and hasattr(controller, "set_params"):
            tunable.add(name)
            for point in grid_points(grid) if grid else []:
                try:
                    make_task_planner(EpisodeTask("", "social_force", PlannerConfig(name, point), 0, solver, config))
                except (KeyError, ValueError) as err:
                    raise ValueError(f"--grid {PlannerConfig(name, point).label}: {str(err).strip(chr(34))}") from None
    return frozenset(tunable)


def evaluate(
    scenarios: Sequence[str],
    planners: Sequence[str],
    seeds: Sequence[int],
    out_dir: str | Path,
    workers: int = 2,
    figures: bool = True,
    progress: bool = True,
    config: EpisodeConfig | None = None,
    *,
    crowds: Sequence[str] = ("social_force",),
    grid: Sequence[tuple[str, Sequence[ParamValue]]] = (),
    scheduler: str | None = None,
    traces: str = "first",
    fresh: bool = False,
    flush_every: int = 50,
) -> EvaluationResult:
    """Run the campaign's missing episodes and write its tables, report and figures (module docstring).

    ``workers``: a local Dask cluster of that many worker processes, 0 for this process; ``scheduler``: an
    existing Dask cluster instead. ``crowds``: the crowd models of the simulated scenarios; ``grid``: runtime
    parameter values of the planners that take them (every combination); ``traces``: which episodes keep
    their per-step trace (``first`` seed, ``all``, ``none``; the figures need the first); ``fresh``: delete
    another campaign's results in ``out_dir`` instead of refusing; ``flush_every``: episodes per Parquet part
    (a part is also written every 10 s). ``config``: the episodes' settings
    (default ``EpisodeConfig()``; its dt must be the MPC solver's interval)."""
    validate_names(scenarios, planners, seeds)
    if not seeds:
        raise ValueError("evaluate needs at least one seed")
    arrow()  # the campaign extra, before any work
    require("scipy.stats", "the report's intervals")
    if scheduler is not None or workers > 0:
        require("dask.distributed", "running episodes on Dask (--workers N >= 1, --scheduler; --workers 0: here)")
    cfg = config or EpisodeConfig()
    solver = solver_ref()
    tunable = check_planners(planners, grid, solver, cfg)
    campaign = Campaign(tuple(scenarios), tuple(crowds), tuple(planners), tuple(int(s) for s in seeds), solver, cfg,
                        tuple((n, tuple(v)) for n, v in grid), tunable, traces)
    store = ResultStore(out_dir)
    store.open(campaign.description(), fresh=fresh)
    tasks = campaign.tasks({name: planner_factory(name) for name in planners})
    engine = make_engine(workers, scheduler)
    try:
        run_campaign(tasks, store, engine, progress=progress, flush_rows=flush_every)
    finally:
        engine.close()
    keys = {t.key for t in tasks}
    rows = sorted((r for r in store.read_rows() if r["key"] in keys),
                  key=lambda r: (str(r["scenario"]), str(r["crowd"]), str(r["planner"]), int(r["seed"])))
    summary = summarize(rows)
    out = store.root
    write_csv(rows, out / "runs.csv")
    write_csv(summary, out / "summary.csv")
    (out / "summary.md").write_text(markdown_table(summary))
    (out / "safety.md").write_text(safety_table(rows))
    write_report(out, figures=figures)
    written = sorted((out / "figures").glob("*.png")) if figures else []
    return EvaluationResult(rows, summary, out, written)
