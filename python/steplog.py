"""A bounded log of solver steps for long runs: status, stop reason, timings, closest human.

Kept in preallocated numpy arrays used as a ring buffer (the newest `capacity` steps), so logging
costs no allocation per step; written to CSV or JSON on request.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np

from .results import StepResult
from .status import QP_STATUS_NAMES, STATUS_NAMES, STOP_REASONS

FIELDS = (
    ("step", np.int64),
    ("status", np.int32),
    ("qp_status", np.int32),
    ("qp_iterations", np.int32),
    ("stop", np.int8),
    ("stop_reason", np.int32),
    ("time_prepare_ms", np.float64),
    ("time_feedback_ms", np.float64),
    ("time_total_ms", np.float64),
    ("min_human_distance", np.float64),
)


class StepLog:
    """The newest ``capacity`` steps of a solver; older ones are overwritten."""

    def __init__(self, capacity: int = 10000) -> None:
        if capacity < 1:
            raise ValueError(f"capacity must be >= 1, got {capacity}")
        self.capacity = capacity
        self._data = {name: np.zeros(capacity, dtype=dtype) for name, dtype in FIELDS}
        self._count = 0  # steps ever appended

    def append(self, r: StepResult) -> None:
        i = self._count % self.capacity
        d = self._data
        d["step"][i] = self._count
        d["status"][i] = r.status
        d["qp_status"][i] = r.qp_status
        d["qp_iterations"][i] = r.qp_iterations
        d["stop"][i] = r.stop
        d["stop_reason"][i] = r.stop_reason
        d["time_prepare_ms"][i] = r.time_prepare_ms
        d["time_feedback_ms"][i] = r.time_feedback_ms
        d["time_total_ms"][i] = r.time_total_ms
        d["min_human_distance"][i] = r.min_human_distance
        self._count += 1

    def __len__(self) -> int:
        return min(self._count, self.capacity)

    @property
    def total_steps(self) -> int:
        """Steps appended since the log began (including those overwritten)."""
        return self._count

    def column(self, name: str) -> np.ndarray:
        """One field over the kept steps, oldest first."""
        a = self._data[name]
        if self._count <= self.capacity:
            return a[: self._count].copy()
        start = self._count % self.capacity
        return np.concatenate([a[start:], a[:start]])

    def stop_counts(self) -> dict[str, int]:
        """Number of kept steps under each stop reason."""
        reasons = self.column("stop_reason")
        return {str(STOP_REASONS[k]): int(np.sum(reasons == k)) for k in STOP_REASONS if k and np.any(reasons == k)}

    def records(self) -> list[dict[str, Any]]:
        cols = {name: self.column(name) for name, _ in FIELDS}
        out = []
        for i in range(len(self)):
            rec: dict[str, Any] = {name: cols[name][i].item() for name, _ in FIELDS}
            rec["status_name"] = STATUS_NAMES.get(rec["status"], str(rec["status"]))
            rec["qp_status_name"] = QP_STATUS_NAMES.get(rec["qp_status"], str(rec["qp_status"]))
            rec["reason"] = STOP_REASONS.get(rec["stop_reason"])
            out.append(rec)
        return out

    def write(self, path: str | Path) -> Path:
        """Write the kept steps as CSV (.csv) or JSON (any other suffix)."""
        p = Path(path)
        recs = self.records()
        if p.suffix == ".csv":
            with p.open("w", newline="") as f:
                writer = csv.DictWriter(f, fieldnames=list(recs[0]) if recs else [n for n, _ in FIELDS])
                writer.writeheader()
                writer.writerows(recs)
        else:
            p.write_text(json.dumps({"total_steps": self._count, "steps": recs}, indent=1) + "\n")
        return p
