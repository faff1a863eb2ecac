"""acados, the peer of the comparison: SQP-RTI with HPIPM from PyPI's prebuilt wheel, in a Python 3.12
virtualenv of its own (acados ships a casadi that must not meet ours); ``acados_peer.py`` runs there on a
replay and writes its results, which ``run_acados`` reads back."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...codegen.ocp import DIST_EPS
from ..replay import Replay

FloatArray = NDArray[np.float64]
Log = Callable[[str], None]

ACADOS_PACKAGE = "comma-deps-acados==0.2.2.post104"
ACADOS_PYTHON = "3.12"
PEER_SCRIPT = Path(__file__).resolve().parent / "acados_peer.py"
DEFAULT_ACADOS_VENV = Path(".venv-acados")
FASTEST = {"cond_N": 5, "qp_iter_max": 50}

class AcadosUnavailableError(RuntimeError):
    """acados cannot run here (no Python 3.12, or its wheel cannot be installed); the message says why."""


def progress(log: Log | None) -> Log:
    return log or (lambda msg: print(msg, file=sys.stderr))


# ----------------------------------------------------------------------------------------------
# The acados virtualenv (Python 3.12, separate from the project's .venv)
# ----------------------------------------------------------------------------------------------


def find_python312() -> Path | None:
    """A Python 3.12 interpreter: $HUMANMPC_PYTHON312, python3.12 on PATH, or a pyenv 3.12.x."""
    candidates: list[Path] = []
    env = os.environ.get("HUMANMPC_PYTHON312")
    if env:
        candidates.append(Path(env))
    which = shutil.which("python3.12")
    if which:
        candidates.append(Path(which))
    pyenv_root = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv"))
    candidates += sorted((pyenv_root / "versions").glob("3.12*/bin/python3.12"), reverse=True)
    for c in candidates:
        if not c.is_file():
            continue
        try:
            out = subprocess.run([str(c), "-c", "import sys, venv; print('%d.%d' % sys.version_info[:2])"],
                                 capture_output=True, text=True, timeout=30, check=False)
        except (OSError, subprocess.TimeoutExpired):
            continue
        if out.returncode == 0 and out.stdout.strip() == ACADOS_PYTHON:
            return c
    return None


def _venv_python(venv_dir: Path) -> Path:
    return venv_dir / "bin" / "python"


def _acados_installed(python: Path) -> bool:
    probe = "import importlib.util as u, sys; sys.exit(0 if u.find_spec('acados') and u.find_spec('casadi') else 1)"
    try:
        return subprocess.run([str(python), "-c", probe], capture_output=True, timeout=60, check=False).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def ensure_acados_venv(venv_dir: str | Path = DEFAULT_ACADOS_VENV, *, log: Log | None = None) -> Path:
    """The interpreter of a Python 3.12 virtualenv holding PyPI's prebuilt acados (created when missing).

    The virtualenv is separate from the project's: acados ships a casadi of its own (3.6.7)
    that must not meet the project's. Raises AcadosUnavailableError with the reason when Python
    3.12 is missing or the wheel cannot be installed.
    """
    say = progress(log)
    d = Path(venv_dir).resolve()
    python = _venv_python(d)
    if python.is_file() and _acados_installed(python):
        return python
    base = find_python312()
    if base is None:
        raise AcadosUnavailableError(
            "acados needs Python 3.12 (PyPI's comma-deps-acados is built for it) and none was found: "
            "install python3.12 (or pyenv 3.12.x) or point HUMANMPC_PYTHON312 at one"
        )
    if not python.is_file():
        say(f"[compare] creating {d} with {base}")
        proc = subprocess.run([str(base), "-m", "venv", str(d)], capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise AcadosUnavailableError(f"could not create the acados virtualenv {d}: {proc.stderr.strip()[-500:]}")
    say(f"[compare] installing {ACADOS_PACKAGE} into {d}")
    proc = subprocess.run([str(python), "-m", "pip", "install", "-q", ACADOS_PACKAGE], capture_output=True, text=True,
                          check=False)
    if proc.returncode != 0 or not _acados_installed(python):
        raise AcadosUnavailableError(f"could not install {ACADOS_PACKAGE} into {d}: "
                                     f"{(proc.stderr or proc.stdout).strip()[-800:]}")
    return python


def acados_unavailable_reason(venv_dir: str | Path = DEFAULT_ACADOS_VENV) -> str | None:
    """None when the acados peer can run (installing it if needed), else the reason (for skips)."""
    try:
        ensure_acados_venv(venv_dir, log=lambda _m: None)
    except AcadosUnavailableError as err:
        return str(err)
    return None


@dataclass
class AcadosRun:
    """acados' results on every step of a replay."""

    mode: str
    status: NDArray[np.int64]  # (T,) acados' status: 0 success, 3 minimum step, 4 QP failure, ...
    qp_iterations: NDArray[np.int64]
    time_tot_ms: FloatArray  # acados' own timer
    wall_ms: FloatArray  # wall time of solve() from Python (ctypes)
    x: FloatArray
    u: FloatArray
    info: dict[str, Any]

    @property
    def failures(self) -> int:
        return int(np.count_nonzero(self.status != 0))


def run_acados(replay: Replay, mode: str, build_dir: str | Path, *, python: Path | None = None,
               venv_dir: str | Path = DEFAULT_ACADOS_VENV, regularization: float | None = None,
               cond_n: int = FASTEST["cond_N"], qp_iter_max: int = FASTEST["qp_iter_max"],
               timeout_s: float = 3600.0, log: Log | None = None) -> AcadosRun:
    """Run the acados peer (``acados_peer.py``) on a replay, in ``mode`` default or fastest."""
    py = python or ensure_acados_venv(venv_dir, log=log)
    build = Path(build_dir).resolve()
    build.mkdir(parents=True, exist_ok=True)
    reg = replay.resolved_spec().solver.regularization if regularization is None else regularization
    with tempfile.TemporaryDirectory(prefix="hm_acados_") as tmp:
        rp, out = Path(tmp) / "replay.npz", Path(tmp) / "results.npz"
        replay.save(rp)
        cmd = [str(py), str(PEER_SCRIPT), str(rp), str(out), "--build", str(build), "--mode", mode,
               "--dist-eps", repr(DIST_EPS), "--cond-N", str(cond_n), "--qp-iter-max", str(qp_iter_max),
               "--regularization", repr(float(reg))]
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s, check=False, env=env)
        if proc.returncode != 0 or not out.is_file():
            raise RuntimeError(f"the acados peer failed (exit {proc.returncode}):\n"
                               f"{(proc.stderr + proc.stdout).strip()[-3000:]}")
        with np.load(out, allow_pickle=False) as r:
            return AcadosRun(mode=mode, status=r["status"].astype(np.int64),
                             qp_iterations=r["qp_iter"].astype(np.int64), time_tot_ms=r["time_tot_ms"].copy(),
                             wall_ms=r["wall_ms"].copy(), x=r["x"].copy(), u=r["u"].copy(),
                             info=json.loads(str(r["info"])))
