"""Every name a generated package derives from its spec's name, and the rule that keeps two packages apart.

A package named ``n`` writes files, defines external symbols, types and macros, and CMake and catkin
targets, each ``n`` followed by a suffix of ``suffixes()`` (macros upper-cased: the table is compared in
lower case). Two packages ``a`` and ``b`` (``b`` the longer) clash exactly when ``a + s == b + t`` for
two suffixes s, t: then ``b == a + w`` and ``s == w + t``. So a name is refused when it ends in such a
``w`` (``lk_model``: ``lk`` + ``_model_dynamics`` == ``lk_model`` + ``_dynamics``), and any two names
that pass have disjoint file names, symbols, macros and targets. Names are lower case, so no two differ
only in case (one file on a case-insensitive file system, the same upper-case macros).

The table: what the templates print after the name (scanned, so a new function joins by itself), the
runtime's HM_NS types, the status constants, CasADi's names, and the lists below (files the generator
names itself, targets). tests/test_names.py checks that the table covers everything a generated
package defines (its files, ``nm``'s external symbols, the identifiers its headers declare, its CMake
and ROS targets) and proves the rule over the table.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache

from .resources import runtime_files, templates_dir
from .status import status_tables

# The model functions CasADi generates as <name>_model_<function> (codegen/ocp.py), and what CasADi's
# code generator appends to each (its external functions and its size macros).
MODEL_FUNCTIONS = ("dynamics", "dynamics_hessian", "cost_stage", "cost_terminal", "cost_collision",
                   "cost_collision_gn", "distance_constraint")
CASADI_FUNCTION_SUFFIXES = ("", "_checkout", "_decref", "_default_in", "_incref", "_n_in", "_n_out", "_name_in",
                            "_name_out", "_release", "_sparsity_in", "_sparsity_out", "_work", "_work_bytes",
                            "_sz_arg", "_sz_iw", "_sz_res", "_sz_w")

# What the templates and the generator define, after the name.
_FILES = (".h", ".c", ".hpp", "_cffi.h", "_model.c", "_model.h", ".a", ".so", ".so.record.json", ".launch",
          ".yaml", "_ros", "_ros_src", "_node.cpp")
_TARGETS = ("", "_shared", "_solver", "_node", "_ros")  # C++ namespace, CMake and catkin targets
_API = (
    "_dims", "_spec_hash", "_struct_sizes", "_solver", "_solver_create", "_solver_feedback", "_solver_init",
    "_solver_memory", "_solver_memsize", "_solver_params", "_solver_prepare", "_solver_reset",
    "_solver_set_clock", "_solver_solve", "_solver_step", "_controller", "_controller_create",
    "_controller_init", "_controller_input", "_controller_memsize", "_controller_output", "_controller_params",
    "_controller_params_check", "_controller_params_default", "_controller_params_rule", "_controller_own_params",
    "_controller_solver_params",
    "_controller_reset", "_controller_set_clock", "_controller_step", "_controller_struct_sizes", "_params",
    "_params_check", "_params_default", "_params_rule", "_input", "_output", "_real", "_clock_fn",
    "_status_message", "_qp_status_message", "_stop_reason_message", "_outcome_message",
    "_casadi_casadi_int_size", "_casadi_casadi_real_size", "_casadi_casadi_version", "_model",
    *(f"_{f}" for f in MODEL_FUNCTIONS),
)
_MACROS = (
    "_", "_h", "_hpp", "_model_h", "_dt", "_generator_version", "_spec_hash", "_n", "_ng", "_nh", "_nu", "_nx",
    "_qp_rows", "_max_obstacle_points", "_max_path_points", "_max_tracks", "_outcome_", "_stop_",
    "_stop_reason_count", "_status_", "_qp_", "_casadi_",
)


@cache
def runtime_type_suffixes() -> tuple[str, ...]:
    """The runtime's types, which <name>.h declares as <name>_<type> (HM_NS(type) in c_runtime/)."""
    found = set()
    for src in runtime_files():
        if src.suffix in (".h", ".c"):
            found.update(re.findall(r"\bHM_NS\((\w+)\)", src.read_text()))
    found.discard("x")  # the macro's own parameter
    return tuple(sorted(f"_{t.lower()}" for t in found))


# A name the templates print after the solver's name (or the ROS package's, <name>_ros): {{ name }}_step ...
_TEMPLATE_NAME = re.compile(r"\{\{\s*(name|NAME|package)\s*\}\}([A-Za-z0-9_.]*)")


@cache
def template_suffixes() -> tuple[str, ...]:
    """Every suffix the templates print literally after the name: a function, type, macro or file added
    to a template joins the table by itself."""
    found = set()
    for path in templates_dir().rglob("*.j2"):
        for kind, tail in _TEMPLATE_NAME.findall(path.read_text()):
            tail = tail.rstrip(".")  # the end of a sentence in a comment
            found.add(("_ros" if kind == "package" else "") + tail.lower())
    return tuple(sorted(found))


@cache
def suffixes() -> frozenset[str]:
    """The whole table, in lower case: the lists above, CasADi's per-function names, and the status
    constants <NAME>_<ID> of runtime/hm_status.h (<NAME>_STOP_DEADLINE, <NAME>_OUTCOME_STALLED, ...)."""
    codes = tuple(f"_{code.id.lower()}" for rows in status_tables().values() for code in rows)
    return frozenset(_FILES + _TARGETS + _API + _MACROS + codes + runtime_type_suffixes() + template_suffixes()
                     + tuple(f"_model_{f}{c}" for f in MODEL_FUNCTIONS for c in CASADI_FUNCTION_SUFFIXES))

# Identifiers C reserves for the library with external linkage, whatever headers a program includes
# (C99 7.26 future library directions, C11 7.31): a package name is the start of its external symbols.
RESERVED_PREFIXES = (
    (re.compile(r"(is|to)[a-z]"), "<ctype.h>'s future functions (is..., to...)"),
    (re.compile(r"(str|mem|wcs)[a-z]"), "<string.h>'s and <stdlib.h>'s future functions (str..., mem..., wcs...)"),
    (re.compile(r"(atomic|cnd|mtx|thrd|tss)_"),
     "C11's <stdatomic.h> and <threads.h> (atomic_, cnd_, mtx_, thrd_, tss_)"),
    (re.compile(r"(hm|casadi|humanmpc)_"), "the runtime's and CasADi's own prefixes (hm_, casadi_, humanmpc_)"),
)


@dataclass(frozen=True)
class Clash:
    """A shorter name ``other`` whose ``other + longer_suffix`` is this name's ``name + suffix``."""

    name: str
    other: str
    tail: str          # the end of name that other lacks
    other_suffix: str  # other's suffix: tail + suffix
    suffix: str

    def explain(self) -> str:
        both = self.other + self.other_suffix
        mine = f"its {self.suffix!r}" if self.suffix else "its C++ namespace and CMake target"
        return (f"a package named {self.other!r} defines {both!r} (its {self.other_suffix!r}), and so would this "
                f"one ({mine}): choose a name that does not end in {self.tail!r}")


def clash(name: str) -> Clash | None:
    """The first way a shorter name's package would define one of this name's files or identifiers, or None."""
    low, table = name.lower(), suffixes()
    for cut in range(1, len(low)):
        tail = low[cut:]
        for other_suffix in sorted(table):
            if other_suffix.startswith(tail) and other_suffix[len(tail):] in table:
                return Clash(name, name[:cut], tail, other_suffix, other_suffix[len(tail):])
    return None


def reserved_prefix(name: str) -> str | None:
    """Why C or the runtime reserves the start of this name, or None."""
    for pattern, why in RESERVED_PREFIXES:
        if pattern.match(name):
            return why
    return None


def derived_names(name: str) -> set[str]:
    """Everything a package named ``name`` defines, in lower case (for the tests' proofs)."""
    return {name.lower() + s for s in suffixes()}
