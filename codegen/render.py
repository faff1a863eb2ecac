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
from .resources import TEMPLATES_DIR
from .spec import IDENT_RE, Spec

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
    "ocp_nlp_lin.c",
    "ocp_nlp_screen.c",
    "ocp_nlp_step.c",
    "ocp_nlp_out.c",
    "ocp_nlp_rti.c",
    "ocp_nlp_sqp.c",
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
    if not IDENT_RE.match(name):
        raise ValueError(f"{name!r} is not a C identifier")
    return name


@dataclass(frozen=True)
class RuntimeParam:
    """A field of <name>_params: set at run time, defaulting to the spec's value."""

    c_name: str
    doc: str
    default: tuple[str, ...] | str  # C literals
    size: int


def runtime_params(spec: Spec) -> list[RuntimeParam]:
    def vec(c_name: str, doc: str, values: tuple[float, ...]) -> RuntimeParam:
        return RuntimeParam(c_name, doc, tuple(c_float(v) for v in values), len(values))

    def one(c_name: str, doc: str, value: float) -> RuntimeParam:
        return RuntimeParam(c_name, doc, c_float(value), 1)

    w, cc, ob, b, s = spec.weights, spec.collision_cost, spec.obstacle, spec.bounds, spec.solver
    return [
        vec("w_goal", "stage weights on x - g", w.goal),
        vec("w_goal_terminal", "terminal weights on x_N - g", w.goal_terminal),
        vec("w_control", "stage weights on u", w.control),
        one("q", "collision potential height", cc.q),
        one("d_th", "collision potential threshold distance [m]", cc.d_th),
        one("kappa", "collision potential steepness [1/m]", cc.kappa),
        one("d_h", "hard distance to humans' current positions [m]", spec.humans.d_h),
        one("human_slack_l1", "exact-penalty weight on the human rows", spec.humans.slack_l1),
        one("human_slack_l2", "L2 penalty on the human-row slack", spec.humans.slack_l2),
        one("d_s", "soft distance to the closest obstacle [m]", ob.d_s),
        one("slack_l1", "L1 penalty on the obstacle slack", ob.slack_l1),
        one("slack_l2", "L2 penalty on the obstacle slack", ob.slack_l2),
        vec("v_bounds", "[min, max] forward speed [m/s]", b.v),
        vec("a_bounds", "[min, max] acceleration [m/s^2]", b.a),
        vec("omega_bounds", "[min, max] turn rate [rad/s]", b.omega),
        one("regularization", "Levenberg-Marquardt term on the QP Hessian", s.regularization),
        one("qp_tol", "QP convergence tolerance", s.qp_tol),
        one("deadline_ms", "time allowed for one solver step [ms]", spec.monitor.deadline_ms),
    ]


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
        "NH_ALLOC": max(1, int(spec.humans.max)),  # C has no zero-length arrays
        "runtime_sources": RUNTIME_SOURCES,
        "dt": c_float(spec.dt),
        "params": runtime_params(spec),
        "qp_max_iter": int(spec.solver.qp_max_iter),
        "line_search": 1 if spec.solver.line_search else 0,
        "row_screening": 1 if spec.solver.row_screening else 0,
        "exact_hessian": 1 if spec.solver.hessian == "exact" else 0,
        "functions": [_function_context(name, ef) for ef in functions],
    }


def make_environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(TEMPLATES_DIR)),
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
