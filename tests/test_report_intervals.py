"""The campaign report's intervals stay within their quantities' ranges, and the report is written whatever
the episodes gave (a cell of 100 % success, two seeds)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from humanmpc.cli import main
from humanmpc.eval.report import Cell, success_figure
from humanmpc.eval.stats import MIN_N, format_mean, mean_interval, wilson

NUMBER = r"-?\d+(?:\.\d+)?"
INTERVAL = re.compile(rf"^({NUMBER}) \[({NUMBER}), ({NUMBER})\](\*?)$")
NO_INTERVAL = re.compile(rf"^{NUMBER} \(n=(\d+)\)$")


def header_range(header: str) -> tuple[float, float]:
    """The range of the quantity a report header names (every quantity of the report is >= 0)."""
    if header.endswith("[%]"):
        return 0.0, 100.0
    if "[0..1]" in header:
        return 0.0, 1.0
    if header.startswith("min time to collision"):
        return 0.0, 10.0
    return 0.0, math.inf


def report_intervals(report: str) -> list[tuple[str, float, float, float]]:
    """(header, value, low, high) of every interval in the report's Markdown tables; also checks that a mean
    shown without an interval names a count below MIN_N."""
    found = []
    header: list[str] = []
    for line in report.splitlines():
        if not line.startswith("|"):
            header = []
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        if not header:
            header = cells
            continue
        for name, cell in zip(header, cells, strict=True):
            m = INTERVAL.match(cell)
            if m:
                found.append((name, float(m[1]), float(m[2]), float(m[3])))
            n = NO_INTERVAL.match(cell)
            if n:
                assert int(n[1]) < MIN_N, f"{name}: {cell} has no interval with {n[1]} values"
    return found


def assert_within_ranges(report: str) -> int:
    intervals = report_intervals(report)
    for name, value, low, high in intervals:
        lo, hi = header_range(name)
        assert lo <= low <= value <= high <= hi, f"{name}: {value} [{low}, {high}] leaves [{lo}, {hi}]"
    return len(intervals)


def test_wilson_interval_holds_its_rate_at_zero_and_all() -> None:
    for n in range(1, 120):
        for k in (0, n):
            iv = wilson(k, n)
            assert 0.0 <= iv.low <= iv.value <= iv.high <= 1.0, (k, n, iv)


def test_mean_interval_is_clipped_to_the_range_and_marked() -> None:
    iv = mean_interval([0.0, 0.0, 0.0, 0.0, 0.0, 0.9], bounds=(0.0, 1.0))
    assert iv.low == 0.0 and iv.clipped and format_mean(iv).endswith("]*")
    inside = mean_interval([0.5, 0.52, 0.49, 0.51, 0.5], bounds=(0.0, 1.0))
    assert 0.0 < inside.low < inside.value < inside.high < 1.0 and not inside.clipped


def test_mean_of_fewer_than_the_minimum_has_no_interval_and_says_its_count() -> None:
    iv = mean_interval([0.04, 0.84], bounds=(0.0, math.inf))  # t interval: 0.440 [-4.64, 5.52]
    assert math.isnan(iv.low) and math.isnan(iv.high)
    assert format_mean(iv) == "0.440 (n=2)"


def test_success_figure_draws_a_cell_where_every_episode_succeeded(tmp_path: Path) -> None:
    rows = tuple({"people": 5, "success": True, "seed": s} for s in range(10))
    path = success_figure([Cell("crowdnav_circle_5", "orca", "dwb", rows)], tmp_path / "s.png")
    assert path.stat().st_size > 0


@pytest.mark.parametrize("extra", [["--seeds", "2"], ["--seeds", "10", "--traces", "none"]],
                         ids=["2-seeds", "10-seeds-no-traces"])
def test_evaluate_report_intervals_are_within_the_quantities_ranges(tmp_path: Path, extra: list[str],
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "campaign"
    code = main(["evaluate", "--scenarios", "circle_crossing", "--planners", "dwb", "--workers", "0", "--quiet",
                 "--out", str(out), *extra])
    assert code == 0, capsys.readouterr().err
    report = (out / "report.md").read_text()
    assert assert_within_ranges(report) >= 10  # the rates, and with 10 seeds the means
    if extra[1] == "2":
        assert "(n=2)" in report  # no t interval from two episodes
    assert "mean ± standard deviation" in capsys.readouterr().out  # the stdout table says what ± is
