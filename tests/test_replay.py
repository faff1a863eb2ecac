"""Replays: building, saving, loading (with checks), per-step inputs, and feeding solvers in order."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import humanmpc
from humanmpc.codegen.spec import resolve_spec
from humanmpc.compare.replay import Replay, ReplayError, concatenate, replay_solver, synthetic_replay

from .conftest import make_solver

SPEC = resolve_spec({"humans": {"max": 4}, "horizon": {"N": 10, "T": 1.0}})


def steps(n: int = 5, seed: int = 0) -> list[dict[str, Any]]:
    rng = np.random.default_rng(seed)
    out = []
    for t in range(n):
        k = t % 5  # 0..4 humans
        now = rng.uniform(-3, 3, (k, 2))
        out.append({
            "x0": rng.normal(size=4), "goal": np.array([5.0, 0.0, 0.0, 0.8]), "humans_now": now,
            "humans_pred": now[None] + 0.1 * np.arange(11)[:, None, None],
            "obstacle": None if t % 2 else rng.normal(size=2),
        })
    return out


def test_from_steps_pads_and_inputs_cut_back() -> None:
    src = steps()
    r = Replay.from_steps(src, SPEC, scenario="unit", seed=7)
    assert r.steps == len(r) == 5 and r.NH == 4 and r.N == 10 and r.dt == pytest.approx(0.1)
    assert r.n_humans.tolist() == [0, 1, 2, 3, 4]
    assert r.humans_pred.shape == (5, 11, 4, 2) and r.humans_now.shape == (5, 4, 2)
    assert np.all(r.humans_now[1, 1:] == 0)  # padding
    for t, s in enumerate(src):
        inp = r.inputs(t)
        assert set(inp) == {"x0", "goal", "humans_now", "humans_pred", "obstacle"}
        np.testing.assert_array_equal(inp["humans_now"], s["humans_now"])
        np.testing.assert_array_equal(inp["humans_pred"], s["humans_pred"])
        np.testing.assert_array_equal(inp["x0"], s["x0"])
        assert (inp["obstacle"] is None) == (s["obstacle"] is None)
    assert r.params["w_goal"] == list(SPEC.weights.goal) and r.params["d_h"] == SPEC.humans.d_h
    assert r.spec_hash == SPEC.digest()
    with pytest.raises(IndexError, match="outside"):
        r.inputs(5)


def test_objects_with_attributes_are_accepted() -> None:
    @dataclass
    class Obs:  # like humanmpc.planner.Observation: x instead of x0
        x: np.ndarray
        goal: np.ndarray
        humans_now: np.ndarray
        humans_pred: np.ndarray
        obstacle: np.ndarray | None

    s = steps(2)
    r = Replay.from_steps([Obs(d["x0"], d["goal"], d["humans_now"], d["humans_pred"], d["obstacle"]) for d in s], SPEC)
    np.testing.assert_array_equal(r.x0, np.array([d["x0"] for d in s]))


def test_save_load_round_trip(tmp_path: Path) -> None:
    r = Replay.from_steps(steps(), SPEC, scenario="unit", seed=3, params={**Replay.from_steps(steps(1), SPEC).params,
                                                                          "q": 3.5})
    p = r.save(tmp_path / "r.npz")
    back = Replay.load(p)
    for key in ("x0", "goal", "n_humans", "humans_now", "humans_pred", "has_obstacle", "obstacle"):
        np.testing.assert_array_equal(getattr(back, key), getattr(r, key))
    assert (back.N, back.dt, back.NH, back.scenario, back.seed) == (10, 0.1, 4, "unit", 3)
    assert back.params["q"] == 3.5 and back.spec_hash == SPEC.digest()
    with pytest.raises(ReplayError, match=r"must end in \.npz"):
        r.save(tmp_path / "r.bin")


def _tamper(path: Path, out: Path, **changes: Any) -> Path:
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays["meta"]))
    for k, v in changes.items():
        if k in meta:
            meta[k] = v
        else:
            arrays[k] = v
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez(out, **arrays)
    return out


def test_load_refuses_broken_files_with_reasons(tmp_path: Path) -> None:
    good = Replay.from_steps(steps(), SPEC).save(tmp_path / "good.npz")
    with pytest.raises(ReplayError, match="no such replay"):
        Replay.load(tmp_path / "missing.npz")
    (tmp_path / "junk.npz").write_bytes(b"not a zip file")
    with pytest.raises(ReplayError, match="not a readable"):
        Replay.load(tmp_path / "junk.npz")
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    with pytest.raises(ReplayError, match="missing meta"):
        Replay.load(tmp_path / "other.npz")
    with pytest.raises(ReplayError, match="format version"):
        Replay.load(_tamper(good, tmp_path / "v.npz", version=99))
    with pytest.raises(ReplayError, match=r"x0: shape \(5, 3\)"):
        Replay.load(_tamper(good, tmp_path / "s.npz", x0=np.zeros((5, 3))))
    bad = np.zeros((5, 4))
    bad[2, 1] = np.nan
    with pytest.raises(ReplayError, match=r"goal: non-finite values at step\(s\) \[2\]"):
        Replay.load(_tamper(good, tmp_path / "n.npz", goal=bad))
    with pytest.raises(ReplayError, match="n_humans: must be in"):
        Replay.load(_tamper(good, tmp_path / "h.npz", n_humans=np.array([0, 1, 9, 0, 0])))
    with pytest.raises(ReplayError, match="do not match the spec"):
        Replay.load(_tamper(good, tmp_path / "N.npz", NH=3, humans_now=np.zeros((5, 3, 2)),
                            humans_pred=np.zeros((5, 11, 3, 2))))
    with pytest.raises(ReplayError, match="altered"):
        Replay.load(_tamper(good, tmp_path / "hash.npz", spec_hash="0" * 64))
    with pytest.raises(ReplayError, match="problem parameters"):
        Replay.load(_tamper(good, tmp_path / "p.npz", params={"q": 1.0}))


def test_from_steps_refuses_wrong_inputs() -> None:
    s = steps(5)
    s[4]["humans_now"] = np.zeros((5, 2))
    with pytest.raises(ReplayError, match=r"step 4: 5 humans, but the spec handles at most N_h = 4"):
        Replay.from_steps(s, SPEC)
    s = steps(3)
    s[2]["humans_pred"] = np.zeros((10, 2, 2))
    with pytest.raises(ReplayError, match=r"step 2: humans_pred must have shape \(N\+1, k, 2\) = \(11, 2, 2\)"):
        Replay.from_steps(s, SPEC)
    with pytest.raises(ReplayError, match="needs x0"):
        Replay.from_steps([{"goal": [0, 0, 0, 0]}], SPEC)


class Recorder:
    """A fake solver that remembers what it was given and answers with its call count."""

    def __init__(self, N: int) -> None:
        self.N = N
        self.calls: list[dict[str, Any]] = []
        self.resets = 0
        self.params: dict[str, Any] = {}

    def reset(self) -> None:
        self.resets += 1
        self.calls.clear()

    def set_params(self, **kw: Any) -> None:
        self.params.update(kw)

    def step(self, x0: Any, goal: Any, humans_now: Any, humans_pred: Any, obstacle: Any) -> Any:
        self.calls.append({"x0": x0, "humans_now": humans_now, "obstacle": obstacle})
        n = len(self.calls)

        @dataclass
        class R:
            x: np.ndarray
            u: np.ndarray
            status: int
            qp_iterations: int

        return R(np.full((self.N + 1, 4), float(n)), np.full((self.N, 2), float(n)), n % 2, 10 + n)


def test_replay_solver_feeds_steps_in_order_with_the_replay_params() -> None:
    r = Replay.from_steps(steps(), SPEC)
    solver = Recorder(10)
    run = replay_solver(solver, r, name="fake")
    assert solver.resets == 1 and solver.params == r.params
    assert [c["humans_now"].shape[0] for c in solver.calls] == [0, 1, 2, 3, 4]
    for t, c in enumerate(solver.calls):
        np.testing.assert_array_equal(c["x0"], r.x0[t])
    assert run.solver == "fake" and run.status.tolist() == [1, 0, 1, 0, 1] and run.failures == 3
    assert run.qp_iterations.tolist() == [11, 12, 13, 14, 15]
    assert np.all(run.x[:, 0, 0] == np.arange(1, 6)) and np.all(run.time_ms == run.wall_ms)
    assert np.all(run.wall_ms >= 0)


def test_replay_solver_with_the_generated_solver(tmp_path: Path) -> None:
    d = make_solver(tmp_path, {"name": "rep", "humans": {"max": 4}, "horizon": {"N": 10, "T": 1.0}})
    solver = humanmpc.load(d)
    r = synthetic_replay(resolve_spec({"name": "rep", "humans": {"max": 4}, "horizon": {"N": 10, "T": 1.0}}),
                         3, 6, seed=1)
    run = replay_solver(solver, r, keep_results=True)
    assert run.x.shape == (6, 11, 4) and run.u.shape == (6, 10, 2) and len(run.results) == 6
    assert np.all(np.isfinite(run.u)) and np.all(run.time_ms > 0) and np.all(run.qp_iterations >= 0)
    np.testing.assert_allclose(run.x[:, 0], r.x0, atol=1e-9)  # every plan starts at the measurement
    wrong = synthetic_replay(resolve_spec({"humans": {"max": 4}, "horizon": {"N": 12, "T": 1.2}}), 1, 1, seed=0)
    with pytest.raises(ReplayError, match="N=10"):
        replay_solver(solver, wrong)


def test_synthetic_replay_is_reproducible_and_drives_to_the_goal() -> None:
    spec = resolve_spec({"humans": {"max": 3}, "horizon": {"N": 20, "T": 2.0}})
    a = synthetic_replay(spec, 3, 12, seed=5)
    b = synthetic_replay(spec, 3, 12, seed=5)
    np.testing.assert_array_equal(a.x0, b.x0)
    np.testing.assert_array_equal(a.humans_now, b.humans_now)
    assert a.n_humans.tolist() == [3] * 12 and a.has_obstacle.all()
    assert a.x0[-1, 0] > 0.3 and a.x0[-1, 3] > 0.3  # moving towards the goal at (8, 0)
    # constant-velocity predictions start at the current positions
    np.testing.assert_allclose(a.humans_pred[:, 0], a.humans_now)
    assert np.all(np.linalg.norm(a.humans_now[0], axis=1) >= 1.5)
    c = concatenate([a, b])
    assert c.steps == 24 and c.scenario == f"{a.scenario}+{b.scenario}"
    with pytest.raises(ValueError, match="n_humans"):
        synthetic_replay(spec, 4, 2, seed=0)
