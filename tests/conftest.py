"""Shared fixtures: generated and built solvers, reused across the session (generation + build take seconds)."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.codegen.build import build
from humanmpc.codegen.generate import generate
from humanmpc.codegen.spec import Spec, resolve_spec
from humanmpc.planners.interface import Observation, PlanResult
from humanmpc.sim.recorded import PEDESTRIANS_ENV, pedestrian_data_dir


def _have_pedestrian_data() -> bool:
    try:
        pedestrian_data_dir()
    except FileNotFoundError:
        return False
    return True


# The recorded scenes (the files in ../shared/data/pedestrians, as CI has them): tests that replay them
# are skipped, with the variable to set, where the checkout has no such sibling folder.
HAVE_DATA = _have_pedestrian_data()
needs_data = pytest.mark.skipif(not HAVE_DATA, reason=f"no pedestrian data (set {PEDESTRIANS_ENV})")

QUIET: Callable[[str], None] = lambda _msg: None  # noqa: E731
REPO_ROOT = Path(__file__).resolve().parent.parent


def make_solver(root: Path, data: dict | None = None, *, built: bool = True) -> Path:
    """Generate (and build) the solver of a spec given as a plain mapping into root/<name>."""
    spec = resolve_spec(data or {})
    out = generate(spec, root / spec.name, force=True, log=QUIET)
    if built:
        build(out, log=QUIET)
    return out


@pytest.fixture(scope="session")
def paper_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The paper's configuration (``preset: paper``: its weights, Gauss-Newton, no controller extras),
    generated and built: the solver tests' reference configuration."""
    return make_solver(tmp_path_factory.mktemp("paper"), {"preset": "paper"})


@pytest.fixture(scope="session")
def default_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The built-in default spec (the values that won the evaluation), generated and built."""
    return make_solver(tmp_path_factory.mktemp("default"))


@pytest.fixture(scope="session")
def paper(paper_dir: Path) -> humanmpc.Solver:
    return humanmpc.load(paper_dir)


@pytest.fixture(scope="session")
def default_spec() -> Spec:
    return Spec()


def require_tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        pytest.fail(f"{name} is not installed: `make test` installs it (see APT_PACKAGES in the Makefile)")
    return path


class Recorder:
    """A planner that drives straight at 0.5 m/s and keeps what it was shown."""

    name = "recorder"

    def __init__(self) -> None:
        self.seen: list[Observation] = []

    def reset(self) -> None:
        self.seen.clear()

    def plan(self, obs: Observation) -> PlanResult:
        self.seen.append(obs)
        return PlanResult(u=np.array([(0.5 - obs.x[3]) / obs.dt, 0.0]))
