"""A command that needs the campaign extra and lacks it says which extra and the pip line, without a
traceback (exit 2), before any episode runs."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from humanmpc.cli import main
from humanmpc.eval.extras import install_line


def missing(monkeypatch: pytest.MonkeyPatch, *modules: str) -> None:
    """Make ``import module`` fail as it does where the package is not installed."""
    for name in modules:
        monkeypatch.setitem(sys.modules, name, None)


def assert_names_the_extra(err: str, package: str) -> None:
    assert "Traceback" not in err
    assert f"needs {package}, of humanmpc's 'campaign' extra" in err
    assert install_line() in err and "[campaign]" in install_line() and "-m pip install" in install_line()


def test_install_line_installs_the_checkout_into_this_python() -> None:
    line = install_line()
    assert line.startswith(sys.executable) and "-e" in line
    assert line.endswith(f"'{Path(__file__).resolve().parents[1]}[campaign]'")


def test_simulate_with_orca_without_pyrvo_names_the_extra(monkeypatch: pytest.MonkeyPatch,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    missing(monkeypatch, "pyrvo")
    code = main(["simulate", "--scenario", "circle_crossing", "--planner", "dwb", "--crowd", "orca"])
    captured = capsys.readouterr()
    assert code == 2 and "ended by" not in captured.out  # no episode ran
    assert_names_the_extra(captured.err, "pyrvo")


def test_evaluate_without_pyarrow_names_the_extra(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    missing(monkeypatch, "pyarrow", "pyarrow.parquet")
    code = main(["evaluate", "--scenarios", "circle_crossing", "--planners", "dwb", "--seeds", "1", "--workers", "0",
                 "--out", str(tmp_path / "c")])
    assert code == 2 and not (tmp_path / "c" / "episodes").exists()
    assert_names_the_extra(capsys.readouterr().err, "pyarrow")


def test_evaluate_with_orca_without_pyrvo_names_the_extra(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    missing(monkeypatch, "pyrvo")
    code = main(["evaluate", "--scenarios", "circle_crossing", "--crowds", "orca", "--planners", "dwb", "--seeds", "1",
                 "--workers", "0", "--out", str(tmp_path / "c")])
    assert code == 2
    assert_names_the_extra(capsys.readouterr().err, "pyrvo")


def test_report_without_pyarrow_names_the_extra(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    missing(monkeypatch, "pyarrow", "pyarrow.parquet")
    (tmp_path / "c").mkdir()
    assert main(["report", str(tmp_path / "c")]) == 2
    assert_names_the_extra(capsys.readouterr().err, "pyarrow")
