"""Row screening: distance rows far from binding stay out of the QP and are checked at its solution.

The claim is exactness: whatever is screened, the step solves the whole QP (re-solving with any
screened row its solution violates). Proven against the whole QP solved from scratch by the same QP
solver (white box, in C, over an RTI closed loop in a crowd of 30), and at the NLP level: the full
SQP reaches the same optimum with and without screening.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import humanmpc

from .conftest import make_solver, require_tool
from .test_sqp import random_scene

C_DIR = Path(__file__).resolve().parent / "c"
STRICT = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]


@pytest.fixture(scope="module")
def crowd_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    # room for every row (51 x 31) in one QP: these tests compare screened QPs with whole ones
    return make_solver(tmp_path_factory.mktemp("screen"), {"name": "screen30", "humans": {"max": 30},
                                                           "solver": {"qp_rows": 51 * 31}})


def test_every_screened_rti_qp_solution_solves_the_whole_qp(crowd_dir: Path, tmp_path: Path) -> None:
    exe = tmp_path / "screening_check"
    cmd = [require_tool("gcc"), *STRICT, "-O2", '-DSOLVER_SOURCE="screen30.c"', "-DSOLVER_PREFIX=screen30_",
           "-I", str(crowd_dir), str(C_DIR / "screening_check.c"), str(crowd_dir / "screen30_model.c"), "-lm",
           "-o", str(exe)]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr
    proc = subprocess.run([str(exe), "200"], capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    r = json.loads(proc.stdout.strip().splitlines()[-1])
    assert r["checked"] >= 150
    assert r["resolves"] >= 1  # the path that admits violated rows and solves again was taken
    assert r["far_rows"] >= 1  # rows the linearisation left unevaluated (beyond the radius), checked too
    assert r["obj_rel"] <= 1e-5  # the QP tolerance is 1e-6 (scaled); both are solutions to it
    assert r["ineq"] <= 1e-8  # no row of the whole QP is violated at the screened solution
    assert r["stat"] <= max(1e-6, 100 * r["stat_full"])


@pytest.mark.parametrize("seed", range(6))
def test_full_sqp_reaches_the_same_optimum_with_and_without_screening(crowd_dir: Path, seed: int) -> None:
    solver = humanmpc.load(crowd_dir)
    scene = random_scene(np.random.default_rng(4000 + seed), 25)
    results = []
    solver.set_params(deadline_ms=1e5)  # a reference solve, not a control period's (20 ms)
    for screening in (False, True):
        solver.set_params(row_screening=screening)
        solver.reset()
        results.append(solver.solve(scene.x0, scene.goal, scene.humans_now, scene.humans_pred, scene.obstacle,
                                    max_iter=300, tol=1e-9))
    whole, screened = results
    assert whole.status_name == screened.status_name == "solved"
    assert screened.cost == pytest.approx(whole.cost, rel=1e-8)
    assert np.max(np.abs(screened.x - whole.x)) <= 1e-5


def test_row_screening_is_a_runtime_parameter_checked_like_the_others(crowd_dir: Path) -> None:
    solver = humanmpc.load(crowd_dir)
    assert solver.params["row_screening"] == 1
    solver.set_params(row_screening=False)
    assert solver.params["row_screening"] == 0
    with pytest.raises(ValueError, match="row_screening must be 0 or 1"):
        solver.set_params(row_screening=2)


CAPACITY = 60  # distance rows one QP of the capped solver holds, of 51 x 31


@pytest.fixture(scope="module")
def capped_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_solver(tmp_path_factory.mktemp("capped"), {"name": "capped30", "humans": {"max": 30},
                                                           "solver": {"qp_rows": CAPACITY}})


def test_a_qp_beyond_its_row_capacity_holds_the_rows_of_smallest_margin_and_the_sqp_the_same_optimum(
        crowd_dir: Path, capped_dir: Path) -> None:
    whole, capped = humanmpc.load(crowd_dir), humanmpc.load(capped_dir)
    solved = 0
    for seed in range(8):
        scene = random_scene(np.random.default_rng(5000 + seed), 25)
        results = []
        for solver in (whole, capped):
            solver.set_params(deadline_ms=1e5)
            solver.reset()
            # from a cold start nothing is screened: every row of the 25 people near the plan is in the first QP
            results.append(solver.solve(scene.x0, scene.goal, scene.humans_now, scene.humans_pred, scene.obstacle,
                                        max_iter=300, tol=1e-9))
        a, b = results
        assert a.qp_rows == b.qp_rows > CAPACITY and a.qp_rows_capped == 0 and b.qp_rows_capped >= 1
        if a.status_name != "solved":  # a scene the SQP does not converge on in 300 iterations (one of eight)
            continue
        solved += 1
        assert b.status_name == "solved"
        assert b.cost == pytest.approx(a.cost, rel=1e-8)
        assert np.max(np.abs(b.x - a.x)) <= 1e-6
    assert solved >= 6
