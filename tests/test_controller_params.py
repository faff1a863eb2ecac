"""The controller's own parameters apart from the solver's: <name>_controller_params beside <name>_params,
each set through its accessor (<name>_controller_own_params, <name>_controller_solver_params), both
checked with every controller step, and the solver's left as the caller set them between steps."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

import humanmpc
from humanmpc.codegen.params import CONTROLLER_PARAMS, SOLVER_PARAMS
from humanmpc.controller import Controller
from humanmpc.status import StopReason


def struct_fields(header: str, struct: str) -> list[str]:
    """The field names of ``typedef struct <struct> { ... } <struct>;`` in a generated header."""
    m = re.search(rf"typedef struct {struct} \{{(.*?)\}} {struct};", header, re.S)
    assert m is not None, f"no struct {struct} in the header"
    return re.findall(r"^\s+(?:int|\w+_real) (\w+)(?:\[\d+\])?;", m.group(1), re.M)


@pytest.fixture()
def ctl(paper_dir: Path) -> Controller:
    return humanmpc.load(paper_dir).controller()


def accessor(ctl: Controller, which: str) -> Any:
    """<name>_controller_<which>(&ctl): the C struct a C caller writes (own_params, solver_params)."""
    return getattr(ctl._lib, f"{ctl.name}_controller_{which}")(ctl._ctl)


def test_a_controller_parameter_is_a_field_of_the_controller_params_not_of_the_solvers(paper_dir: Path) -> None:
    name = humanmpc.load(paper_dir).name
    header = (paper_dir / f"{name}.h").read_text()
    solver_fields = struct_fields(header, f"{name}_params")
    controller_fields = struct_fields(header, f"{name}_controller_params")
    assert solver_fields == [p.name for p in SOLVER_PARAMS]
    assert controller_fields == [p.name for p in CONTROLLER_PARAMS]
    for key in ("v_ref", "goal_tolerance", "speed_limit", "progress", "stall_time"):
        assert key in controller_fields and key not in solver_fields


def test_the_solver_refuses_a_controller_parameter_naming_where_it_belongs(paper: humanmpc.Solver) -> None:
    assert "goal_tolerance" not in paper.params
    with pytest.raises(KeyError, match="a parameter of the controller"):
        paper.set_params(goal_tolerance=0.6)


def test_goal_tolerance_set_through_the_own_params_accessor_decides_when_the_goal_is_reached(
        ctl: Controller) -> None:
    """The robot at rest 0.5 m from its goal: not reached with the spec's 0.3 m; reached once a C caller
    sets 0.6 m through <name>_controller_own_params; Python reads the same struct."""
    assert ctl.step(0.0, pose=(0, 0, 0), v=0.0, goal=(0.5, 0.0, 0.0)).outcome_name == "following"
    ctl.reset()
    accessor(ctl, "own_params").goal_tolerance = 0.6
    assert ctl.params["goal_tolerance"] == 0.6
    r = ctl.step(0.0, pose=(0, 0, 0), v=0.0, goal=(0.5, 0.0, 0.0))
    assert r.goal_reached and r.outcome_name == "goal_reached"


def test_a_broken_controller_parameter_written_behind_pythons_back_is_a_protective_stop(ctl: Controller) -> None:
    """The controller applies its own parameters' rules with every step, as the monitor applies the
    solver's: a C caller writing goal_tolerance = -1 gets a stop with reason invalid_params."""
    accessor(ctl, "own_params").goal_tolerance = -1.0
    r = ctl.step(0.0, pose=(0, 0, 0), v=0.5, goal=(5.0, 0.0, 0.0))
    assert r.stop and r.stop_reason == StopReason.INVALID_PARAMS and r.u[0] < 0.0
    accessor(ctl, "own_params").goal_tolerance = 0.3
    assert not ctl.step(0.1, pose=(0, 0, 0), v=0.5, goal=(5.0, 0.0, 0.0)).stop
    accessor(ctl, "solver_params").d_h = 150.0   # the solver's, beyond its rule
    r = ctl.step(0.2, pose=(0, 0, 0), v=0.5, goal=(5.0, 0.0, 0.0))
    assert r.stop and r.stop_reason == StopReason.INVALID_PARAMS


def test_a_step_leaves_the_callers_solver_parameters_as_they_were(default_dir: Path) -> None:
    """Within a period the controller writes the speed cap, the progress weights and the potential's end
    into its solver's parameters; after it, they are the caller's again (nothing else is copied)."""
    ctl = humanmpc.load(default_dir).controller()
    ctl.set_params(speed_limit=0.5, w_goal=(1.0, 2.0, 0.0, 3.0), collision_horizon=2.5)
    before = ctl.params
    r = ctl.step(0.0, pose=(0, 0, 0), v=0.5, goal=(1.5, 0.0, 0.0), people=[[3.0, 0.5, 0.0, 0.0]])
    assert not r.stop
    assert ctl.params == before
    assert tuple(accessor(ctl, "solver_params").w_goal) == (1.0, 2.0, 0.0, 3.0)
