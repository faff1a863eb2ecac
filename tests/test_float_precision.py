"""Single-precision solvers (spec key `precision: float`) on the host.

The float build must be float throughout: the hand-written runtime through hm_real / HM_R() /
hm_sqrt & co., CasADi's model code through the mechanical fix of codegen/casadi_emit.py (f-variants
of the math calls, f-suffixed literals). Checked by compiling with -Wdouble-promotion -Werror and by
the undefined symbols of the objects. Numerically, the float solver is compared with the double one
on the same replay (tolerances: FLOAT_U0_TOL in test_firmware.py, where they are justified).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.codegen.casadi_emit import make_single_precision
from humanmpc.codegen.spec import FLOAT_MIN_QP_TOL, SpecError, resolve_spec
from humanmpc.compare.replay import Replay
from humanmpc.firmware import image as fw

from .conftest import make_solver, require_tool
from .test_firmware import FLOAT_U0_MEDIAN_TOL, FLOAT_U0_TOL

DOUBLE_MATH = {"sin", "cos", "tan", "sincos", "exp", "log", "sqrt", "pow", "fabs", "fmax", "fmin", "atan2", "tanh"}
FLOAT_SPEC = {"preset": "paper", "precision": "float"}  # the paper spec otherwise, qp_tol 1e-6 included


@pytest.fixture(scope="session")
def float_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("float")


@pytest.fixture(scope="session")
def pair(float_root: Path) -> tuple[humanmpc.Solver, humanmpc.Solver]:
    """(double, float) solvers of the paper's spec."""
    d = make_solver(float_root, {"preset": "paper", "name": "pd"})
    f = make_solver(float_root, {"name": "pf", **FLOAT_SPEC})
    return humanmpc.load(d), humanmpc.load(f)


# -- the spec -----------------------------------------------------------------------------------


def test_precision_key_defaults_to_double_and_takes_float() -> None:
    assert resolve_spec({}).precision == "double"
    spec = resolve_spec(FLOAT_SPEC)
    assert spec.precision == "float" and spec.digest() != resolve_spec({}).digest()


def test_precision_key_is_validated_with_an_actionable_message() -> None:
    with pytest.raises(SpecError, match=r"precision: 'half' is not allowed: must be one of double, float"):
        resolve_spec({"precision": "half"})
    with pytest.raises(SpecError) as err:
        resolve_spec({"precision": "float", "solver": {"qp_tol": 1e-7}})
    assert "solver.qp_tol: 1e-07 is below what single precision reaches" in str(err.value)
    assert f"set solver.qp_tol >= {FLOAT_MIN_QP_TOL:g}" in str(err.value)
    with pytest.raises(SpecError, match=r"line search solves its QPs to 0.1 \* qp_tol.*qp_tol >= 1e-05"):
        resolve_spec({"precision": "float", "solver": {"line_search": True}})
    resolve_spec({"precision": "float", "solver": {"line_search": True, "qp_tol": 1e-5}})


# -- the generated C ----------------------------------------------------------------------------


def test_single_precision_fix_maps_calls_and_literals_only() -> None:
    src = ("/* CasADi 3.8.2 */\n  a01=1.6666666666666666e-02;\n  a02=(2.*a12);\n  a03=sin(a03)+cos(a1)+sqrt(a2);\n"
           "  a04=exp(-a05)*1e-6+.5;\n  a06=casadi_fmax(a01,a03); return fmax(x, y);\n  a07=arg[0]? arg[0][3] : 0;\n")
    out = make_single_precision(src)
    assert "CasADi 3.8.2" in out  # a version number is not a literal
    assert "a01=1.6666666666666666e-02f;" in out and "(2.f*a12)" in out
    assert "sinf(a03)+cosf(a1)+sqrtf(a2)" in out and "expf(-a05)*1e-6f+.5f" in out
    assert "casadi_fmax(a01,a03)" in out and "fmaxf(x, y)" in out  # helpers keep their names
    assert "arg[0][3] : 0;" in out  # integers untouched


def test_float_model_code_has_no_double_call_or_literal(pair: tuple[humanmpc.Solver, humanmpc.Solver]) -> None:
    text = (pair[1].path / "pf_model.c").read_text()
    assert "#define casadi_real float" in text
    code = "\n".join(ln for ln in text.splitlines() if not ln.lstrip().startswith(("/*", "*")))
    for fn in ("sin", "cos", "exp", "sqrt", "fmax"):
        assert f"{fn}(" not in code.replace(f"{fn}f(", "").replace(f"casadi_{fn}(", ""), fn
        assert f"{fn}f(" in code or fn == "fmax"
    assert "2.f" in code and " 2.*" not in code and "(2.*" not in code


@pytest.mark.parametrize("cc", ["gcc", "clang"])
def test_float_package_is_float_throughout(cc: str, pair: tuple[humanmpc.Solver, humanmpc.Solver],
                                           float_root: Path) -> None:
    require_tool(cc)
    d = pair[1].path
    undefined: set[str] = set()
    for src in ("pf.c", "pf_model.c"):
        obj = float_root / f"{cc}_{src}.o"
        proc = subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror", "-Wdouble-promotion",
                               "-I", str(d), "-c", str(d / src), "-o", str(obj)], capture_output=True, text=True,
                              check=False)
        assert proc.returncode == 0, proc.stderr
        nm = subprocess.run(["nm", "-u", str(obj)], capture_output=True, text=True, check=True).stdout
        undefined |= {ln.split()[-1] for ln in nm.splitlines() if ln.strip()}
    assert not undefined & DOUBLE_MATH, sorted(undefined & DOUBLE_MATH)
    # sin/cos/exp are the runtime's own (hm_math.h): single-precision arithmetic, scaled by ldexpf
    assert "ldexpf" in undefined and not undefined & {"expf", "sincosf"}
    assert not undefined & {"malloc", "calloc", "realloc", "free"}


# -- the Python binding -------------------------------------------------------------------------


def test_binding_uses_the_solvers_real_type(pair: tuple[humanmpc.Solver, humanmpc.Solver]) -> None:
    dbl, flt = pair
    assert dbl.dtype == np.float64 and flt.dtype == np.float32
    x, u = [0.3, -0.2, 0.7, 0.6], [0.4, -0.9]
    a, b = dbl.model.dynamics(x, u), flt.model.dynamics(x, u)
    for p, q in zip(a, b, strict=True):
        assert q.dtype == np.float64  # results are handed out as float64 copies either way
        np.testing.assert_allclose(q, p, rtol=2e-6, atol=2e-7)
    c = flt.model.cost_collision([0.0, 0.0], [0.8, 0.1], 2.0, 1.0, 5.0)
    assert c.f == pytest.approx(dbl.model.cost_collision([0.0, 0.0], [0.8, 0.1], 2.0, 1.0, 5.0).f, rel=1e-6)
    flt.reset()
    r = flt.step([0, 0, 0, 0.5], [8, 0, 0, 0.8], [[3.0, 0.4]], np.tile([3.0, 0.4], (51, 1, 1)), [4.0, -1.0])
    assert r.status == 0 and r.x.dtype == np.float64 and r.x.shape == (51, 4)
    flt.set_params(q=3.25)
    assert flt.params["q"] == 3.25  # exactly representable in float


# -- float against double -----------------------------------------------------------------------


@pytest.fixture(scope="session")
def replay(pair: tuple[humanmpc.Solver, humanmpc.Solver]) -> Replay:
    return fw.record_replay(pair[0], steps=60, seed=1)


def test_float_host_stays_within_tolerance_of_double_on_a_cold_replay(
        pair: tuple[humanmpc.Solver, humanmpc.Solver], replay: Replay) -> None:
    dbl, flt = (fw.host_results(s, replay, cold=True) for s in pair)
    assert [(r.stop, r.stop_reason) for r in flt] == [(r.stop, r.stop_reason) for r in dbl]
    assert sum(r.stop for r in dbl) >= 3 and sum(r.status == 0 for r in dbl) >= 20
    du = np.array([np.max(np.abs(a.u0 - b.u0)) for a, b in zip(dbl, flt, strict=True)])
    assert du.max() <= FLOAT_U0_TOL and np.median(du) <= FLOAT_U0_MEDIAN_TOL, du


def test_float_host_makes_the_doubles_stop_decisions_on_warm_replays(float_root: Path) -> None:
    """Warm replays of the damped RTI (line search): the full-step RTI of the paper's weights sends
    float and double down different warm-start sequences (see docs/firmware.md); the damped one keeps
    their decisions together, but not their plans (u0 differs by up to the input ranges: the QP is
    nearly an LP in the turn rate), so a plan may pass a human at d_h in one precision and just
    outside it in the other. Measured over 30 replays of 60 steps: 1 such step in 1,800, with and
    without the QP warm start. Any other decision (the monitor's input checks, a human already within
    d_h, a failed QP) must agree at every step, and the plan check in all but one step per replay."""
    ls = {"line_search": True, "qp_tol": 10 * FLOAT_MIN_QP_TOL}
    dbl = humanmpc.load(make_solver(float_root, {"preset": "paper", "name": "lsd", "solver": ls}))
    flt = humanmpc.load(make_solver(float_root, {"preset": "paper", "name": "lsf", "precision": "float", "solver": ls}))
    unsafe_plan = 7
    stops = 0
    for nh_seed in (0, 1, 2):
        replay = fw.record_replay(dbl, steps=60, seed=nh_seed)
        a, b = fw.host_results(dbl, replay), fw.host_results(flt, replay)
        differ = [(i, ra.stop_reason, rb.stop_reason) for i, (ra, rb) in enumerate(zip(a, b, strict=True))
                  if (ra.stop, ra.stop_reason) != (rb.stop, rb.stop_reason)]
        assert len(differ) <= 1 and all({da, db} == {0, unsafe_plan} for _, da, db in differ), differ
        stops += sum(r.stop for r in a)
        assert not any(r.stop_reason == 4 for r in b), "a float QP failed"
    # decisions to agree on: since the damped RTI starts within the bounds (issue 22, item 10) seed 2's
    # loop passes without a stop; 24 over the three
    assert stops >= 3


def test_float_needs_the_qp_tolerance_the_spec_demands(pair: tuple[humanmpc.Solver, humanmpc.Solver],
                                                       replay: Replay) -> None:
    """Below FLOAT_MIN_QP_TOL float QPs fail (why the spec refuses it): shown at 1e-7, against none at
    the paper's 1e-6."""
    flt = pair[1]
    try:
        failed = {}
        for tol in (FLOAT_MIN_QP_TOL, 0.1 * FLOAT_MIN_QP_TOL):
            flt.set_params(**replay.params)
            flt.set_params(qp_tol=tol)
            flt.reset()
            failed[tol] = sum(flt.step(**replay.inputs(t)).stop_reason == 4 for t in range(replay.steps))
        assert failed[FLOAT_MIN_QP_TOL] == 0
        assert failed[0.1 * FLOAT_MIN_QP_TOL] >= 3  # QPs stop at the float rounding floor above 1e-7
    finally:
        flt.set_params(qp_tol=FLOAT_MIN_QP_TOL)
