"""The exact Hessian's projection onto {eigenvalues >= floor}, per stage, against numpy's eigh.

The full SQP and the RTI with the exact Hessian (the default) convexify every stage's [Q S'; S R] by
replacing the eigenvalues below a floor with the floor. The C does it with Jacobi rotations, with the
2 x 2 position block in closed form, and keeps a matrix whose eigenvalues are all above the floor as
it is; the reference is LAPACK's symmetric eigensolver through numpy (white box: tests/c/psd_projection.c
includes the solver's translation unit).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from .conftest import make_solver, require_tool

C_DIR = Path(__file__).resolve().parent / "c"
STRICT = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]
NX, NU = 4, 2


@pytest.fixture(scope="module")
def harness(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("psd")
    d = make_solver(root, {"name": "psd"}, built=False)
    exe = root / "psd_projection"
    cmd = [require_tool("gcc"), *STRICT, "-O2", '-DSOLVER_SOURCE="psd.c"', "-I", str(d),
           str(C_DIR / "psd_projection.c"), str(d / "psd_model.c"), "-lm", "-o", str(exe)]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr
    return exe


def project(exe: Path, kind: str, mats: list[np.ndarray], floor: float) -> list[np.ndarray]:
    lines = [f"{kind} {m.shape[0]} {floor!r} " + " ".join(repr(float(v)) for v in m.flatten(order="F"))
             for m in mats]
    proc = subprocess.run([str(exe)], input="\n".join(lines) + "\n", capture_output=True, text=True,
                          timeout=60, check=True)
    rows = proc.stdout.split("\n")[: len(mats)]
    return [np.array([float(v) for v in r.split()]).reshape(m.shape, order="F")
            for r, m in zip(rows, mats, strict=True)]


def reference(m: np.ndarray, floor: float) -> np.ndarray:
    lam, v = np.linalg.eigh(m)
    return (v * np.maximum(lam, floor)) @ v.T


def random_symmetric(rng: np.random.Generator, n: int, scale: float) -> np.ndarray:
    a = rng.normal(size=(n, n)) * scale
    return 0.5 * (a + a.T)


def assert_projection(got: np.ndarray, m: np.ndarray, floor: float) -> None:
    want = reference(m, floor)
    tol = 1e-13 * max(1.0, float(np.abs(m).max()), floor)
    np.testing.assert_allclose(got, want, rtol=0, atol=tol)
    assert np.array_equal(got, got.T)
    assert np.linalg.eigvalsh(got).min() >= floor - tol


@pytest.mark.parametrize("floor", [1e-8, 0.5])
def test_jacobi_projection_matches_eigh_on_dense_indefinite_matrices(harness: Path, floor: float) -> None:
    rng = np.random.default_rng(7)
    mats = [random_symmetric(rng, n, s) for n in (2, 3, 4, 6) for s in (1e-3, 1.0, 1e3) for _ in range(10)]
    for got, m in zip(project(harness, "full", mats, floor), mats, strict=True):
        assert_projection(got, m, floor)


def test_closed_form_pair_matches_eigh_including_diagonal_and_repeated_eigenvalues(harness: Path) -> None:
    rng = np.random.default_rng(11)
    mats = [random_symmetric(rng, 2, s) for s in (1e-4, 1.0, 1e4) for _ in range(30)]
    mats += [np.diag([-1.0, 2.0]), np.diag([2.0, -1.0]), np.diag([-3.0, -3.0]),
             np.array([[1.0, 1e-12], [1e-12, 1.0]]), np.array([[0.0, 1.0], [1.0, 0.0]]),
             np.array([[-2.0, 0.5], [0.5, -2.0]]), np.array([[1e-9, 1.0], [1.0, 1e9]])]
    for floor in (1e-8, 0.3):
        for got, m in zip(project(harness, "pair", mats, floor), mats, strict=True):
            assert_projection(got, m, floor)


def test_a_matrix_above_the_floor_is_kept_bit_for_bit(harness: Path) -> None:
    rng = np.random.default_rng(3)
    mats = []
    for n in (2, 4, 6):
        a = rng.normal(size=(n, n))
        mats.append(a @ a.T + 0.1 * np.eye(n))
    for kind in ("full", "pair"):
        use = [m for m in mats if kind == "full" or m.shape[0] == 2]
        for got, m in zip(project(harness, kind, use, 1e-8), use, strict=True):
            assert np.array_equal(got, m), kind


def test_stage_projection_is_that_of_its_blocks_or_of_the_whole_matrix(harness: Path) -> None:
    """A robot stage is block diagonal, (px, py) apart from (theta, v, a, omega): projected block by
    block (the closed form and Jacobi); a stage that couples the blocks is projected whole. Both are
    the projection of the whole matrix."""
    rng = np.random.default_rng(5)
    nz = NX + NU
    mats = []
    for s in (1e-2, 1.0, 1e2):
        for _ in range(10):
            m = np.zeros((nz, nz))
            m[:2, :2] = random_symmetric(rng, 2, s)
            m[2:, 2:] = random_symmetric(rng, nz - 2, s)
            mats.append(m)
            coupled = m.copy()
            coupled[0, 3] = coupled[3, 0] = 0.3 * s
            mats.append(coupled)
    for floor in (1e-8, 0.5):
        for got, m in zip(project(harness, "stage", mats, floor), mats, strict=True):
            assert_projection(got, m, floor)
            if m[0, 3] == 0.0:
                assert not got[:2, 2:].any(), "the blocks stay apart"
