"""simulate, evaluate and demo evaluate a user's own spec (--spec) or package (--solver-dir), and never
overwrite a generated folder the tools did not create (humanmpc.planners.solver_cache).

Real generated C built by the real compiler throughout; the specs are small (N = 20, N_h <= 3) to keep
the builds short. Every test runs in its own working folder, where the tools keep their cache
(generated/.cache/)."""

from __future__ import annotations

import csv
import os
import shutil
import time
from pathlib import Path

import pytest

import humanmpc
from humanmpc import cli
from humanmpc.codegen.build import is_stale
from humanmpc.codegen.spec import Spec, load_spec
from humanmpc.planners import solver_cache
from humanmpc.planners.solver_cache import CACHE_MARKER, SolverDirError, cache_dir, ensure_solver

from .conftest import make_solver

SMALL = "name: small\nhorizon: {T: 2.0, N: 20}\nhumans: {max: 3}\n"
OTHER = {"name": "mine", "horizon": {"T": 2.0, "N": 20}, "humans": {"max": 2}}  # a user's own solver
SIMULATE = ["simulate", "--scenario", "crossing_group", "--planner", "mpc", "--seed", "0"]
EVALUATE = ["evaluate", "--scenarios", "crossing_group", "--planners", "mpc", "--seeds", "1", "--quiet",
            "--no-figures"]


@pytest.fixture(autouse=True)
def _fresh_choice(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Each test in its own working folder, and the process's solver choice restored after it."""
    monkeypatch.setattr(solver_cache, "_choice", solver_cache.SolverChoice())
    monkeypatch.chdir(tmp_path)


@pytest.fixture(scope="module")
def user_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A package the user generated and built themselves (humanmpc-gen generate + build)."""
    return make_solver(tmp_path_factory.mktemp("user"), OTHER)


def snapshot(folder: Path) -> dict[str, tuple[int, bytes]]:
    """Every file under folder (the build's too) with its modification time and content."""
    return {str(p.relative_to(folder)): (p.stat().st_mtime_ns, p.read_bytes())
            for p in sorted(folder.rglob("*")) if p.is_file()}


def write_spec(path: Path, text: str = SMALL) -> Path:
    path.write_text(text)
    return path


def command(name: str, out: Path) -> list[str]:
    return {"simulate": SIMULATE, "evaluate": [*EVALUATE, "--out", str(out)],
            "demo": ["demo", "--out", str(out)]}[name]


@pytest.mark.parametrize("name", ["simulate", "evaluate", "demo"])
def test_a_user_folder_of_another_spec_is_named_in_the_error_and_left_unchanged(
        name: str, user_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write_spec(tmp_path / "small.yaml")
    before = snapshot(user_dir)
    code = cli.main([*command(name, tmp_path / "out"), "--spec", str(spec), "--solver-dir", str(user_dir)])
    out = capsys.readouterr()
    assert code == 2
    held = humanmpc.load(user_dir).spec_hash
    assert f"{user_dir} holds the solver 'mine' of spec sha256 {held}" in out.err
    assert load_spec(spec).digest() in out.err and "humanmpc-gen generate" in out.err
    assert "ended by" not in out.out and not (tmp_path / "out").exists()  # no episode ran
    assert snapshot(user_dir) == before
    assert not (tmp_path / "generated").exists()  # and nothing was generated instead


def test_a_folder_at_a_cache_path_the_tools_did_not_create_is_never_regenerated(
        user_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write_spec(tmp_path / "small.yaml")
    # the user's own package, put where the tools would keep small.yaml's solver
    mine = cache_dir(load_spec(spec))
    mine.parent.mkdir(parents=True)
    shutil.copytree(user_dir, mine)  # copy2: the files keep their modification times
    before = snapshot(mine)
    assert cli.main([*SIMULATE, "--spec", str(spec)]) == 2
    err = capsys.readouterr().err
    assert f"{mine} is where humanmpc's tools keep the solver 'small'" in err
    assert f"no {CACHE_MARKER} marker" in err and humanmpc.load(mine).spec_hash in err
    assert snapshot(mine) == before
    assert sorted(p.name for p in mine.parent.iterdir()) == [".lock", mine.name]  # nothing else generated


def test_simulate_with_a_spec_runs_the_mpc_on_that_spec_s_solver_from_the_cache_and_touches_no_other_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write_spec(tmp_path / "small.yaml")
    digest = load_spec(spec).digest()
    # the folder the old simulate regenerated with the default spec: here the user's own solver
    users = make_solver(tmp_path / "generated", OTHER)
    os.rename(users, tmp_path / "generated" / "paper")
    before = snapshot(tmp_path / "generated" / "paper")

    assert cli.main([*SIMULATE, "--spec", str(spec)]) == 0
    out = capsys.readouterr().out
    cached = (tmp_path / cache_dir(load_spec(spec))).resolve()
    # the planner that ran loaded the spec's solver: its folder, spec hash and sizes as loaded
    assert f"solver: {cached} ('small', spec sha256 {digest}, N=20, N_h=3, dt=0.1 s)" in out
    assert "crossing_group seed 0 with mpc: ended by" in out
    assert (cached / CACHE_MARKER).is_file()
    solver = humanmpc.load(cached, build_if_needed=False)
    assert solver.spec_hash == digest and (solver.dims.N, solver.dims.nh) == (20, 3)
    assert snapshot(tmp_path / "generated" / "paper") == before
    assert sorted(p.name for p in (tmp_path / "generated").iterdir()) == [".cache", "paper"]

    # the next run reuses the cached solver as it is
    cached_files = snapshot(cached)
    assert ensure_solver(spec=load_spec(spec)).resolve() == cached
    assert snapshot(cached) == cached_files
    # the tools' own folder, and only theirs, is rebuilt when its sources are newer than the library
    source = cached / "small.c"
    os.utime(source, ns=(time.time_ns(), time.time_ns() + 10**9))
    assert is_stale(cached)
    assert ensure_solver(spec=load_spec(spec)).resolve() == cached and not is_stale(cached)


def test_evaluate_with_a_solver_dir_uses_it_as_it_is_in_its_dask_workers(
        user_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    before = snapshot(user_dir)
    out = tmp_path / "evaluation"
    # two seeds on two workers: an episode run on any other solver than the N = 20 one fails on the
    # prediction horizon (20 intervals), so both rows prove the workers loaded the user's solver
    code = cli.main(["evaluate", "--scenarios", "crossing_group", "--planners", "mpc", "mpc_paper", "--seeds", "2",
                     "--workers", "2", "--quiet", "--no-figures", "--out", str(out), "--solver-dir", str(user_dir)])
    assert code == 0, capsys.readouterr().err
    with (out / "runs.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert sorted((r["planner"], r["seed"]) for r in rows) == [("mpc", "0"), ("mpc", "1"),
                                                                ("mpc_paper", "0"), ("mpc_paper", "1")]
    assert snapshot(user_dir) == before
    assert not (tmp_path / "generated").exists()


@pytest.mark.parametrize("name", ["simulate", "evaluate", "demo"])
def test_an_invalid_spec_exits_2_naming_the_file_and_the_key_before_any_episode(
        name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write_spec(tmp_path / "broken.yaml", "horizon: {T: 2.0, N: 20}\nhumans: {max: 3, d_hh: 0.5}\n")
    t0 = time.perf_counter()
    code = cli.main([*command(name, tmp_path / "out"), "--spec", str(spec)])
    out = capsys.readouterr()
    assert code == 2
    assert f"invalid {spec}" in out.err and "humans.d_hh: unknown key" in out.err and "d_h" in out.err
    assert "ended by" not in out.out and "running" not in out.err and not (tmp_path / "out").exists()
    assert not (tmp_path / "generated").exists()
    assert time.perf_counter() - t0 < 5.0


def test_a_spec_whose_interval_is_not_the_control_period_is_refused_before_anything_is_generated(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write_spec(tmp_path / "coarse.yaml", "horizon: {T: 5.0, N: 20}\n")
    assert cli.main([*SIMULATE, "--spec", str(spec)]) == 2
    err = capsys.readouterr().err
    assert f"{spec}: horizon.T / horizon.N = 0.25 s" in err and "T: 2 for N: 20" in err
    assert not (tmp_path / "generated").exists()


def test_a_solver_dir_that_is_missing_or_not_built_is_refused_without_building_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main([*SIMULATE, "--solver-dir", str(tmp_path / "nowhere")]) == 2
    assert f"solver folder {tmp_path / 'nowhere'} does not exist" in capsys.readouterr().err
    unbuilt = make_solver(tmp_path, OTHER, built=False)
    before = snapshot(unbuilt)
    assert cli.main([*SIMULATE, "--solver-dir", str(unbuilt)]) == 2
    assert f"build it (humanmpc-gen build {unbuilt})" in capsys.readouterr().err
    assert snapshot(unbuilt) == before
    with pytest.raises(SolverDirError, match="missing or older"):
        ensure_solver(unbuilt)


def test_make_planner_loads_the_selected_solver_and_by_default_the_default_spec_s_cache_folder(
        user_dir: Path) -> None:
    from humanmpc.planners.mpc import DEFAULT_SOLVER_DIR
    from humanmpc.planners.mpc import ensure_solver as reexported
    from humanmpc.planners.registry import make_planner, select_solver

    choice = solver_cache.selected_solver()
    assert choice.spec is None and choice.solver_dir is None
    expected = Path("generated", ".cache", f"paper-{solver_cache.cache_key(Spec())}")
    assert expected == DEFAULT_SOLVER_DIR == solver_cache.DEFAULT_SOLVER_DIR and reexported is ensure_solver
    select_solver(solver_dir=user_dir)
    held = humanmpc.load(user_dir).spec_hash
    for name in ("mpc", "mpc_paper"):
        loaded = make_planner(name).solver  # type: ignore[attr-defined]
        assert (loaded.path, loaded.spec_hash, loaded.dims.nh) == (user_dir.resolve(), held, 2)
