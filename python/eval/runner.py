"""Run a campaign's missing episodes on an engine and stream their results into its folder.

The episodes whose rows are already in the folder are skipped (a campaign resumes where it stopped);
the others run on the engine, and their results are written as they come, one Parquet part every
``flush_rows`` episodes or ``flush_seconds`` seconds, whichever comes first, and whatever is pending when
the run ends, is interrupted (Ctrl-C) or fails. Progress: a bar with the episodes done and their rate.
Every run appends its record to the folder's run log: engine, workers, episodes run, wall time, episodes
per second (the cluster's start-up not included).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from datetime import datetime, timezone
from typing import TYPE_CHECKING, Any

from tqdm import tqdm

from ..codegen.resources import generator_digest
from .campaign import EpisodeTask
from .engines import Engine
from .store import ResultStore
from .worker import EpisodeResult, run_task

if TYPE_CHECKING:
    import pyarrow as pa


class GeneratorMismatchError(RuntimeError):
    """A worker ran another humanmpc generator than this process (another version, or an edited checkout)."""


@dataclass(frozen=True)
class RunRecord:
    """One run of a campaign (its folder's run log)."""

    started: str
    engine: str
    workers: int
    episodes: int  # of the campaign
    done_before: int  # already in the folder
    ran: int  # by this run
    wall_s: float  # running them (the cluster's start-up not included)
    startup_s: float  # the cluster's start-up
    episodes_per_s: float
    interrupted: bool


def run_campaign(tasks: Sequence[EpisodeTask], store: ResultStore, engine: Engine, *, progress: bool = True,
                 flush_rows: int = 50, flush_seconds: float = 10.0,
                 fn: Callable[[EpisodeTask], EpisodeResult] = run_task,
                 say: Callable[[str], None] | None = None) -> RunRecord:
    """Run the tasks without a row in ``store`` on ``engine`` (module docstring) and return the run's record."""
    tell = say or (lambda m: print(m, file=sys.stderr))
    done = store.done_keys()
    todo = [t for t in tasks if t.key not in done]
    started = datetime.now(timezone.utc).isoformat(timespec="seconds")
    tell(f"[campaign] {len(tasks)} episodes: {len(tasks) - len(todo)} already in {store.root}, {len(todo)} to run "
         f"on {engine.name}")
    rows: list[dict[str, Any]] = []
    traces: list[pa.Table] = []
    mine = generator_digest()[:12]
    ran = 0
    interrupted = True
    bar = tqdm(total=len(tasks), initial=len(tasks) - len(todo), desc="episodes", unit="ep", disable=not progress)
    t0 = last_flush = time.perf_counter()

    def flush() -> None:
        nonlocal last_flush
        store.append(rows, traces)
        rows.clear()
        traces.clear()
        last_flush = time.perf_counter()

    try:
        for result in engine.run(fn, todo):
            if result.row.get("generator_digest") != mine:
                raise GeneratorMismatchError(
                    f"episode {result.key} ran on {result.row.get('worker')} with humanmpc generator "
                    f"{result.row.get('generator_digest')}, this process has {mine}: install the same humanmpc on "
                    "every worker")
            rows.append(result.row)
            if result.trace is not None:
                traces.append(result.trace)
            ran += 1
            bar.update()
            if len(rows) >= flush_rows or time.perf_counter() - last_flush >= flush_seconds:
                flush()
        interrupted = False
    finally:
        if rows:
            flush()
        bar.close()
        wall = time.perf_counter() - t0
        record = RunRecord(started, engine.name, engine.workers, len(tasks), len(tasks) - len(todo), ran, wall,
                           engine.startup_s, ran / wall if wall > 0 else 0.0, interrupted)
        store.log_run(asdict(record))
    tell(f"[campaign] ran {ran} episodes in {record.wall_s:.1f} s: {record.episodes_per_s:.2f} episodes/s on "
         f"{engine.name} (start-up {record.startup_s:.1f} s); results in {store.root}")
    return record
