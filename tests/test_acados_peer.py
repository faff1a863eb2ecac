"""acados as a peer (PyPI's prebuilt acados under Python 3.12, in its own virtualenv).

Skipped, with the reason, on machines without Python 3.12; a failure to install or run acados
where Python 3.12 exists is an error.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from humanmpc.codegen.ocp import DIST_EPS, OcpModel, smooth_distance
from humanmpc.codegen.spec import resolve_spec
from humanmpc.compare.peers.acados_client import PEER_SCRIPT, AcadosRun, ensure_acados_venv, find_python312, run_acados
from humanmpc.compare.replay import Replay, synthetic_replay

from .conftest import REPO_ROOT

VENV = REPO_ROOT / ".venv-acados"


@pytest.fixture(scope="module")
def acados_python() -> Path:
    if find_python312() is None:
        pytest.skip("acados needs Python 3.12 (PyPI's comma-deps-acados is built for it): none found here "
                    "(install python3.12 or pyenv 3.12.x, or set HUMANMPC_PYTHON312)")
    return ensure_acados_venv(VENV, log=lambda _m: None)


def test_peer_model_matches_codegen_ocp(acados_python: Path, tmp_path: Path) -> None:
    """The peer's potential, distance and ERK4 step (acados' own integrator) equal codegen/ocp.py's."""
    out = tmp_path / "selfcheck.npz"
    proc = subprocess.run([str(acados_python), str(PEER_SCRIPT), "--selfcheck", str(out), "--dist-eps",
                           repr(DIST_EPS)], capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    model = OcpModel(resolve_spec({}))
    with np.load(out) as r:
        ours = np.array([float(model.potential(d, 2.0, 1.0, 5.0)[0]) for d in r["d"]])
        np.testing.assert_allclose(r["f"], ours, rtol=1e-14, atol=1e-15)
        assert float(r["dist"]) == pytest.approx(float(smooth_distance(np.array([0.3, -0.2]), np.array([1.0, 0.5]))),
                                                 rel=1e-15)
        x_next = np.array(model["dynamics"].function(r["x"], r["u"])[0]).ravel()
        np.testing.assert_allclose(r["x_next"], x_next, rtol=1e-12, atol=1e-14)


@pytest.fixture(scope="module")
def runs(acados_python: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Replay, dict[str, AcadosRun]]:
    spec = resolve_spec({"humans": {"max": 5}})
    replay = synthetic_replay(spec, 5, 12, seed=2)
    build = tmp_path_factory.mktemp("acados")
    return replay, {m: run_acados(replay, m, build, python=acados_python) for m in ("default", "fastest")}


def test_both_settings_run_every_step(runs: tuple[Replay, dict[str, AcadosRun]]) -> None:
    replay, by_mode = runs
    T = replay.steps
    for mode, r in by_mode.items():
        assert r.status.shape == (T,) and r.x.shape == (T, 51, 4) and r.u.shape == (T, 50, 2)
        assert np.all(r.time_tot_ms > 0) and np.all(r.wall_ms > 0)
        assert np.all(r.qp_iterations >= 1)
        assert set(np.unique(r.status)) <= {0, 1, 2, 3, 4}, f"{mode}: unexpected acados status"
        ok = r.status == 0
        assert ok.sum() >= T // 2, f"{mode}: only {ok.sum()} of {T} steps succeeded"
        np.testing.assert_allclose(r.x[ok, 0], replay.x0[ok], atol=1e-9)
        assert np.all(np.abs(r.u[ok, :, 0]) <= 1.0 + 1e-6) and np.all(np.abs(r.u[ok, :, 1]) <= 1.5 + 1e-6)
        assert r.info["levenberg_marquardt"] == pytest.approx(1e-6)
    fastest = by_mode["fastest"]
    assert fastest.info["hpipm_mode"] == "SPEED_ABS" and fastest.info["qp_solver_cond_N"] == 5
    assert np.all(fastest.qp_iterations <= fastest.info["qp_solver_iter_max"])
    assert by_mode["default"].info["hpipm_mode"] == "BALANCE"


def test_peer_refuses_a_file_that_is_not_a_replay(acados_python: Path, tmp_path: Path) -> None:
    np.savez(tmp_path / "x.npz", meta=np.array('{"format": "other"}'))
    proc = subprocess.run([str(acados_python), str(PEER_SCRIPT), str(tmp_path / "x.npz"), str(tmp_path / "o.npz"),
                           "--build", str(tmp_path / "b")], capture_output=True, text=True, check=False)
    assert proc.returncode != 0 and "is not a humanmpc replay" in proc.stderr
