"""Evaluation campaigns: the grid, the Parquet results, real Dask clusters (distributed.LocalCluster) against
the sequential run, an interrupted campaign resumed, parameter sweeps, concurrent solver builds.

Every episode here is real: the CrowdNav circle crossing with 5 people in both crowd models (the social
force model and ORCA through pyrvo), the generated C controller (``mpc``, the default spec's solver built
once for the session) and the DWB baseline."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import cloudpickle
import numpy as np
import pyarrow.parquet as pq
import pytest
from distributed import Client, LocalCluster

import humanmpc
from humanmpc import cli
from humanmpc.codegen.spec import Spec, resolve_spec
from humanmpc.eval.campaign import Campaign, EpisodeTask, SolverRef, parse_grid
from humanmpc.eval.engines import CampaignEngineError, DaskEngine, InProcess
from humanmpc.eval.evaluate import check_planners
from humanmpc.eval.metrics import compute_metrics
from humanmpc.eval.runner import run_campaign
from humanmpc.eval.store import CampaignFolderError, ResultStore
from humanmpc.eval.traces import trace_to_log
from humanmpc.eval.worker import MEASURED_COLUMNS, make_task_planner, run_task
from humanmpc.planners import solver_cache
from humanmpc.planners.registry import planner_factory
from humanmpc.planners.solver_cache import cached_solver
from humanmpc.sim.scenarios import make_scenario

from .conftest import needs_data

cloudpickle.register_pickle_by_value(sys.modules[__name__])  # this module's functions run on Dask workers

SEEDS = (0, 1, 2, 3)
# The controller's deadline (20 ms) measures wall time: on a busy machine a step can miss it, and the episode
# then goes on differently. 1 s keeps the runs compared here free of the clock.
UNCLOCKED = ("deadline_ms", (1000,))  # as the command line reads --grid deadline_ms=1000
GRID = ["--scenarios", "crowdnav_circle_5", "--crowds", "social_force", "orca", "--planners", "mpc", "dwb",
        "--seeds", str(len(SEEDS)), "--grid", "deadline_ms=1000"]
QUIET = lambda _m: None  # noqa: E731


@pytest.fixture(autouse=True)
def _restore_solver_choice(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(solver_cache, "_choice", solver_cache.SolverChoice())


def campaign(default_dir: Path, traces: str = "all", **changes: Any) -> Campaign:
    """crowdnav_circle_5 x {social force, ORCA} x {mpc (1 s deadline), dwb} x 4 seeds = 16 episodes on the
    default solver."""
    base = Campaign(("crowdnav_circle_5",), ("social_force", "orca"), ("mpc", "dwb"), SEEDS,
                    SolverRef(Spec().digest(), None, str(default_dir)), grid=(UNCLOCKED,), tunable=frozenset({"mpc"}),
                    traces=traces)
    return replace(base, **changes)


def tasks_of(c: Campaign) -> list[EpisodeTask]:
    return c.tasks({name: planner_factory(name) for name in c.planners})


def same_row(a: dict[str, Any], b: dict[str, Any]) -> list[str]:
    """The columns where two rows of the same episode differ (measured times and the worker aside)."""
    out = []
    for col in sorted(set(a) | set(b)):
        absent = 0 if col.startswith("stops[") else None  # a reason no episode of a folder stopped for
        x, y = a.get(col, absent), b.get(col, absent)
        if col in MEASURED_COLUMNS or x == y or (isinstance(x, float) and isinstance(y, float) and
                                                 math.isnan(x) and math.isnan(y)):
            continue
        out.append(f"{col}: {x} != {y}")
    return out


@dataclass(frozen=True)
class Reference:
    rows: dict[str, dict[str, Any]]  # by key
    store: ResultStore


@pytest.fixture(scope="module")
def reference(default_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Reference:
    """The 16 episodes run one after another in this process (the sequential run), traces kept."""
    store = ResultStore(tmp_path_factory.mktemp("sequential"))
    c = campaign(default_dir)
    store.open(c.description())
    try:
        record = run_campaign(tasks_of(c), store, InProcess(), progress=False, say=QUIET)
    finally:
        solver_cache.select_solver()  # the tasks chose this process's solver; back to the default
    assert record.ran == 16 and not record.interrupted
    return Reference({r["key"]: r for r in store.read_rows()}, store)


@needs_data
def test_the_grid_has_every_cell_once_with_recorded_scenes_in_their_own_crowd(default_dir: Path) -> None:
    c = campaign(default_dir, scenarios=("crowdnav_circle_5", "biwi_hotel"), seeds=(0, 1), traces="first",
                 grid=parse_grid(["q=10,50", "reaction_time=0.3,0.5"]))
    tasks = tasks_of(c)
    # circle: 2 crowds x (4 grid points of mpc + dwb) x 2 seeds; biwi_hotel: once (recorded) x 5 x 2
    assert len(tasks) == 2 * 5 * 2 + 5 * 2 and len({t.key for t in tasks}) == len(tasks)
    assert {t.crowd for t in tasks if t.scenario == "biwi_hotel"} == {"recorded"}
    assert {t.planner.label for t in tasks} == {"dwb", "mpc[q=10,reaction_time=0.3]", "mpc[q=10,reaction_time=0.5]",
                                                "mpc[q=50,reaction_time=0.3]", "mpc[q=50,reaction_time=0.5]"}
    assert all(t.traces == (t.seed == 0) for t in tasks)
    assert tasks[0].key == "crowdnav_circle_5/social_force/mpc[q=10,reaction_time=0.3]/0"
    assert all(t.factory is planner_factory(t.planner.name) for t in tasks)


@pytest.mark.parametrize(("items", "message"), [
    (["q"], "write NAME=V1,V2"), (["q=1,x"], "'x' is not a number"), (["q=1", "q=2"], "names q twice"),
    (["q=1,1"], "repeated"), (["w_goal=0.5:0.5:0:nan"], "not a finite number"),
])
def test_a_malformed_grid_is_refused_naming_it(items: list[str], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        parse_grid(items)


def test_a_parameter_sweep_runs_every_grid_point_with_its_values(default_dir: Path) -> None:
    grid = parse_grid(["q=10,50", "w_goal=0.5:0.5:0:25"])
    c = campaign(default_dir, grid=grid, planners=("mpc",), seeds=(0,))
    for task in tasks_of(c):
        params = make_task_planner(task).controller.params  # type: ignore[attr-defined]
        assert params["q"] == dict(task.planner.params)["q"]
        assert tuple(params["w_goal"]) == (0.5, 0.5, 0.0, 25.0)
    ref = campaign(default_dir).solver
    with pytest.raises(ValueError, match=r"(?s)--grid mpc\[q=-1\]: .*q must be"):
        check_planners(["mpc", "dwb"], parse_grid(["q=-1"]), ref, c.config)
    with pytest.raises(ValueError, match="unknown parameter 'speed'"):
        check_planners(["mpc"], parse_grid(["speed=1"]), ref, c.config)
    with pytest.raises(ValueError, match="none of the planners dwb"):
        campaign(default_dir, planners=("dwb",), grid=grid)


def test_a_sweep_on_the_command_line_is_checked_before_any_episode(default_dir: Path, tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    code = cli.main(["evaluate", *GRID, "--grid", "q=10,-5", "--solver-dir", str(default_dir), "--out",
                     str(tmp_path / "sweep"), "--quiet"])
    assert code == 2 and "q must be" in capsys.readouterr().err
    assert not (tmp_path / "sweep" / "episodes").exists()


def test_a_dask_cluster_of_two_workers_gives_the_rows_of_the_sequential_run(
        default_dir: Path, reference: Reference, tmp_path: Path) -> None:
    """An existing cluster (two worker processes), reached by its scheduler's address (--scheduler)."""
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        engine = DaskEngine(scheduler=cluster.scheduler_address)
        store = ResultStore(tmp_path)
        c = campaign(default_dir)
        store.open(c.description())
        try:
            record = run_campaign(tasks_of(c), store, engine, progress=False, say=QUIET)
        finally:
            engine.close()
    rows = {r["key"]: r for r in store.read_rows()}
    assert record.ran == 16 and record.workers == 2 and set(rows) == set(reference.rows)
    for key, row in rows.items():
        assert same_row(row, reference.rows[key]) == [], key
    workers = {r["worker"] for r in rows.values()}
    assert len(workers) == 2 and not any(w.endswith(f":{os.getpid()}") for w in workers)
    assert store.trace_keys() == set(rows)


def test_the_metrics_of_a_stored_trace_are_those_of_its_row(reference: Reference) -> None:
    for key, row in reference.rows.items():
        trace = reference.store.read_trace(key)
        assert trace is not None and trace.num_rows >= 2
        log = trace_to_log(trace, make_scenario(row["scenario"], row["seed"]), row["planner"], row["ended_by"], 0.1)
        again = compute_metrics(log).as_row()
        assert same_row({**row, **again}, row) == [], key
        assert (log.human_velocities is None) == np.isnan(row["people_speed_change"])


def test_an_interrupted_campaign_resumes_without_repeating_or_losing_an_episode(
        reference: Reference, default_dir: Path, tmp_path: Path) -> None:
    """Ctrl-C (KeyboardInterrupt) after three episodes: their rows are written, the run is logged as
    interrupted, and the next run runs exactly the others."""
    c = campaign(default_dir, traces="none")
    tasks = tasks_of(c)
    store = ResultStore(tmp_path)
    store.open(c.description())
    calls = []

    def interrupted(task: EpisodeTask) -> Any:
        if len(calls) == 3:
            raise KeyboardInterrupt
        calls.append(task.key)
        return run_task(task)

    with pytest.raises(KeyboardInterrupt):
        run_campaign(tasks, store, InProcess(), progress=False, flush_rows=100, fn=interrupted, say=QUIET)
    assert store.done_keys() == set(calls) and store.runs()[-1]["interrupted"]
    resumed: list[str] = []

    def counted(task: EpisodeTask) -> Any:
        resumed.append(task.key)
        return run_task(task)

    record = run_campaign(tasks, store, InProcess(), progress=False, fn=counted, say=QUIET)
    assert (record.done_before, record.ran) == (3, 13) and not set(resumed) & set(calls)
    rows = store.read_rows()
    assert sorted(r["key"] for r in rows) == sorted(t.key for t in tasks)
    for row in rows:
        assert same_row(row, reference.rows[row["key"]]) == []


def _interrupt(argv: list[str], out: Path, parts: int, sig: int) -> int:
    """Start humanmpc-gen (in its own process group), send ``sig`` to the group once ``parts`` Parquet parts
    are there, return its exit code."""
    proc = subprocess.Popen([sys.executable, "-m", "humanmpc.cli", *argv], start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        while len(list((out / "episodes").glob("part-*.parquet"))) < parts:
            assert proc.poll() is None, proc.stderr.read().decode() if proc.stderr else ""
            assert time.monotonic() < deadline, "no results after 120 s"
            time.sleep(0.02)
        os.killpg(proc.pid, sig)
        return proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def test_a_terminated_then_killed_dask_campaign_resumes_without_repeating_or_losing_an_episode(
        reference: Reference, default_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """humanmpc-gen evaluate on a local cluster of 2 workers: stopped by SIGTERM (it writes what it has,
    logs the run as interrupted and exits 130), run again and killed by SIGKILL (no clean-up at all, its
    workers with it); the same command then runs exactly the missing episodes."""
    out = tmp_path / "campaign"
    argv = ["evaluate", *GRID, "--workers", "2", "--solver-dir", str(default_dir), "--out", str(out),
            "--traces", "none", "--flush-every", "1", "--quiet", "--no-figures"]
    store = ResultStore(out)
    assert _interrupt(argv, out, 2, signal.SIGTERM) == 130
    first = store.done_keys()
    assert store.runs()[-1]["interrupted"] and store.runs()[-1]["ran"] == len(first)
    assert _interrupt(argv, out, len(first) + 2, signal.SIGKILL) == -signal.SIGKILL
    done = store.done_keys()
    assert first < done and len(done) < 16
    capsys.readouterr()
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert f"16 episodes: {len(done)} already in {out}, {16 - len(done)} to run" in err
    rows = store.read_rows()  # raises on a key with two rows
    assert sorted(r["key"] for r in rows) == sorted(reference.rows)
    for row in rows:
        assert same_row(row, reference.rows[row["key"]]) == []
    assert store.runs()[-1]["ran"] == 16 - len(done)
    assert not list(out.rglob(".*.tmp"))


def test_the_results_folder_belongs_to_one_campaign_and_is_cleaned_of_what_a_killed_writer_left(
        default_dir: Path, tmp_path: Path) -> None:
    c = campaign(default_dir)
    store = ResultStore(tmp_path)
    store.open(c.description())
    store.append([{"key": "a", "x": 1.0, "stops[deadline]": 2}, {"key": "b", "x": 2.0}])
    store.append([{"key": "c", "x": 3.0, "stops[separation]": 1}])
    assert store.done_keys() == {"a", "b", "c"}
    rows = store.read_rows()
    assert [(r["key"], r["stops[deadline]"], r["stops[separation]"]) for r in rows] == [
        ("a", 2, 0), ("b", 0, 0), ("c", 0, 1)]
    (store.episodes / ".part-000002.parquet.tmp").write_bytes(b"half a part")
    pq.write_table(pq.read_table(store.episodes / "part-000001.parquet"), store.traces / "part-000009.parquet")
    store.open(c.description())  # the same campaign: resumed, cleaned
    assert not list(store.episodes.glob(".*.tmp")) and not (store.traces / "part-000009.parquet").exists()
    assert store.done_keys() == {"a", "b", "c"}
    other = campaign(default_dir, seeds=(0, 1))
    with pytest.raises(CampaignFolderError, match=r"seeds: \[0, 1, 2, 3\] there, \[0, 1\] now.*--fresh"):
        store.open(other.description())
    store.open(other.description(), fresh=True)
    assert store.done_keys() == set()


def _build(spec: Spec, root: str) -> tuple[str, bool]:
    said: list[str] = []
    path = cached_solver(spec, Path(root), log=said.append)
    return str(path.resolve()), any("cached in" in m for m in said)


def test_workers_building_the_same_solver_at_once_build_it_once(tmp_path: Path) -> None:
    """Two Dask workers ask for one spec's solver in an empty cache at the same moment: one generates and
    builds it (in a staging folder, under the cache's lock), the other waits and uses it."""
    spec = resolve_spec({"name": "race", "horizon": {"T": 2.0, "N": 20}, "humans": {"max": 2}})
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        results = client.run(_build, spec, str(tmp_path / "cache"))
    assert len(results) == 2
    paths = {p for p, _ in results.values()}
    assert len(paths) == 1 and sorted(g for _, g in results.values()) == [False, True]
    built = Path(paths.pop())
    assert sorted(p.name for p in (tmp_path / "cache").iterdir()) == [".lock", built.name]
    assert humanmpc.load(built, build_if_needed=False).dims.N == 20


def test_a_scheduler_that_does_not_answer_is_named_with_what_to_do() -> None:
    with pytest.raises(CampaignEngineError, match=r"--scheduler tcp://127.0.0.1:9: no Dask scheduler answered.*"
                                                  r"--workers N"):
        DaskEngine(scheduler="tcp://127.0.0.1:9", connect_timeout=1.0)
