"""Jinja2 rendering of the per-solver glue: strict about undefined names, no autoescaping (C)."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

import casadi as ca
import jinja2

from . import __version__
from .casadi_emit import EmittedFunction
from .ocp import NU, NX
from .params import CONTROLLER_PARAMS, SOLVER_PARAMS, Param, Range, spec_params
from .resources import templates_dir
from .spec import IDENT_RE, Spec
from .status import status_tables

# What a number may look like once printed into C source: a decimal floating literal.
_C_FLOAT = re.compile(r"^-?[0-9]+(\.[0-9]*)?(e[-+]?[0-9]+)?$")

# Runtime files compiled into the solver's translation unit, in dependency order.
RUNTIME_SOURCES = (
    "ocp_qp.c",
    "ocp_qp_res.c",
    "ocp_qp_kkt.c",
    "ocp_qp_hsde_kkt.c",
    "ocp_qp_hsde_setup.c",
    "ocp_qp_hsde_res.c",
    "ocp_qp_hsde.c",
    "ocp_qp_ipm_setup.c",
    "ocp_qp_ipm_lanes.c",
    "ocp_qp_ipm_pass_a.c",
    "ocp_qp_ipm_measures.c",
    "ocp_qp_ipm_pred_corr.c",
    "ocp_qp_ipm_sol.c",
    "ocp_qp_ipm_cert.c",
    "ocp_qp_ipm_polish.c",
    "ocp_qp_ipm_warm.c",
    "ocp_qp_ipm.c",
    "ocp_nlp_common.c",
    "monitor.c",
    "ocp_nlp_cost.c",
    "ocp_nlp_lin.c",
    "ocp_nlp_screen.c",
    "ocp_nlp_step.c",
    "ocp_nlp_out.c",
    "ocp_nlp_rti.c",
    "ocp_nlp_sqp.c",
    "ocp_nlp_iterate.c",
    "controller_common.c",
    "controller_path.c",
    "controller_people.c",
    "controller_tracks.c",
    "controller_safety.c",
    "controller_objective.c",
    "controller_candidates.c",
    "controller_recovery.c",
    "controller_goal_checker.c",
    "controller_progress_checker.c",
    "controller.c",
)

# Template -> file name in the generated folder ({name} is the spec's name).
TEMPLATES = {
    "solver.h.j2": "{name}.h",
    "solver.c.j2": "{name}.c",
    "cffi_cdef.h.j2": "{name}_cffi.h",
    "Makefile.j2": "Makefile",
    "CMakeLists.txt.j2": "CMakeLists.txt",
    "solver.hpp.j2": "{name}.hpp",
}


def c_float(x: float) -> str:
    """A finite float as a C floating literal that reads back to the same double."""
    if not math.isfinite(x):
        raise ValueError(f"{x!r} cannot be written into C source: not finite")
    text = repr(float(x))
    if not _C_FLOAT.match(text):
        raise ValueError(f"{x!r} printed as {text!r}, which is not a C floating literal")
    return text


def c_identifier(name: str) -> str:
    if not IDENT_RE.fullmatch(name):
        raise ValueError(f"{name!r} is not a C identifier")
    return name


@dataclass(frozen=True)
class RuntimeParam:
    """A field of <name>_params or <name>_controller_params as the templates print it: from its row of the
    parameter table."""

    c_name: str
    ctype: str                      # "real" or "int"
    doc: str
    default: tuple[str, ...] | str  # C literals
    size: int
    checks: tuple[str, ...]         # C expressions over p, all true when the rule holds (NaN fails them)
    rule: str                       # the rule in words, a C string literal's contents


def _range_test(x: str, r: Range, real: str | None) -> str:
    """C for r holding x: reals as literals of the solver's real type, integers (real None) as ints."""
    def lit(v: float) -> str:
        return str(int(v)) if real is None else f"({real}){c_float(v)}"

    return f"{lit(r.lo)} {'<' if r.lo_open else '<='} {x} && {x} {'<' if r.hi_open else '<='} {lit(r.hi)}"


def _check_exprs(p: Param, real: str) -> tuple[str, ...]:
    f = f"p->{c_identifier(p.name)}"
    if p.kind == "flag":
        return (f"{f} == 0 || {f} == 1",)
    if p.kind == "integer":
        assert p.valid is not None
        return (_range_test(f, p.valid, None),)
    if p.kind == "interval":
        assert p.lower is not None and p.upper is not None
        return (_range_test(f + "[0]", p.lower, real), _range_test(f + "[1]", p.upper, real), f"{f}[0] < {f}[1]")
    assert p.valid is not None
    entries = [f"{f}[{i}]" for i in range(p.size)] if p.size > 1 else [f]
    return tuple(_range_test(e, p.valid, real) for e in entries)


def _c_string(text: str) -> str:
    if not re.fullmatch(r"[ -~]*", text) or '"' in text or "\\" in text or "*/" in text:
        raise ValueError(f"{text!r} cannot be printed into a C string literal")
    return text


def runtime_params(spec: Spec, real: str, rows: tuple[Param, ...]) -> list[RuntimeParam]:
    """The rows (of one params struct) with the spec's values as defaults."""
    values = spec_params(spec)
    out = []
    for p in rows:
        v = values[p.name]
        if p.ctype == "int":
            default: tuple[str, ...] | str = str(int(v))
        elif p.size > 1:
            default = tuple(c_float(x) for x in v)
        else:
            default = c_float(v)
        out.append(RuntimeParam(c_identifier(p.name), p.ctype, _c_string(p.described), default, p.size,
                                _check_exprs(p, real), _c_string(f"{p.name} must be {p.rule}")))
    return out


def _function_context(prefix: str, ef: EmittedFunction) -> dict[str, Any]:
    mf = ef.model
    return {
        "name": c_identifier(mf.name),
        "doc": mf.doc.replace("*/", "* /"),
        "casadi_name": c_identifier(ef.casadi_name),
        "inputs": [{"name": c_identifier(p.name), "size": p.size, "rows": p.rows, "cols": p.cols} for p in mf.inputs],
        "outputs": [{"name": c_identifier(p.name), "size": p.size, "rows": p.rows, "cols": p.cols}
                    for p in mf.outputs],
        "sz_arg": ef.sz_arg,
        "sz_res": ef.sz_res,
        "sz_iw": ef.sz_iw,
        "sz_w": ef.sz_w,
    }


def template_context(spec: Spec, functions: list[EmittedFunction], real: str) -> dict[str, Any]:
    name = c_identifier(spec.name)
    return {
        "name": name,
        "NAME": name.upper(),
        "version": __version__,
        "casadi_version": ca.CasadiMeta.version(),
        "spec_hash": spec.digest(),
        "real": {"double": "double", "float": "float"}[real],
        "nx": NX,
        "nu": NU,
        "N": int(spec.horizon.N),
        "NH": int(spec.humans.max),
        "NG": int(spec.n_rows),
        "QP_ROWS": int(spec.qp_row_capacity),
        "NH_ALLOC": max(1, int(spec.humans.max)),  # C has no zero-length arrays
        "NT": int(spec.controller.max_tracks),
        "MAX_PATH_POINTS": int(spec.controller.max_path_points),
        "NK": int(spec.controller.max_obstacle_points),
        "NC": int(spec.controller.candidates),
        "runtime_sources": RUNTIME_SOURCES,
        "dt": c_float(spec.dt),
        "statuses": status_tables(),
        "params": runtime_params(spec, {"double": "double", "float": "float"}[real], SOLVER_PARAMS),
        "controller_params": runtime_params(spec, {"double": "double", "float": "float"}[real], CONTROLLER_PARAMS),
        "functions": [_function_context(name, ef) for ef in functions],
    }


def make_environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(templates_dir())),
        undefined=jinja2.StrictUndefined,
        autoescape=False,  # C source, not HTML
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
    )


def render_all(context: dict[str, Any]) -> dict[str, str]:
    """File name -> rendered text, for every template."""
    env = make_environment()
    return {
        out.format(name=context["name"]): env.get_template(tpl).render(**context) for tpl, out in TEMPLATES.items()
    }
