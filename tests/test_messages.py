"""Messages a new user meets: each says what is wrong, where, and what to do."""

from __future__ import annotations

from pathlib import Path

import pytest

from humanmpc import cli
from humanmpc.sim.recorded import PEDESTRIANS_ENV, pedestrian_data_dir

REPO_ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("command", ["build", "info"])
def test_build_or_info_of_a_folder_that_does_not_exist_says_so(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str) -> None:
    """`build nosuch` said "manifest.json is missing"."""
    missing = tmp_path / "nosuch"
    assert cli.main([command, str(missing)]) == 1
    err = capsys.readouterr().err
    assert f"{missing} does not exist" in err and "manifest.json" not in err and "Traceback" not in err
    a_file = tmp_path / "file"
    a_file.write_text("x")
    assert cli.main([command, str(a_file)]) == 1
    assert f"{a_file} is a file, not a folder" in capsys.readouterr().err


def test_the_missing_pedestrian_data_message_names_each_place_once_what_the_data_is_and_what_to_set(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """From the checkout, the two places it looks are the same folder: the message listed it twice, and
    did not say what the data is or where it comes from."""
    monkeypatch.delenv(PEDESTRIANS_ENV, raising=False)
    monkeypatch.chdir(REPO_ROOT)
    sibling = REPO_ROOT.parent / "shared" / "data" / "pedestrians"
    if sibling.is_dir():
        pytest.skip(f"the data is at {sibling}: nothing is missing here")
    with pytest.raises(FileNotFoundError) as info:
        pedestrian_data_dir()
    message = str(info.value)
    assert message.count(str(sibling)) == 1, message
    assert f"{PEDESTRIANS_ENV} is not set" in message and f"set {PEDESTRIANS_ENV} to the folder" in message
    assert "ETH/UCY" in message and "biwi_eth.txt" in message and "BIWI Walking Pedestrians" in message


def _documented_catkin_make() -> str:
    lines = (REPO_ROOT / "docs" / "ros.md").read_text().splitlines()
    command = next(ln for ln in lines if "catkin_make" in ln and ln.strip().startswith("cd ~/ws"))
    return command.split("#", 1)[0]  # the command, not a comment after it


def test_the_documented_and_printed_catkin_make_name_the_system_python(
        paper_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """With another python3 first on PATH (a venv, pyenv), catkin_make failed with "No module named
    'catkin_pkg'"; docs/ros.md had the fix only as a trailing comment, and `humanmpc-gen ros` printed none."""
    assert "-DPYTHON_EXECUTABLE=/usr/bin/python3" in _documented_catkin_make()
    assert cli.main(["ros", str(paper_dir), "-o", str(tmp_path / "ros_src")]) == 0
    err = capsys.readouterr().err
    assert "catkin_make" in err and "-DPYTHON_EXECUTABLE=/usr/bin/python3" in err
