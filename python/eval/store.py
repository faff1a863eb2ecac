"""A campaign's results folder: rows and traces as Parquet, written as they come, read back to resume.

    DIR/campaign.json          the campaign's description (:meth:`Campaign.description`)
    DIR/episodes/part-NNNNNN.parquet   one row per finished episode (:func:`humanmpc.eval.worker.run_task`)
    DIR/traces/part-NNNNNN.parquet     the per-step traces of those of them that keep one (same NNNNNN)
    DIR/runs.jsonl             one line per run of the campaign: when, where, how many episodes, how fast

Each :meth:`ResultStore.append` writes one part: its traces first, then its rows, each to a temporary
name renamed into place, so a part is there whole or not at all, and a row is there only once its
trace is. An episode is done when its row is in a part; a campaign that stops (interrupted, killed, a
machine lost) loses at most the episodes finished since its last part, and running it again runs
exactly the episodes that have no row (:meth:`done_keys`). Opening the folder removes what a killed
writer can leave: temporary files and a traces part without its rows part.
"""

from __future__ import annotations

import json
import os
import re
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .extras import arrow

if TYPE_CHECKING:
    import pyarrow as pa

Row = dict[str, Any]

CAMPAIGN = "campaign.json"
EPISODES = "episodes"
TRACES = "traces"
RUNS_LOG = "runs.jsonl"
_PART = re.compile(r"part-(\d{6})\.parquet")


class CampaignFolderError(ValueError):
    """A results folder that holds another campaign; the message says what differs and what to do."""


def _differences(old: dict[str, Any], new: dict[str, Any], prefix: str = "") -> list[str]:
    out: list[str] = []
    for key in sorted(set(old) | set(new)):
        a, b = old.get(key), new.get(key)
        if isinstance(a, dict) and isinstance(b, dict):
            out.extend(_differences(a, b, f"{prefix}{key}."))
        elif a != b:
            out.append(f"{prefix}{key}: {json.dumps(a)} there, {json.dumps(b)} now")
    return out


class ResultStore:
    """The results folder ``root`` of one campaign (module docstring)."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)
        self.episodes = self.root / EPISODES
        self.traces = self.root / TRACES

    def open(self, description: dict[str, Any], fresh: bool = False) -> None:
        """Use the folder for the campaign ``description``: a new folder is set up, one of the same campaign
        is resumed (cleaned of what a killed writer left), one of another campaign is a
        :class:`CampaignFolderError` unless ``fresh``, which deletes its results first."""
        path = self.root / CAMPAIGN
        if path.is_file():
            old = json.loads(path.read_text())
            if old != json.loads(json.dumps(description)):
                if not fresh:
                    diff = "; ".join(_differences(old, json.loads(json.dumps(description)))[:6])
                    raise CampaignFolderError(
                        f"{self.root} holds the results of another campaign ({diff}): give another --out, or "
                        "--fresh to delete those results and start this campaign there")
                self.clear()
        elif fresh:
            self.clear()
        self.root.mkdir(parents=True, exist_ok=True)
        self.episodes.mkdir(exist_ok=True)
        self.traces.mkdir(exist_ok=True)
        _write_atomically(path, json.dumps(description, indent=1, sort_keys=True).encode())
        self._clean()

    def clear(self) -> None:
        """Delete the campaign's results (the description, rows, traces and run log), nothing else."""
        for d in (self.episodes, self.traces):
            if d.is_dir():
                shutil.rmtree(d)
        for name in (CAMPAIGN, RUNS_LOG):
            (self.root / name).unlink(missing_ok=True)

    def _clean(self) -> None:
        for d in (self.episodes, self.traces):
            for tmp in d.glob(".*.tmp"):
                tmp.unlink()
        rows = {p.name for p in self.episodes.glob("part-*.parquet")}
        for trace in self.traces.glob("part-*.parquet"):
            if trace.name not in rows:  # its rows were never written: those episodes run again
                trace.unlink()

    def _parts(self, folder: Path) -> list[Path]:
        return sorted(p for p in folder.glob("part-*.parquet") if _PART.fullmatch(p.name))

    def done_keys(self) -> set[str]:
        """The keys of the episodes that have a row."""
        _, pq = arrow()
        keys: set[str] = set()
        for part in self._parts(self.episodes):
            keys.update(pq.read_table(part, columns=["key"]).column("key").to_pylist())
        return keys

    def append(self, rows: Sequence[Row], traces: Sequence[pa.Table] = ()) -> Path | None:
        """Write one part (module docstring); returns its rows file (None when there is nothing to write)."""
        if not rows:
            return None
        pa, _ = arrow()
        parts = self._parts(self.episodes)
        number = int(_PART.fullmatch(parts[-1].name).group(1)) + 1 if parts else 0  # type: ignore[union-attr]
        name = f"part-{number:06d}.parquet"
        if traces:
            _write_table(pa.concat_tables(traces), self.traces / name)
        columns: dict[str, None] = {}
        for row in rows:
            columns.update(dict.fromkeys(row))
        full = [{c: row.get(c, 0 if c.startswith("stops[") else None) for c in columns} for row in rows]
        _write_table(pa.Table.from_pylist(full), self.episodes / name)  # from_pylist takes the first row's keys
        return self.episodes / name

    def read_rows(self) -> list[Row]:
        """Every row, in the order of their keys; columns a part lacks (a stop reason no episode of it had)
        read 0. ``ValueError`` if a key has two rows (a folder written by something else)."""
        pa, pq = arrow()
        parts = [pq.read_table(p) for p in self._parts(self.episodes)]
        if not parts:
            return []
        rows = pa.concat_tables(parts, promote_options="permissive").to_pylist()
        seen: set[str] = set()
        for row in rows:
            if row["key"] in seen:
                raise ValueError(f"{self.episodes}: episode {row['key']} has two rows")
            seen.add(row["key"])
            for col, value in row.items():
                if value is None and col.startswith("stops["):
                    row[col] = 0
        return sorted(rows, key=lambda r: str(r["key"]))

    def read_trace(self, key: str) -> pa.Table | None:
        """The per-step trace of episode ``key``, None if it kept none."""
        _, pq = arrow()
        for part in self._parts(self.traces):
            table = pq.read_table(part, filters=[("key", "=", key)])
            if table.num_rows:
                return table
        return None

    def trace_keys(self) -> set[str]:
        _, pq = arrow()
        keys: set[str] = set()
        for part in self._parts(self.traces):
            keys.update(pq.read_table(part, columns=["key"]).column("key").unique().to_pylist())
        return keys

    def log_run(self, record: dict[str, Any]) -> None:
        with (self.root / RUNS_LOG).open("a") as fh:
            fh.write(json.dumps(record, sort_keys=True) + "\n")

    def runs(self) -> list[dict[str, Any]]:
        path = self.root / RUNS_LOG
        return [json.loads(line) for line in path.read_text().splitlines() if line.strip()] if path.is_file() else []

    def description(self) -> dict[str, Any] | None:
        path = self.root / CAMPAIGN
        return json.loads(path.read_text()) if path.is_file() else None


def _write_atomically(path: Path, data: bytes) -> None:
    tmp = path.parent / f".{path.name}.tmp"
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _write_table(table: pa.Table, path: Path) -> None:
    tmp = path.parent / f".{path.name}.tmp"
    arrow()[1].write_table(table, tmp)
    with tmp.open("rb") as fh:
        os.fsync(fh.fileno())
    os.replace(tmp, path)
