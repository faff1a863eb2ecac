"""One source per contract: the runtime parameters' table and the status table, seen the same way from
the spec, the generated C and Python."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import humanmpc
from humanmpc.codegen.params import CONTROLLER_PARAMS, PARAMS, SOLVER_PARAMS, Param
from humanmpc.codegen.resources import runtime_dir
from humanmpc.codegen.spec import SpecError, resolve_spec
from humanmpc.codegen.status import StatusTableError, parse_tables, status_tables
from humanmpc.status import QpStatus, Status, StopReason


def out_of_range(p: Param) -> Any:
    """A value that breaks the row's rule (and only that row's)."""
    if p.kind == "flag":
        return 2
    if p.kind == "integer":
        assert p.valid is not None
        return int(p.valid.hi) + 1
    if p.kind == "interval":
        assert p.lower is not None
        return [p.lower.hi + 1.0, p.lower.hi + 2.0]  # a lower bound above its limit
    assert p.valid is not None
    bad = p.valid.hi * 10.0
    return [bad] * p.size if p.kind == "vector" else bad


def spec_data(p: Param, value: Any) -> dict[str, Any]:
    section, key = p.key.split(".")
    return {section: {key: value}}


def c_struct(solver: humanmpc.Solver, p: Param) -> str:
    """The C params struct whose field p is: the solver's, or the controller's own."""
    return f"{solver.name}_controller_params" if p.controller else f"{solver.name}_params"


def c_index(p: Param) -> int:
    """What the struct's check returns when p alone breaks its rule: 1 + its index in its struct."""
    return (CONTROLLER_PARAMS if p.controller else SOLVER_PARAMS).index(p) + 1


def c_params(solver: humanmpc.Solver, p: Param | None = None) -> Any:
    """A fresh copy of the C params struct that holds p (default: the solver's), with the spec's values."""
    ffi, lib = solver._ffi, solver._lib
    struct = f"{solver.name}_params" if p is None else c_struct(solver, p)
    params = ffi.new(f"{struct} *")
    getattr(lib, f"{struct}_default")(params)
    return params


def face(solver: humanmpc.Solver, p: Param) -> Any:
    """What a Python caller sets p on: the solver, or a controller for the controller's own parameters."""
    return solver.controller() if p.controller else solver


@pytest.mark.parametrize("p", PARAMS, ids=[p.name for p in PARAMS])
def test_an_out_of_range_parameter_is_refused_with_the_same_rule_by_the_spec_c_and_python(
        paper: humanmpc.Solver, p: Param) -> None:
    bad = out_of_range(p)
    expected = f"{p.name} must be {p.rule}"
    # the spec
    with pytest.raises(SpecError) as spec_err:
        resolve_spec(spec_data(p, True if p.kind == "flag" and p.spec_choices else bad))
    if p.kind != "flag":  # a flag is true/false in YAML (or a named choice), 0/1 in C and Python
        assert p.rule in str(spec_err.value), str(spec_err.value)
    # the C API
    ffi, lib, struct = paper._ffi, paper._lib, c_struct(paper, p)
    params = c_params(paper, p)
    assert getattr(lib, f"{struct}_check")(params) == 0
    setattr(params, p.name, bad)
    which = getattr(lib, f"{struct}_check")(params)
    assert which == c_index(p)
    assert ffi.string(getattr(lib, f"{struct}_rule")(which)).decode() == expected
    # Python
    target = face(paper, p)
    before = target.params
    with pytest.raises(ValueError) as py_err:
        target.set_params(**{p.name: bad})
    assert expected in str(py_err.value)
    assert target.params == before


@pytest.mark.parametrize("p", [p for p in PARAMS if p.ctype == "real"], ids=lambda p: p.name)
def test_non_finite_parameters_are_refused_by_c_and_python(paper: humanmpc.Solver, p: Param) -> None:
    target = face(paper, p)
    for v in (math.nan, math.inf, -math.inf):
        params = c_params(paper, p)
        setattr(params, p.name, [v] * p.size if p.size > 1 else v)
        assert getattr(paper._lib, f"{c_struct(paper, p)}_check")(params) == c_index(p)
        with pytest.raises(ValueError, match=re.escape(p.rule)):
            target.set_params(**{p.name: [v] * p.size if p.size > 1 else v})


def test_python_refuses_strings_and_booleans_where_c_holds_numbers(paper: humanmpc.Solver) -> None:
    for key, value in (("q", "2.5"), ("q", True), ("qp_max_iter", 5.0), ("qp_max_iter", True), ("w_goal", "1234")):
        with pytest.raises(ValueError, match=r"wrong type|is not a list of 4 numbers"):
            paper.set_params(**{key: value})


def test_a_step_with_parameters_broken_behind_pythons_back_is_a_protective_stop(paper_dir: Path) -> None:
    """The C monitor applies the table's rules itself: a caller writing the struct directly (firmware, a
    robot node) gets a stop with reason invalid_params, not a step with the broken value."""
    solver = humanmpc.load(paper_dir)
    solver._params.d_h = 150.0  # finite, but beyond the table's 100 m
    r = solver.step([0, 0, 0, 0.5], [5, 0, 0, 0.8])
    assert r.stop and r.stop_reason == StopReason.INVALID_PARAMS
    solver._params.d_h = 0.5
    assert not solver.step([0, 0, 0, 0.5], [5, 0, 0, 0.8]).stop


def test_the_manifest_carries_the_parameter_table_with_the_specs_defaults(paper_dir: Path) -> None:
    import json

    manifest = json.loads((paper_dir / "manifest.json").read_text())
    rows = {r["name"]: r for r in manifest["params"]}
    assert list(rows) == [p.name for p in PARAMS]
    assert rows["q"]["default"] == 2.0 and rows["q"]["rule"] == "a number with 0 <= q <= 1e+06"
    assert rows["exact_hessian"]["default"] == 0 and rows["a_bounds"]["unit"] == "m/s^2"
    assert Param.from_manifest_row(rows["kappa"]).rule == next(p for p in PARAMS if p.name == "kappa").rule


def test_status_codes_agree_in_the_header_the_c_messages_and_the_python_enums(paper: humanmpc.Solver,
                                                                               paper_dir: Path) -> None:
    header = (paper_dir / f"{paper.name}.h").read_text()
    defined = {m.group(1): int(m.group(2))
               for m in re.finditer(rf"#define {paper.name.upper()}_([A-Z0-9_]+) (-?\d+)\b", header)}
    for enum, key, c_message in ((QpStatus, "qp_status", paper.qp_status_message), (Status, "status",
                                 paper.status_message), (StopReason, "stop_reason", paper.stop_reason_message)):
        rows = status_tables()[key]
        assert [(m.name.lower(), int(m)) for m in enum] == [(r.name, r.value) for r in rows]
        for r in rows:
            assert defined[r.id] == r.value
            assert c_message(r.value) == r.message == enum(r.value).message
    assert defined["STOP_REASON_COUNT"] == len(StopReason)
    assert humanmpc.StopReason.HUMAN_TOO_CLOSE == 6 and humanmpc.Status.SKIPPED == 3


def test_a_malformed_status_table_is_refused_with_the_line() -> None:
    text = (runtime_dir() / "hm_status.h").read_text()
    assert parse_tables(text) == status_tables()
    with pytest.raises(StatusTableError, match="repeats a value"):
        parse_tables(text.replace("X(STOP_UNSAFE_PLAN, 7,", "X(STOP_UNSAFE_PLAN, 6,"))
    with pytest.raises(StatusTableError, match="not a row"):
        parse_tables(text.replace('X(QP_TIMEOUT, 5, timeout, "', 'X(QP_TIMEOUT, 5, timeout, \''))


def test_step_results_name_their_codes_from_the_table(paper: humanmpc.Solver) -> None:
    r = paper.step([0, 0, 0, 0.5], [5, 0, 0, 0.8], [[0.2, 0.0]], np.tile([[0.2, 0.0]], (paper.dims.N + 1, 1, 1)))
    assert r.stop and r.reason == "human_too_close" and r.status_name == "skipped"
    paper.reset()


@pytest.mark.parametrize("a_min", [0.0, -1e-300, -0.05, -0.0999])
def test_a_lower_acceleration_bound_that_cannot_brake_is_refused_by_the_spec_c_and_python(
        paper: humanmpc.Solver, a_min: float) -> None:
    """Issue 22, item 1: a protective stop must brake by a meaningful margin (a_min <= -0.1 m/s^2); with
    a_min = 0 or -1e-300 a stop commanded a = 0 and the robot drove on with a person 0.3 m ahead."""
    p = next(p for p in PARAMS if p.name == "a_bounds")
    assert "-100 <= lower <= -0.1" in p.rule
    with pytest.raises(SpecError, match=re.escape(p.rule)):
        resolve_spec({"bounds": {"a": [a_min, 1.0]}})
    params = c_params(paper)
    params.a_bounds = [a_min, 1.0]
    assert getattr(paper._lib, f"{paper.name}_params_check")(params) == c_index(p)
    with pytest.raises(ValueError, match=re.escape(p.rule)):
        paper.set_params(a_bounds=[a_min, 1.0])


def test_the_weakest_allowed_braking_brakes_a_protective_stop(paper_dir: Path) -> None:
    """a_min = -0.1 is accepted everywhere, and a stop for a person 0.3 m ahead then decelerates by it."""
    assert resolve_spec({"bounds": {"a": [-0.1, 1.0]}}).bounds.a == (-0.1, 1.0)
    solver = humanmpc.load(paper_dir)
    solver.set_params(a_bounds=[-0.1, 1.0])
    n = solver.dims.N
    r = solver.step([0, 0, 0, 1.0], [5, 0, 0, 0.8], [[0.3, 0.0]], np.tile([[0.3, 0.0]], (n + 1, 1, 1)))
    assert r.stop and r.reason == "human_too_close"
    assert r.u0[0] == -0.1 and r.command[0] == pytest.approx(1.0 - 0.1 * 0.1) and r.command[1] == 0.0
