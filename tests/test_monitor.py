"""Feasibility and safety monitors: each injected fault gives its exact stop reason, a braking command
without turning and nothing non-finite, and the solver recovers on the next clean step by itself."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.steplog import StepLog

N = 50
DT = 0.1


def clean_inputs() -> dict:
    humans_now = np.array([[3.0, 1.5], [5.0, -2.0], [6.0, 0.3]])
    vel = np.array([[0.0, -0.3], [0.2, 0.4], [-0.5, 0.0]])
    pred = np.stack([humans_now + vel * DT * n for n in range(N + 1)])
    return {
        "x0": np.array([0.0, 0.0, 0.1, 0.6]),
        "goal": np.array([8.0, 0.0, 0.0, 0.8]),
        "humans_now": humans_now,
        "humans_pred": pred,
        "obstacle": np.array([4.0, -0.8]),
        "humans_vel": vel,
    }


def assert_braking(r: humanmpc.StepResult, solver: humanmpc.Solver, v0: float | None) -> None:
    a_min, a_max = solver.params["a_bounds"]
    assert r.stop
    assert np.all(np.isfinite(r.u0)) and np.all(np.isfinite(r.command))
    assert np.all(np.isfinite(r.x)) and np.all(np.isfinite(r.u))
    assert r.u0[1] == 0.0 and r.command[1] == 0.0  # no turning
    assert a_min <= r.u0[0] <= a_max
    if v0 is not None:
        assert r.u0[0] == pytest.approx(max(a_min, min(a_max, -v0 / DT)))
        assert r.x[-1, 3] == pytest.approx(0.0, abs=1e-12)  # the plan comes to standstill


def assert_same(a: humanmpc.StepResult, b: humanmpc.StepResult) -> None:
    for field in ("u0", "command", "x", "u"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert (a.status, a.qp_status, a.qp_iterations, a.stop, a.stop_reason) == (
        b.status, b.qp_status, b.qp_iterations, b.stop, b.stop_reason)
    assert a.cost == b.cost and a.min_human_distance == b.min_human_distance


@pytest.fixture()
def fresh(paper_dir: Path) -> humanmpc.Solver:
    return humanmpc.load(paper_dir)


def test_clean_inputs_give_no_stop(fresh: humanmpc.Solver) -> None:
    r = fresh.step(**clean_inputs())
    assert not r.stop and r.reason is None and r.status_name == "solved"


def test_human_inside_d_h_stops_and_the_solver_resumes_when_it_leaves(fresh: humanmpc.Solver) -> None:
    inp = clean_inputs()
    fresh.step(**inp)
    close = dict(inp, humans_now=inp["humans_now"].copy(), humans_pred=inp["humans_pred"].copy())
    close["humans_now"][0] = inp["x0"][:2] + np.array([0.3, 0.1])
    close["humans_pred"][:, 0] = close["humans_now"][0]
    r = fresh.step(**close)
    assert r.reason == "human_too_close" and r.stop_reason == 6
    assert_braking(r, fresh, v0=inp["x0"][3])
    r = fresh.step(**inp)
    assert not r.stop and r.status_name == "solved"


def test_human_walking_into_the_robot_ends_in_a_stop_and_the_robot_resumes_after(fresh: humanmpc.Solver) -> None:
    x = np.array([0.0, 0.0, 0.0, 0.3])
    goal = np.array([10.0, 0.0, 0.0, 0.8])
    h = np.array([[4.0, 0.0]])
    v = np.array([[-1.5, 0.0]])  # straight at the robot, faster than it can get out of the way
    reasons = []
    for _ in range(100):
        pred = np.stack([h + v * DT * n for n in range(N + 1)])
        r = fresh.step(x, goal, h, pred, None)
        assert np.all(np.isfinite(r.u0)) and np.all(np.isfinite(r.command))
        reasons.append(r.reason)
        if float(np.linalg.norm(h[0] - x[:2])) < 0.5:
            assert r.stop and r.reason == "human_too_close"
        if r.stop:
            assert r.u0[1] == 0.0
        x = x + DT * np.array([x[3] * np.cos(x[2]), x[3] * np.sin(x[2]), r.u0[1], r.u0[0]])
        h = h + v * DT
    assert "human_too_close" in reasons
    assert all(reason is None for reason in reasons[-20:])  # resumed by itself once the human had passed
    assert x[0] > 1.0  # and went on towards the goal


def test_person_running_at_the_robot_stops_it_for_separation_and_it_resumes_after(default_dir: Path) -> None:
    solver = humanmpc.load(default_dir)  # speed and separation on (the default spec)
    inp = clean_inputs()
    assert not solver.step(**inp).stop
    run = running_at_the_robot(inp)
    r = solver.step(**run)
    assert r.reason == "separation" and r.stop_reason == 8
    assert_braking(r, solver, v0=inp["x0"][3])
    r = solver.step(**inp)
    assert not r.stop and r.status_name == "solved"


def running_at_the_robot(inp: dict) -> dict:
    """inp with person 0 1.5 m ahead, running at the robot at 3 m/s (velocity and prediction): the person
    alone covers 0.9 m of the 1.0 m gap while the robot reacts (0.3 s); no speed above 0.03 m/s keeps the
    separation, and braking reaches 0.5 m/s."""
    heading = np.array([np.cos(0.1), np.sin(0.1)])
    run = {k: np.array(v, dtype=float) for k, v in inp.items()}
    run["humans_now"][0] = inp["x0"][:2] + 1.5 * heading
    run["humans_vel"][0] = -3.0 * heading
    run["humans_pred"][:, 0] = run["humans_now"][0] + run["humans_vel"][0] * DT * np.arange(N + 1)[:, None]
    return run


def test_the_separation_monitor_takes_the_velocity_given_not_the_predictions_slope(default_dir: Path) -> None:
    """Speed and separation close in at the input's humans_vel: a person predicted to stand but running at
    the robot stops it; one predicted to run at it but standing does not stop it for separation."""
    run = running_at_the_robot(clean_inputs())
    standing = run["humans_now"][0]
    predicted_standing = {k: v.copy() for k, v in run.items()}
    predicted_standing["humans_pred"][:, 0] = standing  # the prediction says nothing about the running
    r = humanmpc.load(default_dir).step(**predicted_standing)
    assert r.reason == "separation" and r.stop_reason == 8
    running_prediction = {k: v.copy() for k, v in run.items()}
    running_prediction["humans_vel"][0] = 0.0  # the tracker says they stand; the prediction runs at the robot
    r = humanmpc.load(default_dir).step(**running_prediction)
    assert r.reason != "separation"


def test_without_velocities_the_solver_takes_those_of_the_predictions_first_interval(default_dir: Path) -> None:
    inp = running_at_the_robot(clean_inputs())
    given = dict(inp, humans_vel=(inp["humans_pred"][1] - inp["humans_pred"][0]) / DT)
    without = {k: v for k, v in inp.items() if k != "humans_vel"}
    assert_same(humanmpc.load(default_dir).step(**without), humanmpc.load(default_dir).step(**given))
    assert humanmpc.load(default_dir).step(**without).reason == "separation"
    with pytest.raises(ValueError, match=r"humans_vel must have shape \(k, 2\) = \(3, 2\)"):
        humanmpc.load(default_dir).step(**dict(inp, humans_vel=np.zeros((2, 2))))


def test_one_microsecond_deadline_stops_inside_the_qp_and_clears(fresh: humanmpc.Solver) -> None:
    inp = clean_inputs()
    fresh.set_params(deadline_ms=0.001)
    r = fresh.step(**inp)
    assert r.reason == "deadline" and r.stop_reason == 3
    assert r.qp_status_name == "timeout"  # caught inside the QP iterations, not only after them
    assert_braking(r, fresh, v0=inp["x0"][3])
    fresh.set_params(deadline_ms=20.0)
    again = fresh.step(**inp)
    assert not again.stop
    reference = humanmpc.load(fresh.path)
    assert_same(again, reference.step(**inp))


FIELDS = [("x0", (i,)) for i in range(4)] + [("goal", (i,)) for i in range(4)] + [
    ("humans_now", (j, k)) for j in range(3) for k in range(2)
] + [("humans_pred", (n, j, k)) for n in (0, 17, 50) for j in range(3) for k in range(2)] + [
    ("humans_vel", (j, k)) for j in range(3) for k in range(2)
] + [
    ("obstacle", (k,)) for k in range(2)
]


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, 1e12], ids=["nan", "inf", "-inf", "absurd"])
def test_non_finite_or_absurd_value_in_every_input_field_stops_then_clears(fresh: humanmpc.Solver,
                                                                          bad: float) -> None:
    inp = clean_inputs()
    reference = humanmpc.load(fresh.path)
    expected_clean = reference.step(**inp)
    for name, index in FIELDS:
        broken = {k: np.array(v, dtype=float) for k, v in inp.items()}
        broken[name][index] = bad
        r = fresh.step(**broken)
        assert r.reason == "invalid_input", f"{name}{list(index)} = {bad}: {r.reason}"
        assert r.status_name == "skipped"
        assert_braking(r, fresh, v0=None if name == "x0" else inp["x0"][3])
        # the failure leaves nothing behind: the next clean step is what a fresh solver gives
        assert_same(fresh.step(**inp), expected_clean)
        fresh.reset()


@pytest.mark.parametrize(("param", "value"), [("q", np.nan), ("kappa", 0.0), ("w_goal", [1, 1, np.inf, 1]),
                                              ("d_h", -1.0), ("a_bounds", [0.5, 1.0]), ("exact_hessian", 2)])
def test_invalid_runtime_parameters_stop_before_anything_is_computed(fresh: humanmpc.Solver, param: str,
                                                                       value: object) -> None:
    inp = clean_inputs()
    params = fresh._params  # bypass the Python checks: firmware can write anything into the struct
    saved = getattr(params, param)
    saved = list(saved) if not isinstance(saved, (float, int)) else saved
    setattr(params, param, value)
    r = fresh.step(**inp)
    assert r.reason == "invalid_params" and r.stop_reason == 2
    assert np.all(np.isfinite(r.u0)) and r.u0[1] == 0.0
    setattr(params, param, saved)
    assert not fresh.step(**inp).stop


def test_infeasible_qp_stops_with_its_reason_and_the_next_step_equals_a_fresh_solver(
    fresh: humanmpc.Solver,
) -> None:
    inp = clean_inputs()
    fast = dict(inp, x0=np.array([0.0, 0.0, 0.1, 3.0]))  # 3 m/s: v <= 1 cannot be reached in 0.1 s
    r = fresh.step(**fast)
    assert r.reason == "qp_failed" and r.qp_status_name == "infeasible"
    assert_braking(r, fresh, v0=3.0)
    reference = humanmpc.load(fresh.path)
    assert_same(fresh.step(**inp), reference.step(**inp))


def test_the_same_inputs_give_bit_identical_outputs_on_fresh_and_reused_solvers(paper_dir: Path) -> None:
    a, b = humanmpc.load(paper_dir), humanmpc.load(paper_dir)
    rng = np.random.default_rng(1)
    sequence = []
    for _ in range(30):
        inp = clean_inputs()
        inp["x0"] = inp["x0"] + rng.normal(0, 0.05, 4)
        sequence.append(inp)
    first = [a.step(**inp) for inp in sequence]
    for ra, inp in zip(first, sequence, strict=True):
        assert_same(ra, b.step(**inp))
    a.reset()
    for ra, inp in zip(first, sequence, strict=True):
        assert_same(ra, a.step(**inp))


def test_step_log_keeps_the_newest_steps_and_writes_them(fresh: humanmpc.Solver, tmp_path: Path) -> None:
    log = fresh.start_log(capacity=5)
    inp = clean_inputs()
    for i in range(8):
        broken = dict(inp, x0=np.array([np.nan, 0, 0, 0])) if i == 6 else inp
        fresh.step(**broken)
    assert isinstance(log, StepLog) and len(log) == 5 and log.total_steps == 8
    assert list(log.column("step")) == [3, 4, 5, 6, 7]
    assert log.stop_counts() == {"invalid_input": 1}
    csv_path = log.write(tmp_path / "steps.csv")
    lines = csv_path.read_text().splitlines()
    assert len(lines) == 6 and "invalid_input" in lines[4]
    json_text = log.write(tmp_path / "steps.json").read_text()
    assert '"total_steps": 8' in json_text
