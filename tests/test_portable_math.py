"""The runtime's own sin/cos/exp/atan2 (c_runtime/hm_math.h): accurate, and the same bits everywhere.

The model file CasADi writes and the runtime both call them instead of <math.h>'s, whose last bit is
the C library's (glibc and newlib differ; the Cortex-M7's double controller drifted from the host's
by up to 3.7e-8 through them). Accuracy is measured against glibc's long-double functions (an
independent reference 11 bits finer than double); bit identity across compilers and optimisation
levels by a checksum of every result; across host and Cortex-M by tests/test_firmware.py.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from humanmpc.codegen.casadi_emit import ModelMathError, use_portable_math

from .conftest import REPO_ROOT, make_solver, require_tool

HARNESS = REPO_ROOT / "tests" / "c" / "portable_math.c"
RUNTIME = REPO_ROOT / "c_runtime"
# Largest error measured over the harness's sweep, in ulp of the result's precision (double: sin
# 1.45, cos 1.44, exp 0.94, atan2 2.80; float: 1.85, 2.26, 0.92, 3.07), with a margin.
ULP_LIMIT = {"double": 3.0, "float": 3.5}
STRICT = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-Wdouble-promotion"]


def _run(cc: str, flags: list[str], out: Path) -> dict[str, str]:
    exe = out / f"pm-{Path(cc).name}-{'_'.join(f.strip('-') for f in flags)}"
    subprocess.run([cc, *STRICT, *flags, f"-I{RUNTIME}", str(HARNESS), "-o", str(exe), "-lm"], check=True)
    text = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    return {m.group(1): m.group(2) for m in re.finditer(r"^(ulp double|ulp float|checksum) (.*)$", text, re.M)}


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, str]]:
    out = tmp_path_factory.mktemp("portable_math")
    gcc, clang = require_tool("gcc"), require_tool("clang")
    return {
        "gcc -O2": _run(gcc, ["-O2"], out),
        "gcc -O0": _run(gcc, ["-O0"], out),
        "clang -O2": _run(clang, ["-O2"], out),
        # the tools' host build (codegen/build.py HOST_CFLAGS): vector units, contraction off
        "gcc host": _run(gcc, ["-O2", "-march=native", "-funroll-loops", "-ffp-contract=off"], out),
    }


@pytest.mark.parametrize("precision", ["double", "float"])
def test_sin_cos_exp_atan2_are_within_a_few_ulp_of_the_long_double_reference(
    runs: dict[str, dict[str, str]], precision: str
) -> None:
    line = runs["gcc -O2"][f"ulp {precision}"]
    errors = {k: float(v) for k, v in re.findall(r"(\w+) ([0-9.]+)", line)}
    assert set(errors) == {"sin", "cos", "exp", "atan2"}
    assert all(e <= ULP_LIMIT[precision] for e in errors.values()), errors


def test_results_are_bit_identical_across_compilers_and_optimisation_levels(runs: dict[str, dict[str, str]]) -> None:
    sums = {name: r["checksum"] for name, r in runs.items()}
    assert len(set(sums.values())) == 1, sums


def test_special_values_follow_c99(tmp_path: Path) -> None:
    src = tmp_path / "special.c"
    src.write_text(
        '#include <stdio.h>\n#include "hm_math.h"\n'
        "int main(void) {\n"
        "  const double inf = HUGE_VAL, nan = 0.0 / 0.0;\n"
        '  printf("%g %g %g %g\\n", hm_math_atan2(0.0, -0.0), hm_math_atan2(-0.0, -1.0), hm_math_atan2(inf, -inf),'
        " hm_math_atan2(-1.0, inf));\n"
        '  printf("%g %g %g %d\\n", hm_math_exp(710.0), hm_math_exp(-800.0), hm_math_exp(0.0), hm_math_sin(nan) != '
        "hm_math_sin(nan));\n"
        '  printf("%d %d %g %g\\n", (int)signbit(hm_math_sin(-0.0)), hm_math_cos(inf) != hm_math_cos(inf),'
        " hm_math_sin(1e6), (double)hm_math_expf(-200.0f));\n"
        "  return 0;\n}\n"
    )
    exe = tmp_path / "special"
    gcc = require_tool("gcc")
    subprocess.run([gcc, "-std=c99", "-O2", f"-I{RUNTIME}", str(src), "-o", str(exe), "-lm"], check=True)
    lines = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout.split("\n")
    assert lines[0] == "3.14159 -3.14159 2.35619 -0"
    assert lines[1] == "inf 0 1 1"
    # beyond the exact reduction (fmod by 2 pi): sin(1e6) = -0.349994 to 4e-11
    assert lines[2] == "1 1 -0.349994 0"


def test_generated_model_calls_no_library_sin_cos_or_exp(tmp_path: Path) -> None:
    out = make_solver(tmp_path, {"name": "pm", "preset": "paper"}, built=False)
    obj = tmp_path / "model.o"
    subprocess.run(
        [require_tool("gcc"), *STRICT, "-O2", "-c", str(out / "pm_model.c"), "-o", str(obj)], check=True, cwd=out
    )
    nm = subprocess.run(["nm", "-u", str(obj)], check=True, capture_output=True, text=True).stdout
    undefined = {ln.split()[-1] for ln in nm.splitlines() if ln.strip()}
    assert not undefined & {"sin", "cos", "exp", "sinf", "cosf", "expf", "sincos"}, undefined
    assert undefined <= {"sqrt", "fabs", "fmax", "fmin", "floor", "fmod", "ldexp"}, undefined
    assert "hm_math_sin(" in (out / "pm_model.c").read_text()


def test_a_model_calling_an_unprovided_library_function_is_refused_with_its_name() -> None:
    source = "#include <math.h>\nstatic double f(double x) { return tan(x) + sqrt(x); }\n"
    with pytest.raises(ModelMathError, match=r"call tan\(\), whose result depends on the C library"):
        use_portable_math(source)
    assert "hm_math_sinf(" in use_portable_math("#include <math.h>\nfloat g(float x) { return sinf(x); }\n")
