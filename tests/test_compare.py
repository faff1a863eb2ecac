"""The comparison report end to end on a small problem, and its command-line options."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from humanmpc.codegen.spec import resolve_spec
from humanmpc.compare.peers.acados_client import find_python312
from humanmpc.compare.peers.ipopt import ipopt_unavailable_reason
from humanmpc.compare.replay import synthetic_replay
from humanmpc.compare.report import (
    SOLVERS,
    SolverStats,
    add_compare_arguments,
    compare,
    markdown_section,
)

from .conftest import REPO_ROOT


def test_compare_writes_table_plot_and_json(tmp_path: Path) -> None:
    reason = ipopt_unavailable_reason()
    if reason is not None:
        pytest.fail(f"{reason} (`make test` installs it: see APT_PACKAGES in the Makefile)")
    specs = [resolve_spec({"name": "cmp", "humans": {"max": n}, "horizon": {"N": 20, "T": 2.0}}) for n in (1, 3)]
    replays = [synthetic_replay(s, s.humans.max, 6, seed=3) for s in specs]
    report = compare(specs, replays, tmp_path / "out", acados_venv=REPO_ROOT / ".venv-acados",
                     command="pytest", log=lambda _m: None)
    rows = report["rows"]
    assert [(r["n_humans"], r["solver"]) for r in rows] == [(n, s) for n in (1, 3) for s in SOLVERS]
    by = {(r["n_humans"], r["solver"]): r for r in rows}
    for n in (1, 3):
        cold, warm = by[(n, "Ipopt cold")], by[(n, "Ipopt warm")]
        assert cold["error"] is None and warm["error"] is None
        assert cold["failures"] == 0 and cold["rcso_steps"] == 6
        # The reference is the better of the two Ipopt runs at every step: neither is below it.
        assert cold["rcso"] >= -1e-12 and warm["rcso"] >= -1e-12
        assert min(cold["rcso"], warm["rcso"]) < 1e-3
        assert 0 < cold["min_ms"] <= cold["mean_ms"] <= cold["p99_ms"] <= cold["max_ms"]
        assert len(cold["times_ms"]) == 6
        ours = by[(n, "humanmpc")]
        assert ours["error"] is None, ours["error"]
        assert ours["ratio_to_ours"] == pytest.approx(1.0)
        assert cold["ratio_to_ours"] == pytest.approx(cold["mean_ms"] / ours["mean_ms"])
        assert cold["median_ratio_to_ours"] == pytest.approx(cold["median_ms"] / ours["median_ms"])
        assert cold["min_ms"] <= cold["median_ms"] <= cold["max_ms"]
        assert np.isfinite(ours["rcso"]) and ours["rcso_steps"] == 6
        exact = by[(n, "humanmpc exact+LS")]
        assert exact["error"] is None and exact["rcso_steps"] == 6
        # RCSO over the steps every real-time iteration solved: the same steps for all of them
        commons = {r["rcso_common_steps"] for r in rows if r["n_humans"] == n and r["solver"] in
                   ("humanmpc", "humanmpc exact+LS", "acados default", "acados fastest") and r["error"] is None}
        assert len(commons) == 1 and 0 < commons.pop() <= 6
        for label in ("acados default", "acados fastest"):
            row = by[(n, label)]
            if find_python312() is None:
                assert "Python 3.12" in row["error"]
            else:
                assert row["error"] is None, row["error"]
                assert row["mean_ms"] > 0 and row["rcso_steps"] >= 1
    out = tmp_path / "out"
    md = (out / "benchmarks.md").read_text()
    assert md.count("\n| 1 | ") == 6 and md.count("\n| 3 | ") == 6 and "Command: `pytest`" in md
    assert "Machine: cpu:" in md
    assert (out / "step_times.png").stat().st_size > 1000
    assert json.loads((out / "results.json").read_text())["command"] == "pytest"


def test_compare_refuses_mismatched_inputs(tmp_path: Path) -> None:
    spec = resolve_spec({"humans": {"max": 2}, "horizon": {"N": 10, "T": 1.0}})
    other = resolve_spec({"humans": {"max": 3}, "horizon": {"N": 10, "T": 1.0}})
    replay = synthetic_replay(other, 1, 2, seed=0)
    with pytest.raises(ValueError, match="give one replay per spec"):
        compare([spec], [replay, replay], tmp_path, skip=list(SOLVERS))
    with pytest.raises(ValueError, match="unknown solver"):
        compare([spec], [replay], tmp_path, skip=["gurobi"])
    with pytest.raises(ValueError, match="not for spec"):
        compare([spec], [replay], tmp_path, skip=list(SOLVERS), log=lambda _m: None)


def test_markdown_reports_solvers_that_did_not_run() -> None:
    rows = [SolverStats("humanmpc", 5, 10, mean_ms=0.5, median_ms=0.45, min_ms=0.4, max_ms=0.7, p99_ms=0.69,
                        ratio_to_ours=1.0, median_ratio_to_ours=1.0,
                        iterations_mean=12.0, iterations_max=20, failures=1, rcso=0.01, rcso_steps=10,
                        max_violation_m=0.0),
            SolverStats("acados default", 5, 10, error="acados needs Python 3.12 ...")]
    md = markdown_section(rows, {"cpu": "x"}, "cmd")
    assert ("| 5 | humanmpc | 0.500 | 0.450 | 0.400 | 0.700 | 0.690 | 1.00 | 1.00 | 12.000/20 | 1/10 | 0.010 | – "
            "| 0.000 |") in md
    assert "| 5 | acados default | not run: acados needs Python 3.12" in md


def test_cli_options() -> None:
    parser = argparse.ArgumentParser()
    add_compare_arguments(parser)
    args = parser.parse_args(["--compare", "--compare-humans", "5", "10", "--compare-steps", "20",
                              "--compare-skip", "Ipopt cold"])
    assert args.compare and args.compare_humans == [5, 10] and args.compare_steps == 20
    assert args.compare_skip == ["Ipopt cold"] and args.acados_venv == Path(".venv-acados")
    with pytest.raises(SystemExit):
        parser.parse_args(["--compare-skip", "gurobi"])
