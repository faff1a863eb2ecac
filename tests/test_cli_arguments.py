"""The command line checks its arguments before any work starts and names the option in every error."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from humanmpc import cli


def test_a_figure_name_matplotlib_cannot_write_is_refused_before_the_episode_runs(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    t0 = time.perf_counter()
    code = cli.main(["simulate", "--scenario", "crossing_group", "--planner", "dwb",
                     "--plot", str(tmp_path / "paths.jpgg")])
    out = capsys.readouterr()
    assert code == 2
    assert ".jpgg is not a figure format" in out.err and ".png" in out.err
    assert "ended by" not in out.out  # no episode ran
    assert time.perf_counter() - t0 < 5.0
    code = cli.main(["simulate", "--scenario", "crossing_group", "--planner", "dwb",
                     "--animate", str(tmp_path / "run.mp4")])
    assert code == 2 and "give a .gif file name" in capsys.readouterr().err


@pytest.mark.parametrize(("argv", "option", "why"), [
    (["simulate", "--scenario", "crossing_group", "--planner", "dwb", "--seed", "-1"], "--seed", "negative"),
    (["evaluate", "--seeds", "0"], "--seeds", ">= 1"),
    (["evaluate", "--first-seed", "x"], "--first-seed", "not an integer"),
    (["evaluate", "--workers", "-1"], "--workers", "negative"),
    (["evaluate", "--traces", "some"], "--traces", "invalid choice"),
    (["evaluate", "--crowds", "boids"], "--crowds", "invalid choice"),
    (["bench", "--steps", "-5"], "--steps", "negative"),
    (["firmware", "somewhere", "--seed", "-2"], "--seed", "negative"),
    (["demo", "--seed", "-3"], "--seed", "negative"),
    (["firmware", "somewhere", "--steps", "-4"], "--steps", "negative"),
    (["firmware", "somewhere", "--humans", "-1"], "--humans", "negative"),
])
def test_a_bad_number_names_its_option(argv: list[str], option: str, why: str,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert f"argument {option}:" in err and why in err


@pytest.mark.parametrize(("argv", "option"), [
    (["generate", "-o", "{file}/sub"], "-o/--output"),
    (["evaluate", "--out", "{file}"], "--out"),
    (["demo", "--out", "{file}/x"], "--out"),
    (["bench", "--out", "{file}"], "--out"),
    (["bench", "--compare", "--compare-out", "{file}"], "--compare-out"),
])
def test_an_output_folder_that_is_a_file_is_refused_before_any_work(argv: list[str], option: str, tmp_path: Path,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """A file where a command's output folder goes raised a traceback (FileExistsError, NotADirectoryError)
    once the command got to writing; now argparse names the option before anything runs."""
    f = tmp_path / "afile"
    f.write_text("")
    t0 = time.perf_counter()
    with pytest.raises(SystemExit) as info:
        cli.main([a.format(file=f) for a in argv])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert f"argument {option}:" in err and "it must be a folder" in err and str(f) in err
    assert time.perf_counter() - t0 < 5.0
