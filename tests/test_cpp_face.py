"""The C++ face of a generated solver (<name>.hpp over Eigen fixed-size types, templates/solver.hpp.j2).

A C++ program, compiled with g++ -Wall -Wextra -pedantic -Werror against Debian's Eigen, replays a
recorded input sequence through the C API and through the C++ face side by side (two solvers),
checks inside that both give the same bits, that the Eigen maps are views of the C structs (no
copies), and prints its results; they must equal the host library's (Python, through cffi) bit for
bit, since the same C is compiled with the same compiler and flags.
"""

from __future__ import annotations

import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

import humanmpc
from humanmpc.compare.replay import Replay
from humanmpc.firmware import image as fw

from .conftest import make_solver, require_tool

STEPS = 30

PROGRAM = r"""
#include "NAME.hpp"

#include <cstdio>
#include <cstring>

#include "replay_data.h"

typedef NAME::Real Real;
static NAME::Solver face;           /* the C++ face: one object, placed statically */
static NAME_solver c_solver;        /* the C API, side by side */
static NAME_input c_in;
static NAME_output c_out;

static void load_c(int t)
{
    const int k = replay_n_humans[t], row = replay_human_offset[t];
    std::memcpy(c_in.x0, replay_x0[t], sizeof c_in.x0);
    std::memcpy(c_in.goal, replay_goal[t], sizeof c_in.goal);
    c_in.n_humans = k;
    for (int j = 0; j < k; j++) {
        c_in.humans_now[j][0] = replay_humans_now[row + j][0];
        c_in.humans_now[j][1] = replay_humans_now[row + j][1];
        c_in.humans_vel[j][0] = replay_humans_vel[row + j][0];
        c_in.humans_vel[j][1] = replay_humans_vel[row + j][1];
        for (int n = 0; n <= NAME::N; n++) {
            c_in.humans_pred[n][j][0] = replay_humans_pred[row + j][n][0];
            c_in.humans_pred[n][j][1] = replay_humans_pred[row + j][n][1];
        }
    }
    c_in.has_obstacle = replay_has_obstacle[t];
    std::memcpy(c_in.obstacle, replay_obstacle[t], sizeof c_in.obstacle);
}

static void load_face(int t)
{
    typedef Eigen::Map<const NAME::State> CState;
    typedef Eigen::Map<const NAME::Point> CPoint;
    const int k = replay_n_humans[t], row = replay_human_offset[t];
    face.x0() = CState(replay_x0[t]);
    face.goal() = CState(replay_goal[t]);
    face.n_humans() = k;
    for (int j = 0; j < k; j++) {
        face.humans_now().col(j) = CPoint(replay_humans_now[row + j]);
        face.humans_vel().col(j) = CPoint(replay_humans_vel[row + j]);
        for (int n = 0; n <= NAME::N; n++) face.humans_pred(n).col(j) = CPoint(replay_humans_pred[row + j][n]);
    }
    face.has_obstacle() = replay_has_obstacle[t];
    face.obstacle() = CPoint(replay_obstacle[t]);
}

static void print_real(Real v)
{
    unsigned char b[sizeof(Real)];
    std::memcpy(b, &v, sizeof v);
    std::printf(" ");
    for (int i = (int)sizeof v - 1; i >= 0; i--) std::printf("%02x", b[i]);
}

int main()
{
    int bad = 0;
    NAME_solver_init(&c_solver);
    replay_set_params(NAME_solver_params(&c_solver));
    replay_set_params(&face.params());

    /* views, not copies: every map points into the C structs */
    if (face.x0().data() != face.input().x0 || face.humans_pred(3).data() != &face.input().humans_pred[3][0][0] ||
        face.humans_vel().data() != &face.input().humans_vel[0][0] ||
        face.humans_pred().data() != &face.input().humans_pred[0][0][0] || face.u0().data() != face.output().u0 ||
        face.x().data() != &face.output().x[0][0] || face.u().data() != &face.output().u[0][0]) {
        std::printf("error: a map is not a view of the C struct\n");
        bad = 1;
    }

    for (int t = 0; t < REPLAY_STEPS; t++) {
        load_c(t);
        load_face(t);
        if (std::memcmp(&c_in, &face.input(), sizeof c_in) != 0) {
            /* padding and absent humans may differ: compare what the solver reads */
            if (c_in.n_humans != face.input().n_humans || (face.x0() - Eigen::Map<NAME::State>(c_in.x0)).norm() != 0)
                bad = 2;
        }
        const int st_c = NAME_solver_step(&c_solver, &c_in, &c_out);
        const int st = face.step();
        const Eigen::Map<const NAME::StatePlan> c_x(&c_out.x[0][0]);
        const Eigen::Map<const NAME::ControlPlan> c_u(&c_out.u[0][0]);
        if (st != st_c || face.status() != c_out.status || face.stop() != (c_out.stop != 0) ||
            face.stop_reason() != c_out.stop_reason || (face.x() - c_x).cwiseAbs().maxCoeff() != 0 ||
            (face.u() - c_u).cwiseAbs().maxCoeff() != 0 || face.u0() != NAME::Control(c_out.u0[0], c_out.u0[1])) {
            std::printf("error: step %d differs between the C API and the C++ face\n", t);
            bad = 3;
        }
        std::printf("step %d %d %d %d", t, face.status(), face.stop() ? 1 : 0, face.stop_reason());
        print_real(face.u0()(0));
        print_real(face.u0()(1));
        print_real(face.x()(0, NAME::N));
        print_real(face.x()(1, NAME::N));
        std::printf("\n");
    }

    /* the model functions, typed: fixed-size Eigen in, fixed-size Eigen out */
    NAME::State x;
    x << Real(0.3), Real(-0.2), Real(0.7), Real(0.6);
    NAME::Control u;
    u << Real(0.4), Real(-0.9);
    NAME::State x_next;
    Eigen::Matrix<Real, 4, 4> A;
    Eigen::Matrix<Real, 4, 2> B;
    NAME::dynamics(x, u, x_next, A, B);
    Real xn_c[4], A_c[16], B_c[8];
    NAME_dynamics(x.data(), u.data(), xn_c, A_c, B_c);
    if (x_next != Eigen::Map<NAME::State>(xn_c) || A != Eigen::Map<Eigen::Matrix<Real, 4, 4> >(A_c) ||
        B != Eigen::Map<Eigen::Matrix<Real, 4, 2> >(B_c))
        bad = 4;
    Real f;
    NAME::Point grad;
    Eigen::Matrix<Real, 2, 2> h_gn, h;
    NAME::cost_collision(NAME::Point(0, 0), NAME::Point(Real(0.8), Real(0.1)), 2, 1, 5, f, grad, h_gn, h);
    std::printf("model");
    print_real(x_next(0));
    print_real(A(0, 2));
    print_real(B(1, 1));
    print_real(f);
    print_real(grad(0));
    std::printf("\n");
    std::printf(bad ? "FAILED %d\n" : "ok\n", bad);
    return bad;
}
"""

WRONG = r"""
#include "NAME.hpp"
int main()
{
    NAME::State x = NAME::State::Zero(), x_next;
    Eigen::Matrix<NAME::Real, 3, 1> u3 = Eigen::Matrix<NAME::Real, 3, 1>::Zero();  /* a control has 2 entries */
    Eigen::Matrix<NAME::Real, 4, 4> A;
    Eigen::Matrix<NAME::Real, 4, 2> B;
    return NAME::dynamics(x, u3, x_next, A, B);
}
"""


def _eigen_flags() -> list[str]:
    pc = shutil.which("pkg-config")
    if pc:
        proc = subprocess.run([pc, "--cflags", "eigen3"], capture_output=True, text=True, check=False)
        if proc.returncode == 0:
            return proc.stdout.split()
    if Path("/usr/include/eigen3/Eigen/Core").is_file():
        return ["-I/usr/include/eigen3"]
    pytest.fail("Eigen 3 is not installed: `make test` installs libeigen3-dev (see APT_PACKAGES in the Makefile)")


def _real(text: str, real: str) -> float:
    return float(struct.unpack(">f" if real == "float" else ">d", bytes.fromhex(text))[0])


@pytest.fixture(scope="session")
def cpp_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    require_tool("g++")
    require_tool("gcc")
    return tmp_path_factory.mktemp("cpp")


def _build(d: Path, name: str, root: Path, std: str, source: str) -> tuple[subprocess.CompletedProcess[str], Path]:
    exe = root / f"{name}_{std}"
    cpp = root / f"{name}_{std}.cpp"
    cpp.write_text(source.replace("NAME", name))
    objs = []
    for src in (d / f"{name}.c", d / f"{name}_model.c", d / "firmware" / "replay_data.c"):
        obj = root / f"{name}_{src.stem}.o"
        if not obj.exists():
            subprocess.run(["gcc", "-std=c99", "-O2", "-I", str(d), "-I", str(d / "firmware"), "-c", str(src), "-o",
                            str(obj)], check=True)
        objs.append(str(obj))
    proc = subprocess.run(["g++", f"-std={std}", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror", *_eigen_flags(),
                           "-I", str(d), "-I", str(d / "firmware"), str(cpp), *objs, "-lm", "-o", str(exe)],
                          capture_output=True, text=True, check=False)
    return proc, exe


@pytest.fixture(scope="session", params=["double", "float"])
def case(request: pytest.FixtureRequest, cpp_root: Path) -> tuple[Path, str, Replay]:
    real = request.param
    name = f"cpp{real[0]}"
    d = make_solver(cpp_root, {"name": name, "precision": real})
    replay = fw.record_replay(humanmpc.load(d), steps=STEPS, seed=1)
    fw.write_firmware(d, replay)  # replay_data.c/h: the same inputs as constants
    return d, name, replay


@pytest.mark.parametrize("std", ["c++11", "c++17"])
def test_cpp_face_compiles_strictly_and_matches_the_c_api_and_the_host(case: tuple[Path, str, Replay], std: str,
                                                                       cpp_root: Path) -> None:
    d, name, replay = case
    proc, exe = _build(d, name, cpp_root, std, PROGRAM)
    assert proc.returncode == 0, proc.stderr[-4000:]
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 0 and run.stdout.rstrip().endswith("ok"), run.stdout[-2000:]
    real = "float" if name.endswith("f") else "double"
    host = fw.host_results(humanmpc.load(d), replay)
    lines = [ln.split() for ln in run.stdout.splitlines() if ln.startswith("step ")]
    assert len(lines) == STEPS
    for f, h in zip(lines, host, strict=True):
        t, status, stop, reason = (int(v) for v in f[1:5])
        assert (status, stop, reason) == (h.status, int(h.stop), h.stop_reason), f"step {t}"
        u0 = [_real(v, real) for v in f[5:7]]
        x_end = [_real(v, real) for v in f[7:9]]
        assert u0 == list(h.u0) and x_end == list(h.x[-1, :2]), f"step {t}: C++ {u0} vs host {h.u0}"
    model = next(ln.split() for ln in run.stdout.splitlines() if ln.startswith("model "))
    solver = humanmpc.load(d)
    dyn = solver.model.dynamics([0.3, -0.2, 0.7, 0.6], [0.4, -0.9])
    col = solver.model.cost_collision([0, 0], [0.8, 0.1], 2, 1, 5)
    got = [_real(v, real) for v in model[1:]]
    assert got == [dyn.x_next[0], dyn.A[0, 2], dyn.B[1, 1], col.f, col.grad_p[0]]


def test_cpp_face_rejects_a_wrongly_sized_argument_at_compile_time(case: tuple[Path, str, Replay],
                                                                   cpp_root: Path) -> None:
    d, name, _ = case
    proc, _ = _build(d, name, cpp_root, "c++11", WRONG)
    assert proc.returncode != 0
    assert "YOU_MIXED_MATRICES_OF_DIFFERENT_SIZES" in proc.stderr  # Eigen's static size check


def test_cpp_face_header_is_in_the_package(case: tuple[Path, str, Replay]) -> None:
    d, name, _ = case
    text = (d / f"{name}.hpp").read_text()
    assert f"namespace {name} {{" in text and "#include <Eigen/Core>" in text
    assert "new " not in text and "malloc" not in text and "std::vector" not in text
    assert np.all([f"inline int {f}(" in text for f in ("dynamics", "cost_stage", "cost_collision")])
