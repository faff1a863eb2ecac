"""CasADi code generation of the model functions, and the mechanical fixes its C needs.

CasADi's output is correct but made for one solver per program: two helpers (casadi_sq, ...)
are global, and its evaluation signature passes work vectors a function may not use. The fixes
below make every helper static and mark each parameter as used, so that the file compiles under
-Wall -Wextra -pedantic -Werror and two solvers link into one binary. They are applied to the
text CasADi wrote and checked by the compile and nm tests.
"""

from __future__ import annotations

import errno
import re
from dataclasses import dataclass
from pathlib import Path

import casadi as ca

from .ocp import ModelFunction

# A function definition: return type and name, the parameter list, and its opening brace.
_DEFINITION = re.compile(
    r"^(?P<head>(?:static |CASADI_SYMBOL_EXPORT )?[A-Za-z_][\w \*]*?\b(?P<name>[A-Za-z_]\w*)"
    r"\((?P<params>[^;{}()]*)\)\s*\{)",
    re.MULTILINE,
)
# A file-scope helper CasADi leaves global, e.g. "casadi_real casadi_sq(casadi_real x) {".
_GLOBAL_HELPER = re.compile(r"^(?!static )(?!CASADI_SYMBOL_EXPORT )([A-Za-z_][\w \*]*\bcasadi_\w+\()", re.MULTILINE)


# The <math.h> functions CasADi's code generator may call. casadi_real = float only changes the
# type: the calls stay double (sin, exp, ...) and so do the literals (2., 1.0000000000000001e-01), so
# every operation promotes to double and back. On a single-precision FPU (Cortex-M4) that is
# soft-float double arithmetic, ~19x slower, and it breaks -Wdouble-promotion. A float build maps
# each call to its C99 f-variant and gives each floating literal the f suffix, in the text itself:
# the file stays correct with any compiler and flags (no -fsingle-precision-constant, no
# force-included header that every build system would have to repeat).
_MATH_FUNCTIONS = (
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh",
    "exp", "expm1", "log", "log1p", "log10", "sqrt", "cbrt", "pow", "fabs", "fmod", "fmin", "fmax", "floor",
    "ceil", "round", "trunc", "erf", "erfc", "copysign", "hypot",
)
_MATH_CALL = re.compile(r"(?<![\w.])(" + "|".join(_MATH_FUNCTIONS) + r")(?=\s*\()")
# Functions whose result C99 leaves to the library (one bit differs between glibc and newlib): the
# model calls the runtime's own (c_runtime/hm_math.h), so that a robot's computer and its firmware
# compute the same bits. The others the model may call are exactly rounded by IEEE 754 (sqrt) or
# exact (fabs, fmin, ...), the same everywhere.
_PORTABLE_FUNCTIONS = ("sin", "cos", "exp", "atan2")
_EXACT_FUNCTIONS = ("sqrt", "fabs", "fmin", "fmax", "floor", "ceil", "round", "trunc", "copysign", "fmod")
_LIBRARY_CALL = re.compile(r"(?<![\w.])(" + "|".join(_MATH_FUNCTIONS) + r")(f?)(?=\s*\()")
_MATH_INCLUDE = "#include <math.h>\n"
# A decimal floating literal without suffix: 2., 0.5, .5, 1e-6, 1.0000000000000001e-01.
_DOUBLE_LITERAL = re.compile(
    r"(?<![\w.])((?:[0-9]+\.[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?|[0-9]+[eE][-+]?[0-9]+)(?![\w.])"
)


@dataclass(frozen=True)
class EmittedFunction:
    model: ModelFunction
    casadi_name: str  # the C symbol CasADi generated, e.g. paper_model_dynamics
    sz_arg: int
    sz_res: int
    sz_iw: int
    sz_w: int


def _param_names(params: str) -> list[str]:
    names = []
    for decl in params.split(","):
        decl = decl.strip()
        if not decl or decl == "void":
            continue
        names.append(re.findall(r"[A-Za-z_]\w*", decl)[-1])
    return names


def make_parameters_used(source: str) -> str:
    def mark(m: re.Match[str]) -> str:
        casts = "".join(f" (void){n};" for n in _param_names(m.group("params")))
        return m.group("head") + casts

    return _DEFINITION.sub(mark, source)


def make_helpers_static(source: str) -> str:
    return _GLOBAL_HELPER.sub(r"static \1", source)


def make_single_precision(source: str) -> str:
    """Single-precision math calls and float literals in CasADi's C (comments and strings hold none
    that matter: a version number such as 3.8.2 is left alone by the look-arounds)."""
    return _DOUBLE_LITERAL.sub(r"\1f", _MATH_CALL.sub(r"\1f", source))


class ModelMathError(ValueError):
    """The model's C calls a <math.h> function the runtime has no portable version of."""


def use_portable_math(source: str) -> str:
    """sin/cos/exp/atan2 (and their f-variants) to the runtime's hm_math_*, included from the
    package's runtime/ folder; any other library function whose last bit is the library's is an error
    (the generated package would compute differently on different C libraries)."""

    def rename(m: re.Match[str]) -> str:
        name, suffix = m.group(1), m.group(2)
        if name in _PORTABLE_FUNCTIONS:
            return f"hm_math_{name}{suffix}"
        if name in _EXACT_FUNCTIONS:
            return m.group(0)
        raise ModelMathError(
            f"the model functions call {name}{suffix}(), whose result depends on the C library; "
            f"c_runtime/hm_math.h provides {', '.join(_PORTABLE_FUNCTIONS)}: add {name} there "
            "(and to codegen/casadi_emit.py's _PORTABLE_FUNCTIONS) or write the model without it"
        )

    if _MATH_INCLUDE not in source:
        raise ModelMathError("CasADi's C no longer includes <math.h> where humanmpc expects it")
    renamed = _LIBRARY_CALL.sub(rename, source)
    return renamed.replace(_MATH_INCLUDE, _MATH_INCLUDE + '#include "runtime/hm_math.h"\n', 1)


# How every file CasADi writes ends: a file without it was cut short.
_CASADI_END = '} /* extern "C" */\n#endif\n'


def check_complete(path: Path) -> None:
    """CasADi writes with C++ streams and reports no error: on a full file system it leaves a truncated
    file (measured: 4096 of 10,911 bytes, no exception). Raise OSError when the file does not end as
    CasADi ends every file, so the package is not moved into place."""
    try:
        with path.open("rb") as f:
            f.seek(max(0, path.stat().st_size - len(_CASADI_END)))
            tail = f.read().decode("ascii", errors="replace")
    except OSError:
        raise
    if tail != _CASADI_END:
        raise OSError(errno.EIO, "CasADi's output is cut short (is the file system full?)", str(path))


def emit_model(functions: tuple[ModelFunction, ...], prefix: str, real: str, out_dir: Path) -> list[EmittedFunction]:
    """Write {prefix}_model.c/.h into out_dir; return what the templates need of each function."""
    basename = f"{prefix}_model"
    cg = ca.CodeGenerator(
        f"{basename}.c",
        {
            "with_header": True,
            "casadi_int": "int",
            "casadi_real": real,
            "prefix": f"{prefix}_casadi",  # CasADi appends "_"
            "main": False,
            "mex": False,
            "cpp": False,
        },
    )
    emitted = []
    for mf in functions:
        casadi_name = f"{prefix}_model_{mf.name}"
        fn = mf.function
        # Rebuild under the prefixed name: CasADi names the C symbol after the Function. Common
        # subexpressions merged (ca.cse): derivatives rebuild nodes that the values already have.
        ins = fn.sx_in()
        renamed = ca.Function(casadi_name, ins, ca.cse(fn.call(ins)), fn.name_in(), fn.name_out())
        cg.add(renamed)
        emitted.append(
            EmittedFunction(
                model=mf,
                casadi_name=casadi_name,
                sz_arg=max(1, renamed.sz_arg()),
                sz_res=max(1, renamed.sz_res()),
                sz_iw=max(1, renamed.sz_iw()),
                sz_w=max(1, renamed.sz_w()),
            )
        )
    cg.generate(str(out_dir) + "/")
    for written in (out_dir / f"{basename}.c", out_dir / f"{basename}.h"):
        check_complete(written)
    single = " single-precision math and literals," if real == "float" else ""
    banner = (
        f"/* {basename}.c: model functions of the humanmpc solver \"{prefix}\", written by CasADi "
        f"{ca.CasadiMeta.version()}\n * and adjusted mechanically by humanmpc (static helpers,{single} parameters "
        "marked used, sin/cos/exp of runtime/hm_math.h). Do not edit. */\n"
    )
    c_file = out_dir / f"{basename}.c"
    text = make_helpers_static(make_parameters_used(c_file.read_text()))
    if real == "float":
        text = make_single_precision(text)
    c_file.write_text(banner + use_portable_math(text))
    return emitted
