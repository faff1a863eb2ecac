"""Closed loop end to end: episode, metrics, plots, evaluation and CLI wiring."""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.eval.commands import add_evaluate_parser, add_simulate_parser, choose_solver
from humanmpc.eval.episode import EpisodeConfig, run_episode
from humanmpc.eval.evaluate import evaluate
from humanmpc.eval.metrics import compute_metrics
from humanmpc.eval.plots import animate_episode, plot_episodes
from humanmpc.planners import solver_cache
from humanmpc.planners.dwb import DWBPlanner
from humanmpc.planners.mpc import MPCPlanner
from humanmpc.planners.registry import make_planner, planner_names, register_planner
from humanmpc.sim.scenarios import make_scenario
from tests.conftest import Recorder, make_solver


def test_episode_feeds_observations_as_tracks_and_logs_consistently() -> None:
    scenario = make_scenario("random_crowded_cluttered", 1)
    rec = Recorder()
    log = run_episode(scenario, rec)
    assert log.ended_by in {"goal", "time_limit"}
    T = log.steps
    assert len(rec.seen) == T and log.states.shape == (T + 1, 4) and log.humans.shape == (T + 1, 10, 2)
    for t in (0, 5, T - 1):
        obs = rec.seen[t]
        np.testing.assert_allclose(obs.humans_now, log.humans[t])
        assert obs.humans_velocity.shape == (10, 2) and obs.tracks.shape == (10, 4)
        np.testing.assert_array_equal(obs.ids, np.arange(10))
        np.testing.assert_allclose(obs.obstacle, scenario.world.nearest_point(log.states[t, :2]))
    # the track's velocity is the finite difference of the last two observations
    v_obs = (log.humans[5] - log.humans[4]) / 0.1
    np.testing.assert_allclose(rec.seen[5].humans_velocity, v_obs, atol=1e-9)


def test_the_evaluation_runs_a_solver_whose_horizon_is_not_the_default_one(tmp_path: Path) -> None:
    """The episode hands tracks, which the controller predicts over its own N: an MPC planner over an N = 20
    solver runs in the evaluation's default settings (they once had to carry N = 50's horizon), and choosing
    that solver leaves the settings as they are."""
    spec = tmp_path / "n20.yaml"
    spec.write_text("name: n20\nhorizon: {T: 2.0, N: 20}\nhumans: {max: 3}\n")
    solver_dir = make_solver(tmp_path, {"name": "n20", "horizon": {"T": 2.0, "N": 20}, "humans": {"max": 3}})
    try:
        assert choose_solver(spec, solver_dir) == EpisodeConfig()
    finally:
        solver_cache.select_solver()  # choose_solver chose this process's solver; back to the default
    planner = MPCPlanner(humanmpc.load(solver_dir))
    assert planner.controller.dims.N == 20
    log = run_episode(make_scenario("crossing_group", 0), planner, EpisodeConfig())
    assert log.steps > 50 and log.ended_by in {"goal", "time_limit"}
    assert planner.last is not None and planner.last.plan.shape == (21, 4)
    assert np.all(np.isfinite(log.controls))


def test_dwb_episode_runs_end_to_end_and_its_plots_are_written(tmp_path: Path) -> None:
    log = run_episode(make_scenario("crossing_group", 0), DWBPlanner())
    assert log.reached_goal
    m = compute_metrics(log)
    assert m.path_length >= 12.0 - 0.3 and np.isfinite(m.min_human_distance)
    png = plot_episodes([log], tmp_path / "paths.png")
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    gif = animate_episode(log, tmp_path / "run.gif", stride=20)
    assert gif.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    with pytest.raises(ValueError, match=r"\.gif"):
        animate_episode(log, tmp_path / "run.mp4")


def test_evaluation_writes_tables_and_figures_with_parallel_workers(tmp_path: Path) -> None:
    result = evaluate(["circle_crossing"], ["dwb"], [0, 1], tmp_path, workers=2, progress=False)
    assert [r["seed"] for r in result.rows] == [0, 1]
    with (tmp_path / "runs.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2 and {"success", "min_human_distance", "planner_ms_p99", "crowd"} <= rows[0].keys()
    assert {r["worker"] for r in rows} != {""}
    table = (tmp_path / "summary.md").read_text()
    assert table.startswith("Each cell: mean ± standard deviation")
    assert "| scenario | crowd | planner | runs [count] |" in table
    assert "| circle_crossing | social_force | dwb | 2 |" in table
    assert (tmp_path / "figures" / "circle_crossing_social_force_seed0.png").is_file()
    assert "## Headline" in (tmp_path / "report.md").read_text()


def test_planner_registry_builds_by_name_and_lists_valid_names() -> None:
    assert "dwb" in planner_names() and isinstance(make_planner("dwb"), DWBPlanner)
    with pytest.raises(ValueError, match=r"valid planners: .*dwb"):
        make_planner("teleport")
    with pytest.raises(ValueError, match="already registered"):
        register_planner("dwb", DWBPlanner)


def _cli() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="humanmpc-gen")
    sub = parser.add_subparsers(dest="command", required=True)
    add_simulate_parser(sub)
    add_evaluate_parser(sub)
    return parser


def test_simulate_command_runs_and_writes_the_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = _cli().parse_args(
        ["simulate", "--scenario", "corridor", "--planner", "dwb", "--seed", "3", "--plot", str(tmp_path / "c.png")]
    )
    assert args.func(args) == 0
    assert (tmp_path / "c.png").is_file()
    assert "min_human_distance" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["simulate", "--scenario", "mall", "--planner", "dwb"], "valid scenarios: biwi_eth, biwi_hotel, circle"),
        (["simulate", "--scenario", "corridor", "--planner", "teleport"], "valid planners: dwb"),
        (["evaluate", "--planners", "teleport"], "valid planners: dwb"),
        (["evaluate", "--scenarios", "mall"], "valid scenarios: biwi_eth, biwi_hotel, circle"),
    ],
)
def test_commands_reject_unknown_names_listing_valid_ones(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    args = _cli().parse_args(argv)
    assert args.func(args) == 2
    assert message in capsys.readouterr().err
