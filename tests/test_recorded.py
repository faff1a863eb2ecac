"""Recorded crowds: reading the tracks, replaying them, predicting people who come and go, the
scenarios built on the ETH / UCY recordings, and closed loops among them."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pytest

from humanmpc.eval.commands import add_demo_parser, add_evaluate_parser, add_simulate_parser
from humanmpc.eval.episode import run_episode
from humanmpc.eval.evaluate import safety_table
from humanmpc.eval.metrics import compute_metrics, human_distances
from humanmpc.sim.crowd import Crowd, CrowdSpec, HumanCrowd
from humanmpc.sim.predict import ConstantVelocityPredictor
from humanmpc.sim.recorded import (
    PEDESTRIANS_ENV,
    RecordedCrowd,
    RecordedCrowdSpec,
    load_recording,
    parse_recording,
    pedestrian_data_dir,
)
from humanmpc.sim.scenarios import (
    RECORDED_CROSSINGS,
    RECORDED_SCENARIOS,
    RECORDED_TIME_LIMIT,
    SIMULATED_SCENARIOS,
    V_REF,
    Scenario,
    make_scenario,
    plan_crossings,
)
from humanmpc.sim.world import World
from tests.conftest import Recorder, needs_data

# 25 frames per second, an annotation every 10 frames (0.4 s). Pedestrian 1 walks along x at 1 m/s and is
# not seen at frame 130 (a gap: two tracks); pedestrian 2 stands at (5, 5) from frame 110 to 130; pedestrian 3
# is seen once, at frame 120. The 5th and 6th columns (a velocity estimate) are ignored.
TRACKS = """\
100 1 0.0 0.0 1.0 0.0
110 1 0.4 0.0 1.0 0.0
110 2 5.0 5.0
120 1 0.8 0.0
120 2 5.0 5.0
120 3 9.0 9.0
130 2 5.0 5.0
140 1 1.6 0.0
150 1 2.0 0.0
"""


def test_tracks_split_at_gaps_and_time_comes_from_the_annotation_step() -> None:
    rec = parse_recording(TRACKS, "hand")
    assert rec.size == 4  # pedestrian 1 twice (before and after the gap), 2 and 3 once
    np.testing.assert_array_equal(rec.pedestrian, [1, 1, 2, 3])
    np.testing.assert_allclose(rec.start, [0.0, 1.6, 0.4, 0.8])  # (frame - 100) / 10 frames * 0.4 s
    np.testing.assert_array_equal(rec.count, [3, 2, 3, 1])
    np.testing.assert_allclose(rec.end, [0.8, 2.0, 1.2, 0.8])
    assert rec.duration == (0.0, 2.0)


def test_replay_interpolates_linearly_and_people_come_and_go_as_recorded() -> None:
    rec = parse_recording(TRACKS, "hand")
    ids, pos = rec.at(0.1)  # only pedestrian 1's first track, a quarter of the way to its second annotation
    np.testing.assert_array_equal(ids, [0])
    np.testing.assert_allclose(pos, [[0.1, 0.0]])
    ids, pos = rec.at(0.8)  # first track's last annotation, 2 standing, 3's only instant
    np.testing.assert_array_equal(ids, [0, 2, 3])
    np.testing.assert_allclose(pos, [[0.8, 0.0], [5.0, 5.0], [9.0, 9.0]])
    ids, _ = rec.at(0.9)  # 1 unseen (gap), 3 gone
    np.testing.assert_array_equal(ids, [2])
    ids, pos = rec.at(1.9)  # 1 again, as a new track
    np.testing.assert_array_equal(ids, [1])
    np.testing.assert_allclose(pos, [[1.9, 0.0]])
    assert rec.at(2.1)[0].size == 0 and rec.at(2.1)[1].shape == (0, 2)


def test_the_replay_steps_at_the_control_period_and_ignores_the_robot() -> None:
    rec = parse_recording(TRACKS, "hand")
    crowd = RecordedCrowd(RecordedCrowdSpec(rec, t0=0.4), dt=0.1)
    assert isinstance(crowd, HumanCrowd)
    seen = []
    for _ in range(5):
        seen.append((crowd.time, crowd.ids.tolist(), crowd.positions[0].tolist()))
        crowd.step(robot_position=[0.55, 0.0], robot_velocity=[-1.0, 0.0])  # in its way: no effect
    assert [s[1] for s in seen] == [[0, 2], [0, 2], [0, 2], [0, 2], [0, 2, 3]]
    np.testing.assert_allclose([s[2] for s in seen], [[0.4, 0], [0.5, 0], [0.6, 0], [0.7, 0], [0.8, 0]])
    np.testing.assert_allclose([s[0] for s in seen], [0.0, 0.1, 0.2, 0.3, 0.4])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("100 1 0.0\n", "line 1: fewer than 4 columns"),
        ("100 1 0.0 0.0\n105.5 1 0.4 0.0\n", "line 2: frame and pedestrian id must be integers"),
        ("100 1 0.0 nan\n", "line 1: positions must be finite"),
        ("100 1 0.0 0.0\n100 1 0.4 0.0\n", "pedestrian 1 is annotated twice in one frame"),
        ("100 1 0.0 0.0\n110 1 0.4 0.0\n125 1 0.8 0.0\n", "not whole multiples of the smallest one, 10"),
        ("# nothing\n", "no annotation rows"),
    ],
)
def test_a_malformed_recording_is_refused_naming_the_problem(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        parse_recording(text, "bad")


def test_a_missing_data_folder_says_where_it_looked_and_what_to_set(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(PEDESTRIANS_ENV, str(tmp_path / "nowhere"))
    with pytest.raises(FileNotFoundError, match=f"nowhere.*set {PEDESTRIANS_ENV}"):
        pedestrian_data_dir()


# Prediction of people who appear and disappear.


def test_prediction_follows_each_id_and_a_newcomer_stands_still_until_seen_twice() -> None:
    pred = ConstantVelocityPredictor(horizon=2, dt=0.5)
    pred.observe(0.0, [[0.0, 0.0], [5.0, 0.0]], ids=[7, 9])
    # 9 left, 4 arrived; 7 walks at 1 m/s along y and is now listed second
    out = pred.observe(0.1, [[2.0, 2.0], [0.0, 0.1]], ids=[4, 7])
    np.testing.assert_allclose(out[:, 0], [[2.0, 2.0]] * 3)  # the newcomer: one observation, stands still
    np.testing.assert_allclose(out[:, 1], [[0.0, 0.1], [0.0, 0.6], [0.0, 1.1]])
    out = pred.observe(0.2, [[2.1, 2.0]], ids=[4])  # 7 gone: not predicted
    np.testing.assert_allclose(out[:, 0], [[2.1, 2.0], [2.6, 2.0], [3.1, 2.0]])
    out = pred.observe(0.3, [[9.0, 9.0], [2.2, 2.0]], ids=[7, 4])  # 7 back: a fresh start, no stale velocity
    np.testing.assert_allclose(out[:, 0], [[9.0, 9.0]] * 3)


def test_prediction_with_ids_of_a_fixed_crowd_is_the_prediction_without() -> None:
    rng = np.random.default_rng(0)
    with_ids, without = ConstantVelocityPredictor(window=3), ConstantVelocityPredictor(window=3)
    for step in range(6):
        pos = rng.normal(size=(4, 2))
        a = with_ids.observe(0.1 * step, pos, ids=np.arange(4))
        b = without.observe(0.1 * step, pos)
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    ("ids", "message"), [([1, 1], "ids must be distinct"), ([1], "ids must be 2 integers"), ([0.5, 1], "integers")]
)
def test_bad_ids_are_refused(ids: list[float], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        ConstantVelocityPredictor().observe(0.0, np.zeros((2, 2)), ids=ids)


def test_the_simulated_crowd_names_everyone_always() -> None:
    crowd = Crowd(CrowdSpec.build([[0.0, 0.0], [3.0, 0.0]], [[[5.0, 0.0]], [[-5.0, 0.0]]], 1.0))
    assert isinstance(crowd, HumanCrowd)
    np.testing.assert_array_equal(crowd.ids, [0, 1])


# Closed loop among people who come and go.


def _hand_scenario(t0: float = 0.0) -> Scenario:
    rec = parse_recording(TRACKS, "hand")
    x0 = np.array([0.0, -3.0, 0.0, 0.5])
    return Scenario("hand", 0, World((), (-1.0, 10.0, -4.0, 10.0)), RecordedCrowdSpec(rec, t0), x0,
                    np.array([9.0, -3.0, 0.0, 0.5]), time_limit=2.5)


def test_an_episode_among_recorded_people_logs_who_is_present_and_shows_only_them() -> None:
    planner = Recorder()
    log = run_episode(_hand_scenario(), planner)
    assert log.steps == 25 and log.humans.shape == (26, 4, 2)
    np.testing.assert_array_equal(log.human_ids, [0, 1, 2, 3])
    present = log.present
    assert present[:, 0].tolist() == [t <= 8 for t in range(26)]  # track 0: 0 .. 0.8 s
    assert present[:, 3].tolist() == [t == 8 for t in range(26)]  # track 3: only at 0.8 s
    assert np.all(np.isnan(log.humans[~present])) and np.all(np.isfinite(log.humans[present]))
    for t, obs in enumerate(planner.seen):
        np.testing.assert_allclose(obs.humans_now, log.humans[t, present[t]])
        assert obs.humans_velocity.shape == (int(present[t].sum()), 2)
        np.testing.assert_array_equal(obs.ids, log.human_ids[present[t]])
    # at 1.6 s track 1 appears (one observation): it stands; at 1.7 s it walks at 1 m/s
    np.testing.assert_allclose(planner.seen[16].humans_velocity, [[0.0, 0.0]])
    np.testing.assert_allclose(planner.seen[17].humans_velocity, [[1.0, 0.0]], atol=1e-9)
    m = compute_metrics(log)
    # nearest person: track 0 at 3.0 m when the robot starts (both at x = 0), never anyone absent
    assert m.min_human_distance == pytest.approx(3.0) and m.collisions == 0




@needs_data
@pytest.mark.parametrize(("name", "tracks", "most"), [("biwi_eth", 360, 27), ("biwi_hotel", 390, 18),
                                                      ("crowds_zara01", 148, 20)])
def test_recorded_people_walk_at_walking_speed(name: str, tracks: int, most: int) -> None:
    rec = load_recording(name)
    assert rec.size == tracks  # no gaps in these files: one track per pedestrian
    # the frame rate comes out right (15 frames/s in eth, 25 in the others): people walk at 0.4..2 m/s
    steps = np.linalg.norm(np.diff(rec.xy, axis=1), axis=-1).ravel()
    speed = np.median(steps[np.isfinite(steps)]) / rec.period
    assert 0.4 < speed < 2.0
    # the README's largest number of people in one frame, at the annotated instants
    annotated = rec.start[:, None] + rec.period * np.arange(rec.xy.shape[1])[None]
    instants = np.unique(np.round(annotated[np.arange(rec.xy.shape[1])[None] < rec.count[:, None]], 6))
    assert int(rec.present(instants).sum(axis=-1).max()) == most


@needs_data
@pytest.mark.parametrize("name", RECORDED_SCENARIOS)
def test_each_recorded_scene_has_32_crossings_both_ways_at_16_start_times_a_crossing_apart(name: str) -> None:
    scenes = [make_scenario(name, seed) for seed in range(RECORDED_CROSSINGS)]
    plan = plan_crossings(load_recording(name))
    assert RECORDED_CROSSINGS == 32
    starts = np.array([float(s.crowd.t0) for s in scenes[::2] if isinstance(s.crowd, RecordedCrowdSpec)])
    assert starts.size == 16
    # crossings 0..7: one start time in each quarter of the admissible ones, in order
    first, last = load_recording(name).duration
    quarter = (last - RECORDED_TIME_LIMIT - first) / 4
    np.testing.assert_array_equal(np.floor((starts[:4] - first) / quarter).clip(0, 3), [0, 1, 2, 3])
    # no two crossings start within one nominal duration (length at v_ref) of each other
    nominal = np.linalg.norm(plan.ends[1] - plan.ends[0]) / V_REF
    gaps = np.abs(starts[:, None] - starts[None, :]) + np.eye(starts.size) * 1e9
    assert gaps.min() >= nominal - 1e-9
    for a, b in zip(scenes[::2], scenes[1::2], strict=True):
        np.testing.assert_allclose(a.robot_start[:2], b.goal[:2])  # the same crossing, the other way
        np.testing.assert_allclose(a.goal[:2], b.robot_start[:2])
    for s in scenes:
        assert isinstance(s.crowd, RecordedCrowdSpec) and s.world.is_empty
        assert 10.0 < np.linalg.norm(s.goal[:2] - s.robot_start[:2]) < 14.0
        assert s.world.contains_free_disc(s.robot_start[:2], 0.2) and s.world.contains_free_disc(s.goal[:2], 0.2)
        gaps = np.linalg.norm(s.crowd.positions[:, None] - plan.ends[None], axis=-1)
        assert gaps.size == 0 or gaps.min() >= 1.0  # nobody at either end when the robot sets off
        assert s.crowd.t0 + s.time_limit <= s.crowd.recording.duration[1]  # people all the way
        # people walk through it: at least two present on average over its nominal duration
        along = s.crowd.t0 + np.arange(0.0, nominal, 0.4)
        assert s.crowd.recording.present(along).sum(axis=-1).mean() >= 2.0
    assert all(s.crowd.ids.size >= 2 for s in scenes[:8])  # the first eight start among people
    # reproducible
    np.testing.assert_array_equal(make_scenario(name, 3).goal, scenes[3].goal)


@needs_data
def test_a_recorded_scene_has_no_seed_beyond_its_crossings() -> None:
    with pytest.raises(ValueError, match=r"biwi_hotel has seeds 0\.\.31"):
        make_scenario("biwi_hotel", 32)


@needs_data
def test_an_episode_in_a_recorded_scene_replays_the_recording() -> None:
    scenario = make_scenario("crowds_zara01", 5)
    assert isinstance(scenario.crowd, RecordedCrowdSpec)
    planner = Recorder()
    log = run_episode(scenario, planner)
    rec, t0 = scenario.crowd.recording, scenario.crowd.t0
    for t in (0, 37, log.steps):
        ids, pos = rec.at(t0 + 0.1 * t)
        col = np.searchsorted(log.human_ids, ids)
        np.testing.assert_array_equal(np.nonzero(log.present[t])[0], col)
        np.testing.assert_allclose(log.humans[t, col], pos)
    m = compute_metrics(log)
    in_contact = human_distances(log.states[:, :2], log.humans, log.present) < 0.45
    assert m.robot_fault_steps + m.person_fault_steps == int(np.count_nonzero(in_contact))
    assert np.isfinite(m.min_human_distance)


# The commands.


def _cli() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="humanmpc-gen")
    sub = parser.add_subparsers(dest="command", required=True)
    add_simulate_parser(sub)
    add_evaluate_parser(sub)
    add_demo_parser(sub)
    return parser


@needs_data
def test_simulate_runs_a_recorded_scene_and_prints_the_attributed_contacts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = _cli().parse_args(["simulate", "--scenario", "biwi_hotel", "--planner", "dwb", "--seed", "1",
                              "--plot", str(tmp_path / "hotel.png")])
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert "biwi_hotel seed 1 with dwb" in out and "robot_fault_contacts" in out and "freezing_time" in out
    assert (tmp_path / "hotel.png").stat().st_size > 10_000


@pytest.mark.parametrize(
    "argv",
    [
        ["evaluate", "--scenarios", "biwi_eth", "--planners", "dwb", "--seeds", "33"],
        ["simulate", "--scenario", "biwi_eth", "--planner", "dwb", "--seed", "32"],
        ["demo", "--scenario", "biwi_eth", "--seed", "32"],
    ],
)
def test_commands_refuse_a_seed_beyond_the_crossings(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    args = _cli().parse_args(argv)
    assert args.func(args) == 2
    assert "biwi_eth has seeds 0..31" in capsys.readouterr().err


def test_evaluate_defaults_to_the_simulated_scenarios(monkeypatch: pytest.MonkeyPatch) -> None:
    import humanmpc.eval.evaluate as evaluation

    asked: list[list[str]] = []

    def fake(scenarios: list[str], *args: object, **kwargs: object) -> object:
        asked.append(list(scenarios))
        raise SystemExit(0)

    monkeypatch.setattr(evaluation, "evaluate", fake)
    args = _cli().parse_args(["evaluate", "--planners", "dwb", "--seeds", "20"])
    with pytest.raises(SystemExit):
        args.func(args)
    assert asked == [list(SIMULATED_SCENARIOS)]


def test_the_safety_table_totals_contacts_by_fault_and_takes_the_median_distance() -> None:
    def row(seed: int, reached: bool, robot: tuple[int, int], person: tuple[int, int], dmin: float,
            stop: float, freeze: tuple[int, float]) -> dict[str, float | int | bool | str]:
        return {"scenario": "biwi_hotel", "planner": "dwb", "seed": seed, "reached_goal": reached,
                "robot_fault_contacts": robot[0], "robot_fault_steps": robot[1], "person_fault_contacts": person[0],
                "person_fault_steps": person[1], "min_human_distance": dmin, "stop_time": stop,
                "freezing_events": freeze[0], "freezing_time": freeze[1]}

    rows = [row(0, True, (0, 0), (1, 3), 0.40, 1.0, (0, 0.0)), row(1, False, (2, 7), (0, 0), 0.30, 2.0, (1, 6.0)),
            row(2, True, (0, 0), (0, 0), 0.90, 0.0, (0, 0.0))]
    table = safety_table(rows)
    assert table.splitlines()[2] == "| biwi_hotel | dwb | 3 | 2 / 3 | 2 / 7 | 1 | 1 / 3 | 0.40 | 1.0 | 1 / 2.0 |"
    assert "min distance, median of runs [m]" in table.splitlines()[0]
