"""Test support for the C QP solver (c_runtime/ocp_qp*.c): build and drive tests/c/qp_harness.c,
generate stage-structured QPs, solve them independently with Clarabel, and check KKT conditions.

Problem data live in :class:`QP` in natural (row-major, numpy) shapes; the harness converts to the
column-major C layout. The conic form for Clarabel packs rows in the same order as the C solver
(per stage: bounds, lower before upper, u before x; general rows; s >= 0 of soft rows), so that the
Newton system of the C code can be compared with a dense one row for row.
"""

from __future__ import annotations

import dataclasses
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cffi
import numpy as np
import scipy.sparse as sp

NX, NU, NPOS = 4, 2, 2
NUX = NU + NX
HM_INF = 1e30
REPO = Path(__file__).resolve().parent.parent
RUNTIME = REPO / "c_runtime"
CDIR = Path(__file__).resolve().parent / "c"

# The flags every runtime file must pass (project convention).
STRICT_FLAGS = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-Wshadow", "-Wdouble-promotion"]

STATUS = {"SOLVED": 0, "MAX_ITER": 1, "INFEASIBLE": 2, "NUMERICAL": 3, "NONFINITE": 4, "TIMEOUT": 5}
SOLVED, MAX_ITER, INFEASIBLE, NUMERICAL, NONFINITE, TIMEOUT = range(6)

Array = np.ndarray[Any, np.dtype[np.float64]]


@dataclass
class QP:
    """The QP of c_runtime/ocp_qp_types.h (ocp_qp), natural matrix shapes (A[n] is 4x4, S[n] is 2x4)."""

    A: Array
    B: Array
    b: Array
    Q: Array
    S: Array
    R: Array
    q: Array
    r: Array
    x0: Array
    lbx: Array
    ubx: Array
    lbu: Array
    ubu: Array
    ng: np.ndarray[Any, np.dtype[np.int32]]
    D: Array
    lg: Array
    soft: np.ndarray[Any, np.dtype[np.int32]]
    zl: Array
    Zl: Array

    @property
    def horizon(self) -> int:
        """N: the number of intervals (stages 0..N)."""
        return int(self.A.shape[0])

    @property
    def ng_max(self) -> int:
        """HM_NG: the room for general rows per stage."""
        return int(self.D.shape[1])

    def copy(self) -> QP:
        return QP(**{f.name: np.array(getattr(self, f.name), copy=True) for f in dataclasses.fields(self)})


@dataclass
class Sol:
    """ocp_qp_sol in natural shapes."""

    x: Array
    u: Array
    s: Array
    pi: Array
    lam_lbx: Array
    lam_ubx: Array
    lam_lbu: Array
    lam_ubu: Array
    lam_lg: Array
    lam_ls: Array


@dataclass
class Result:
    status: int
    iter: int
    polls: int
    unbounded: int
    polished: int
    sol: Sol
    res: dict[str, float]  # ocp_qp_res recorded in the workspace
    scaled: tuple[float, float, float]  # res_primal, res_dual, gap
    mu_tau_kappa: tuple[float, float, float]
    fallback: int = 0  # the homogeneous-embedding fallback solver produced the result


def present(v: Array | float) -> Any:
    return np.abs(v) < HM_INF


# ------------------------------------------------------------------------------------------------
# Building and driving the harness
# ------------------------------------------------------------------------------------------------


def compile_c(
    sources: list[Path], out: Path, defines: dict[str, str], shared: bool, cc: str = "gcc",
    extra: tuple[str, ...] = (), opt: str = "-O2",
) -> None:
    cmd = [cc, *STRICT_FLAGS, opt, f"-I{RUNTIME}"]
    cmd += [f"-D{k}={v}" if v else f"-D{k}" for k, v in defines.items()]
    cmd += list(extra)
    if shared:
        cmd += ["-fPIC", "-shared"]
    cmd += [str(s) for s in sources] + ["-o", str(out), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"compile failed: {' '.join(cmd)}\n{proc.stdout}{proc.stderr}")


def _cdef(N: int, NG: int, real: str) -> str:
    ng1 = N + 1
    return f"""
typedef struct {{
    {real} A[{N}][16]; {real} B[{N}][8]; {real} b[{N}][4]; {real} Q[{ng1}][16]; {real} S[{N}][8];
    {real} R[{N}][4]; {real} q[{ng1}][4]; {real} r[{N}][2]; {real} x0[4];
    {real} lbx[{ng1}][4]; {real} ubx[{ng1}][4]; {real} lbu[{N}][2]; {real} ubu[{N}][2];
    int ng[{ng1}]; {real} D[{ng1}][{NG}][2]; {real} lg[{ng1}][{NG}]; int soft[{ng1}][{NG}];
    {real} zl[{ng1}][{NG}]; {real} Zl[{ng1}][{NG}];
}} qpt_ocp_qp;
typedef struct {{
    {real} x[{ng1}][4]; {real} u[{N}][2]; {real} s[{ng1}][{NG}]; {real} pi[{N}][4];
    {real} lam_lbx[{ng1}][4]; {real} lam_ubx[{ng1}][4]; {real} lam_lbu[{N}][2]; {real} lam_ubu[{N}][2];
    {real} lam_lg[{ng1}][{NG}]; {real} lam_ls[{ng1}][{NG}];
}} qpt_ocp_qp_sol;
int qp_harness_dims(int *n, int *ng, int *real_size, int *nc_max);
size_t qp_harness_sizeof(int which);
qpt_ocp_qp *qp_harness_qp(void);
qpt_ocp_qp_sol *qp_harness_sol(void);
void qp_harness_set_zero(void);
int qp_harness_check(void);
void qp_harness_arg(int max_iter, double tol, double tol_infeas, int stop_after, int polish);
void qp_harness_warm(int warm_start, double warm_mu);
int qp_harness_solve(void);
int qp_harness_solve_fallback(void);
int qp_harness_rows(void);
int qp_harness_info(int *iter, int *polls, int *flags, double *res6, double *scaled3, double *mtk3);
void qp_harness_res(double *res6);
const char *qp_harness_status_message(int status);
int qp_harness_kkt_map(int *m, int *off, int *nb, int *nr, int *ns, int *kernel, double *cost_scale);
int qp_harness_kkt_solve(const {real} *w, const {real} *rhs, {real} *sol);
"""


QP_FIELDS = ["A", "B", "b", "Q", "S", "R", "q", "r", "x0", "lbx", "ubx", "lbu", "ubu", "ng", "D", "lg",
             "soft", "zl", "Zl"]
SOL_FIELDS = ["x", "u", "s", "pi", "lam_lbx", "lam_ubx", "lam_lbu", "lam_ubu", "lam_lg", "lam_ls"]
RES_KEYS = ["stat", "eq", "ineq", "comp", "dual", "obj"]


class Harness:
    """The shared library of tests/c/qp_harness.c for one (N, NG, real type)."""

    def __init__(self, lib_path: Path, N: int, NG: int, real: str = "double") -> None:
        self.horizon, self.ng_max, self.real = N, NG, real
        self.dtype = np.float64 if real == "double" else np.float32
        self.ffi = cffi.FFI()
        self.ffi.cdef(_cdef(N, NG, real))
        self.lib: Any = self.ffi.dlopen(str(lib_path))
        n, ng, rs, ncmax = (self.ffi.new("int *") for _ in range(4))
        self.lib.qp_harness_dims(n, ng, rs, ncmax)
        assert (n[0], ng[0], rs[0]) == (N, NG, np.dtype(self.dtype).itemsize)
        self.nc_max = int(ncmax[0])
        # The Python view of the structs must be the C layout.
        assert self.lib.qp_harness_sizeof(0) == self.ffi.sizeof("qpt_ocp_qp")
        assert self.lib.qp_harness_sizeof(1) == self.ffi.sizeof("qpt_ocp_qp_sol")
        self.vec_len = (N + 1) * NUX + (N + 1) * NG + N * NX + self.nc_max
        assert self.lib.qp_harness_sizeof(2) == self.vec_len * np.dtype(self.dtype).itemsize
        self.lib.qp_harness_set_zero()

    @classmethod
    def build(cls, out_dir: Path, N: int, NG: int, real: str = "double", cc: str = "gcc",
              rows: int | None = None) -> Harness:
        """rows: soft rows a QP may hold (the solvers' row capacity); None: every row."""
        defines = {"QPT_N": str(N), "QPT_NG": str(NG)}
        if real == "float":
            defines["HM_REAL_IS_FLOAT"] = ""
        if rows is not None:
            defines["QPT_NRC"] = str(rows)
        lib = out_dir / f"libqpt_{N}_{NG}_{real}_{cc}{'' if rows is None else f'_r{rows}'}.so"
        compile_c([CDIR / "qp_harness.c"], lib, defines, shared=True, cc=cc, extra=("-Wmissing-prototypes",))
        return cls(lib, N, NG, real)

    def _view(self, cdata: Any, dtype: Any) -> Any:
        return np.frombuffer(self.ffi.buffer(cdata), dtype=dtype)

    def load(self, qp: QP) -> None:
        """Writes qp into the static ocp_qp (matrices column-major)."""
        assert (qp.horizon, qp.ng_max) == (self.horizon, self.ng_max)
        c = self.lib.qp_harness_qp()
        colmajor = {"A", "B", "Q", "S", "R"}
        for name in QP_FIELDS:
            val = np.asarray(getattr(qp, name))
            if name in colmajor:
                val = np.swapaxes(val, -1, -2)
            dtype = np.int32 if name in ("ng", "soft") else self.dtype
            with np.errstate(over="ignore"):  # junk like -1e300 in ignored entries becomes -inf in float
                self._view(getattr(c, name), dtype)[:] = val.astype(dtype).ravel()

    def set_arg(self, max_iter: int = 0, tol: float = 0.0, tol_infeas: float = 0.0, stop_after: int = -1,
                polish: int = -1) -> None:
        self.lib.qp_harness_arg(max_iter, tol, tol_infeas, stop_after, polish)

    def sol(self) -> Sol:
        c = self.lib.qp_harness_sol()
        N, NG = self.horizon, self.ng_max
        shapes = {"x": (N + 1, NX), "u": (N, NU), "s": (N + 1, NG), "pi": (N, NX), "lam_lbx": (N + 1, NX),
                  "lam_ubx": (N + 1, NX), "lam_lbu": (N, NU), "lam_ubu": (N, NU), "lam_lg": (N + 1, NG),
                  "lam_ls": (N + 1, NG)}
        return Sol(**{k: self._view(getattr(c, k), self.dtype).astype(np.float64).reshape(shapes[k])
                      for k in SOL_FIELDS})

    def write_sol(self, sol: Sol) -> None:
        c = self.lib.qp_harness_sol()
        for k in SOL_FIELDS:
            self._view(getattr(c, k), self.dtype)[:] = getattr(sol, k).astype(self.dtype).ravel()

    def solve(self, qp: QP, max_iter: int = 0, tol: float = 0.0, tol_infeas: float = 0.0,
              stop_after: int = -1, polish: int = -1, warm_start: int = 0, warm_mu: float = 0.0) -> Result:
        """Solve qp; option values 0 / -1 keep the defaults of ocp_qp_ipm_arg_set_default. warm_mu > 0:
        keep an iterate for the next solve; warm_start 1 / 2: start from the kept one, shifted or not."""
        self.load(qp)
        self.set_arg(max_iter, tol, tol_infeas, stop_after, polish)
        self.lib.qp_harness_warm(warm_start, warm_mu)
        status = self.lib.qp_harness_solve()
        return self.result(status)

    def solve_fallback(self, qp: QP, max_iter: int = 0, tol: float = 0.0) -> Result:
        """Solve qp with the fallback solver alone (the homogeneous embedding, ocp_qp_hsde.h)."""
        self.load(qp)
        self.set_arg(max_iter, tol)
        return self.result(self.lib.qp_harness_solve_fallback())

    @property
    def rows(self) -> int:
        """Soft rows a QP may hold (the row capacity the harness was built with)."""
        return int(self.lib.qp_harness_rows())

    def result(self, status: int) -> Result:
        it, polls, flags = (self.ffi.new("int *") for _ in range(3))
        res6 = np.zeros(6)
        scaled = np.zeros(3)
        mtk = np.zeros(3)
        st = self.lib.qp_harness_info(it, polls, flags, self.ffi.from_buffer("double[]", res6),
                                      self.ffi.from_buffer("double[]", scaled), self.ffi.from_buffer("double[]", mtk))
        assert st == status
        res = {k: float(v) for k, v in zip(RES_KEYS, res6, strict=True)}
        f = int(flags[0])
        return Result(status, int(it[0]), int(polls[0]), f & 1, (f >> 1) & 1, self.sol(), res,
                      (scaled[0], scaled[1], scaled[2]), (mtk[0], mtk[1], mtk[2]), (f >> 2) & 1)

    def res_compute(self) -> dict[str, float]:
        """ocp_qp_res_compute on the loaded problem and the current (possibly edited) solution."""
        res6 = np.zeros(6)
        self.lib.qp_harness_res(self.ffi.from_buffer("double[]", res6))
        return {k: float(v) for k, v in zip(RES_KEYS, res6, strict=True)}

    def check(self, qp: QP) -> int:
        self.load(qp)
        return int(self.lib.qp_harness_check())

    def status_message(self, status: int) -> str:
        return str(self.ffi.string(self.lib.qp_harness_status_message(status)).decode())

    def kkt_map(self, qp: QP) -> tuple[int, float, dict[str, list[int]]]:
        """(number of packed inequality rows, cost scale, per-stage offsets and counts, and the
        Riccati path of each stage: 0 general, 1 general with the position-free shortcut, 2 the
        integrators' kernel)."""
        self.load(qp)
        arrs = {k: self.ffi.new("int[]", self.horizon + 1) for k in ("off", "nb", "nr", "ns", "kernel")}
        m = self.ffi.new("int *")
        cs = self.ffi.new("double *")
        st = self.lib.qp_harness_kkt_map(m, arrs["off"], arrs["nb"], arrs["nr"], arrs["ns"], arrs["kernel"], cs)
        assert st == 0
        return int(m[0]), float(cs[0]), {k: list(v) for k, v in arrs.items()}

    def kkt_solve(self, qp: QP, w: Array, rhs: Array) -> tuple[int, Array]:
        """C solve of the Newton system with row weights w for rhs, both as flat ocp_qp_ipm_vec."""
        self.load(qp)
        wb = np.zeros(self.nc_max, dtype=self.dtype)
        wb[: len(w)] = w
        rb = np.ascontiguousarray(rhs, dtype=self.dtype)
        out = np.zeros(self.vec_len, dtype=self.dtype)
        rt = f"{self.real}[]"
        st = self.lib.qp_harness_kkt_solve(self.ffi.from_buffer(rt, wb), self.ffi.from_buffer(rt, rb),
                                           self.ffi.from_buffer(rt, out))
        return int(st), out.astype(np.float64)


# ------------------------------------------------------------------------------------------------
# Conic form (for Clarabel and for the dense Newton system), in the C solver's packing order
# ------------------------------------------------------------------------------------------------


@dataclass
class Conic:
    """minimise 1/2 v'Pv + c'v  s.t.  Aeq v = beq,  Ain v + t = bin, t >= 0."""

    P: Array
    c: Array
    Aeq: Array
    beq: Array
    Ain: Array
    bin: Array
    u_idx: list[list[int]]  # variable indices of u_n
    x_idx: list[list[int]]  # of x_n (empty for n = 0)
    s_idx: dict[tuple[int, int], int]  # (n, row i) -> index of s for soft rows
    vec_idx: list[int]  # position in the C ocp_qp_ipm_vec of each variable
    row_kind: list[tuple[str, int, int, int]]  # (kind, stage, component or row, sign)


def conic_form(qp: QP) -> Conic:
    N, NG = qp.horizon, qp.ng_max
    u_idx: list[list[int]] = []
    x_idx: list[list[int]] = []
    s_idx: dict[tuple[int, int], int] = {}
    vec_idx: list[int] = []
    soft_pos: dict[tuple[int, int], int] = {}  # (n, row i) -> packed general row k
    nv = 0
    for n in range(N + 1):
        u_idx.append(list(range(nv, nv + NU)) if n < N else [])
        if n < N:
            vec_idx += [n * NUX + j for j in range(NU)]
            nv += NU
        x_idx.append(list(range(nv, nv + NX)) if n > 0 else [])
        if n > 0:
            vec_idx += [n * NUX + NU + j for j in range(NX)]
            nv += NX
            k = 0
            for i in range(qp.ng[n]):
                if not present(qp.lg[n, i]):
                    continue
                if qp.soft[n, i]:
                    s_idx[(n, i)] = nv
                    soft_pos[(n, i)] = k
                    vec_idx.append((N + 1) * NUX + n * NG + k)
                    nv += 1
                k += 1
    P = np.zeros((nv, nv))
    c = np.zeros(nv)
    for n in range(N + 1):
        ui, xi = u_idx[n], x_idx[n]
        if n < N:
            P[np.ix_(ui, ui)] += qp.R[n]
            c[ui] += qp.r[n] + (qp.S[0] @ qp.x0 if n == 0 else 0.0)
        if n > 0:
            P[np.ix_(xi, xi)] += qp.Q[n]
            c[xi] += qp.q[n]
        if 0 < n < N:
            P[np.ix_(ui, xi)] += qp.S[n]
            P[np.ix_(xi, ui)] += qp.S[n].T
    for (n, i), j in s_idx.items():
        P[j, j] += qp.Zl[n, i]
        c[j] += qp.zl[n, i]
    Aeq = np.zeros((NX * N, nv))
    beq = np.zeros(NX * N)
    for n in range(N):
        rows = slice(NX * n, NX * n + NX)
        Aeq[rows, x_idx[n + 1]] = np.eye(NX)
        Aeq[rows, u_idx[n]] = -qp.B[n]
        if n == 0:
            beq[rows] = qp.b[0] + qp.A[0] @ qp.x0
        else:
            Aeq[rows, x_idx[n]] = -qp.A[n]
            beq[rows] = qp.b[n]
    rows_in: list[Array] = []
    b_in: list[float] = []
    kinds: list[tuple[str, int, int, int]] = []

    def add(coefs: list[tuple[int, float]], val: float, kind: tuple[str, int, int, int]) -> None:
        row = np.zeros(nv)
        for j, cf in coefs:
            row[j] += cf
        rows_in.append(row)
        b_in.append(val)
        kinds.append(kind)

    for n in range(N + 1):
        comps: list[tuple[int, float, float, str]] = []
        if n < N:
            comps += [(u_idx[n][j], qp.lbu[n, j], qp.ubu[n, j], "u") for j in range(NU)]
        if n > 0:
            comps += [(x_idx[n][j], qp.lbx[n, j], qp.ubx[n, j], "x") for j in range(NX)]
        for cidx, (var, lb, ub, kind) in enumerate(comps):
            comp = cidx if n < N else cidx + NU
            if present(lb):
                add([(var, -1.0)], -lb, ("l" + kind, n, comp, -1))
            if present(ub):
                add([(var, 1.0)], ub, ("u" + kind, n, comp, 1))
        if n == 0:
            continue
        px, py = x_idx[n][0], x_idx[n][1]
        live = [i for i in range(qp.ng[n]) if present(qp.lg[n, i])]
        for i in live:
            co = [(px, -qp.D[n, i, 0]), (py, -qp.D[n, i, 1])]
            if qp.soft[n, i]:
                co.append((s_idx[(n, i)], -1.0))
            add(co, -qp.lg[n, i], ("g", n, i, -1))
        for i in live:
            if qp.soft[n, i]:
                add([(s_idx[(n, i)], -1.0)], 0.0, ("s", n, i, -1))
    Ain = np.array(rows_in).reshape(-1, nv)
    return Conic(P, c, Aeq, beq, Ain, np.array(b_in), u_idx, x_idx, s_idx, vec_idx, kinds)


@dataclass
class RefSolution:
    status: str
    u: Array
    x: Array  # x_0 .. x_N
    s: Array  # (N+1, NG), zero for hard or absent rows
    iterations: int


def clarabel_solve(qp: QP, tol: float = 1e-12) -> RefSolution:
    import clarabel

    cf = conic_form(qp)
    A = sp.csc_matrix(np.vstack([cf.Aeq, cf.Ain]))
    b = np.concatenate([cf.beq, cf.bin])
    st = clarabel.DefaultSettings()
    st.verbose = False
    st.tol_gap_abs = tol
    st.tol_gap_rel = tol
    st.tol_feas = tol
    st.max_iter = 200
    cones = [clarabel.ZeroConeT(len(cf.beq)), clarabel.NonnegativeConeT(len(cf.bin))]
    solver = clarabel.DefaultSolver(sp.csc_matrix(np.triu(cf.P)), cf.c, A, b, cones, st)
    out = solver.solve()
    v = np.array(out.x)
    N, NG = qp.horizon, qp.ng_max
    u = np.array([v[cf.u_idx[n]] for n in range(N)])
    x = np.array([qp.x0] + [v[cf.x_idx[n]] for n in range(1, N + 1)])
    s = np.zeros((N + 1, NG))
    for (n, i), j in cf.s_idx.items():
        s[n, i] = v[j]
    return RefSolution(str(out.status), u, x, s, int(out.iterations))


# ------------------------------------------------------------------------------------------------
# Independent KKT check from the problem statement of ocp_qp_types.h and the conventions of ocp_qp.h
# ------------------------------------------------------------------------------------------------


def kkt_errors(qp: QP, sol: Sol) -> dict[str, float]:
    """Scaled KKT errors of sol: each residual divided by max(1, largest term that makes it up)."""
    N = qp.horizon
    x = sol.x.copy()
    x[0] = qp.x0
    err = {"stat": 0.0, "eq": 0.0, "ineq": 0.0, "comp": 0.0, "sign": 0.0, "absent": 0.0}

    def upd(key: str, res: Array | float, *terms: Array | float) -> None:
        scale = max([1.0] + [float(np.max(np.abs(t))) if np.size(t) else 0.0 for t in terms])
        err[key] = max(err[key], float(np.max(np.abs(res))) / scale)

    err["eq"] = float(np.max(np.abs(sol.x[0] - qp.x0)))
    for n in range(N):
        Ru, Sx, Bp = qp.R[n] @ sol.u[n], qp.S[n] @ x[n], qp.B[n].T @ sol.pi[n]
        upd("stat", Ru + Sx + qp.r[n] + Bp - sol.lam_lbu[n] + sol.lam_ubu[n], Ru, Sx, qp.r[n], Bp,
            sol.lam_lbu[n], sol.lam_ubu[n])
        Ax, Bu = qp.A[n] @ x[n], qp.B[n] @ sol.u[n]
        upd("eq", Ax + Bu + qp.b[n] - x[n + 1], Ax, Bu, qp.b[n], x[n + 1])
    for n in range(1, N + 1):
        Qx = qp.Q[n] @ x[n]
        terms = [Qx, qp.q[n], sol.pi[n - 1], sol.lam_lbx[n], sol.lam_ubx[n]]
        g = Qx + qp.q[n] - sol.pi[n - 1] - sol.lam_lbx[n] + sol.lam_ubx[n]
        if n < N:
            Su, Ap = qp.S[n].T @ sol.u[n], qp.A[n].T @ sol.pi[n]
            g = g + Su + Ap
            terms += [Su, Ap]
        for i in range(qp.ng[n]):
            if not present(qp.lg[n, i]):
                continue
            Dl = qp.D[n, i] * sol.lam_lg[n, i]
            g[:2] -= Dl
            terms.append(Dl)
            soft = bool(qp.soft[n, i])
            s = sol.s[n, i] if soft else 0.0
            row = qp.D[n, i] @ x[n, :2] + s - qp.lg[n, i]
            upd("ineq", max(-row, 0.0), qp.D[n, i] * x[n, :2], s, qp.lg[n, i])
            upd("comp", sol.lam_lg[n, i] * row, sol.lam_lg[n, i])
            err["sign"] = max(err["sign"], -sol.lam_lg[n, i])
            if soft:
                gs = qp.Zl[n, i] * s + qp.zl[n, i] - sol.lam_lg[n, i] - sol.lam_ls[n, i]
                upd("stat", gs, qp.Zl[n, i] * s, qp.zl[n, i], sol.lam_lg[n, i], sol.lam_ls[n, i])
                upd("ineq", max(-s, 0.0), s)
                upd("comp", sol.lam_ls[n, i] * s, sol.lam_ls[n, i])
                err["sign"] = max(err["sign"], -sol.lam_ls[n, i])
            else:
                err["absent"] = max(err["absent"], abs(sol.lam_ls[n, i]), abs(sol.s[n, i]))
        for i in range(qp.ng[n], qp.ng_max):
            err["absent"] = max(err["absent"], abs(sol.lam_lg[n, i]), abs(sol.lam_ls[n, i]), abs(sol.s[n, i]))
        upd("stat", g, *terms)
    for v, lb, ub, ll, lu in _bounded_components(qp, x, sol):
        for lo, lam, val in ((True, ll, lb), (False, lu, ub)):
            if present(val):
                gap = v - val if lo else val - v
                upd("ineq", max(-gap, 0.0), v, val)
                upd("comp", lam * gap, lam)
                err["sign"] = max(err["sign"], -lam)
            else:
                err["absent"] = max(err["absent"], abs(lam))
    return err


def _bounded_components(qp: QP, x: Array, sol: Sol) -> list[tuple[float, float, float, float, float]]:
    out = []
    for n in range(qp.horizon):
        for j in range(NU):
            out.append((sol.u[n, j], qp.lbu[n, j], qp.ubu[n, j], sol.lam_lbu[n, j], sol.lam_ubu[n, j]))
    for n in range(1, qp.horizon + 1):
        for j in range(NX):
            out.append((x[n, j], qp.lbx[n, j], qp.ubx[n, j], sol.lam_lbx[n, j], sol.lam_ubx[n, j]))
    return out


def certificate_errors(qp: QP, sol: Sol) -> tuple[float, float, float]:
    """For a Farkas certificate in sol (ocp_qp_ipm.h): (stationarity without cost terms, most negative
    multiplier, certificate value which must be 1)."""
    N = qp.horizon
    stat = 0.0
    value = 0.0
    for n in range(N):
        c = qp.b[n] + (qp.A[0] @ qp.x0 if n == 0 else 0.0)
        value += float(sol.pi[n] @ c)
        g = qp.B[n].T @ sol.pi[n] - sol.lam_lbu[n] + sol.lam_ubu[n]
        stat = max(stat, float(np.max(np.abs(g))))
    neg = 0.0
    for n in range(1, N + 1):
        g = -sol.pi[n - 1] - sol.lam_lbx[n] + sol.lam_ubx[n]
        if n < N:
            g = g + qp.A[n].T @ sol.pi[n]
        for i in range(qp.ng[n]):
            if not present(qp.lg[n, i]):
                continue
            g[:2] -= qp.D[n, i] * sol.lam_lg[n, i]
            value += qp.lg[n, i] * sol.lam_lg[n, i]
            neg = min(neg, sol.lam_lg[n, i], sol.lam_ls[n, i])
            if qp.soft[n, i]:
                stat = max(stat, abs(sol.lam_lg[n, i] + sol.lam_ls[n, i]))
        stat = max(stat, float(np.max(np.abs(g))))
    for n in range(N):
        for j in range(NU):
            value += _bound_value(qp.lbu[n, j], sol.lam_lbu[n, j]) - _bound_value(qp.ubu[n, j], sol.lam_ubu[n, j])
            neg = min(neg, sol.lam_lbu[n, j], sol.lam_ubu[n, j])
    for n in range(1, N + 1):
        for j in range(NX):
            value += _bound_value(qp.lbx[n, j], sol.lam_lbx[n, j]) - _bound_value(qp.ubx[n, j], sol.lam_ubx[n, j])
            neg = min(neg, sol.lam_lbx[n, j], sol.lam_ubx[n, j])
    return stat, -neg, value


def _bound_value(bound: float, lam: float) -> float:
    return float(bound * lam) if present(bound) else 0.0


# ------------------------------------------------------------------------------------------------
# Problem generators (numpy Generator driven; hypothesis draws the seed and the structure)
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Shape:
    """Structure of a random QP."""

    hessian: str = "pd"  # "pd" | "singular_q" (rank-deficient Q, R > 0) | "lp_like" (R = 0, low-rank Q)
    bound_density: float = 0.3
    soft_fraction: float = 0.5
    l1_only: bool = False  # soft rows with Zl = 0
    duplicate_rows: bool = False
    scale: float = 1.0  # magnitude of the linear cost terms (pulls the optimum onto bounds)
    # "general"; "position_free": A = [e_0 e_1 * *] on most stages; "integrators": that, and on most of
    # those stages rows 2 and 3 of [A B] those of two integrators (the robot's heading and speed). Each
    # is a path of the Riccati recursion (ocp_qp_kkt.c), and all that apply meet in one QP.
    dynamics: str = "general"


def empty_qp(N: int, NG: int) -> QP:
    return QP(
        A=np.zeros((N, NX, NX)), B=np.zeros((N, NX, NU)), b=np.zeros((N, NX)), Q=np.zeros((N + 1, NX, NX)),
        S=np.zeros((N, NU, NX)), R=np.zeros((N, NU, NU)), q=np.zeros((N + 1, NX)), r=np.zeros((N, NU)),
        x0=np.zeros(NX), lbx=np.full((N + 1, NX), -HM_INF), ubx=np.full((N + 1, NX), HM_INF),
        lbu=np.full((N, NU), -HM_INF), ubu=np.full((N, NU), HM_INF), ng=np.zeros(N + 1, dtype=np.int32),
        D=np.zeros((N + 1, NG, NPOS)), lg=np.zeros((N + 1, NG)), soft=np.zeros((N + 1, NG), dtype=np.int32),
        zl=np.zeros((N + 1, NG)), Zl=np.zeros((N + 1, NG)),
    )


def _psd(rng: np.random.Generator, n: int, rank: int, floor: float) -> Array:
    M = rng.standard_normal((n, rank))
    return M @ M.T / max(rank, 1) + floor * np.eye(n)


def random_qp(rng: np.random.Generator, N: int, NG: int, shape: Shape = Shape()) -> tuple[QP, Array, Array]:
    """A feasible QP with hard rows and bounds satisfied by a reference trajectory (returned as
    (qp, x_ref, u_ref)); soft rows are placed anywhere, often violated at the optimum."""
    qp = empty_qp(N, NG)
    qp.A[:] = np.eye(NX) + 0.3 * rng.standard_normal((N, NX, NX))
    qp.B[:] = 0.5 * rng.standard_normal((N, NX, NU))
    if shape.dynamics in ("position_free", "integrators"):
        # the position does not enter the dynamics (columns 0 and 1 unit vectors), except on a few
        # stages
        plain = rng.random(N) < 0.8
        qp.A[plain, :, 0] = np.eye(NX)[0]
        qp.A[plain, :, 1] = np.eye(NX)[1]
        if shape.dynamics == "integrators":
            # theta += B[2, 1] omega and v += B[3, 0] a, as the robot's
            integ = plain & (rng.random(N) < 0.8)
            qp.A[integ, 2, :] = np.eye(NX)[2]
            qp.A[integ, 3, :] = np.eye(NX)[3]
            qp.B[integ, 2, 0] = 0.0
            qp.B[integ, 3, 1] = 0.0
    elif shape.dynamics != "general":
        raise ValueError(f"unknown dynamics {shape.dynamics!r}")
    qp.b[:] = 0.1 * rng.standard_normal((N, NX))
    qp.x0[:] = rng.standard_normal(NX)
    qp.lbu[:] = -0.5 - rng.random((N, NU))
    qp.ubu[:] = 0.5 + rng.random((N, NU))
    if shape.hessian != "lp_like":
        drop = rng.random((N, NU)) > 0.7  # some inputs unbounded on one side or both
        qp.lbu[drop & (rng.random((N, NU)) < 0.5)] = -HM_INF
        qp.ubu[drop & (rng.random((N, NU)) < 0.5)] = HM_INF
    u_ref = rng.uniform(np.maximum(qp.lbu, -1.0), np.minimum(qp.ubu, 1.0))
    x_ref = np.zeros((N + 1, NX))
    x_ref[0] = qp.x0
    for n in range(N):
        x_ref[n + 1] = qp.A[n] @ x_ref[n] + qp.B[n] @ u_ref[n] + qp.b[n]
    for n in range(1, N + 1):
        for j in range(NX):
            if rng.random() < shape.bound_density:
                qp.lbx[n, j] = x_ref[n, j] - 0.5 * rng.random()
            if rng.random() < shape.bound_density:
                qp.ubx[n, j] = x_ref[n, j] + 0.5 * rng.random()
    for n in range(N + 1):
        if shape.hessian == "pd":
            H = _psd(rng, NUX, NUX, 0.05)
        elif shape.hessian == "singular_q":
            H = np.zeros((NUX, NUX))
            H[NU:, NU:] = _psd(rng, NX, int(rng.integers(0, NX)), 0.0)
            H[:NU, :NU] = _psd(rng, NU, NU, 0.1)
        else:
            H = np.zeros((NUX, NUX))
            H[NU:, NU:] = _psd(rng, NX, int(rng.integers(0, 2)), 0.0)
        qp.Q[n] = H[NU:, NU:]
        if n < N:
            qp.R[n] = H[:NU, :NU]
            qp.S[n] = H[:NU, NU:]
    qp.q[:] = shape.scale * rng.standard_normal((N + 1, NX))
    qp.r[:] = shape.scale * rng.standard_normal((N, NU))
    qp.ng[:] = rng.integers(0, NG + 1, N + 1)
    ang = rng.uniform(0, 2 * np.pi, (N + 1, NG))
    qp.D[:] = np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    for n in range(1, N + 1):
        for i in range(qp.ng[n]):
            val = qp.D[n, i] @ x_ref[n, :2]
            if rng.random() < shape.soft_fraction:
                qp.soft[n, i] = 1
                qp.lg[n, i] = val + rng.standard_normal()
                qp.zl[n, i] = 0.1 + 2.0 * rng.random()
                qp.Zl[n, i] = 0.0 if shape.l1_only or rng.random() < 0.3 else rng.random()
            else:
                qp.lg[n, i] = val - 0.3 * rng.random()
        if shape.duplicate_rows and qp.ng[n] >= 2:
            qp.D[n, 1], qp.lg[n, 1], qp.soft[n, 1] = qp.D[n, 0], qp.lg[n, 0], qp.soft[n, 0]
            qp.zl[n, 1], qp.Zl[n, 1] = qp.zl[n, 0], qp.Zl[n, 0]
    qp.ng[0] = int(rng.integers(0, NG + 1))  # stage-0 rows are ignored by definition
    _garbage_unused(rng, qp)
    return qp, x_ref, u_ref


def _garbage_unused(rng: np.random.Generator, qp: QP) -> None:
    """Fills every entry the problem statement ignores with junk (stage-0 state bounds and rows,
    rows i >= ng, soft data of hard rows): they must change nothing."""
    junk = lambda shape: rng.choice([np.nan, np.inf, -1e300, 7.0], size=shape)  # noqa: E731
    qp.lbx[0] = junk(NX)
    qp.ubx[0] = junk(NX)
    qp.D[0] = junk((qp.ng_max, NPOS))
    qp.lg[0] = junk(qp.ng_max)
    for n in range(qp.horizon + 1):
        for i in range(qp.ng_max):
            if n == 0 or i >= qp.ng[n]:
                qp.D[n, i] = junk(NPOS)
                qp.lg[n, i] = junk(1)[0]
                qp.soft[n, i] = int(rng.integers(-3, 3))
                qp.zl[n, i] = junk(1)[0]
                qp.Zl[n, i] = junk(1)[0]
            elif not qp.soft[n, i]:
                qp.zl[n, i] = junk(1)[0]
                qp.Zl[n, i] = junk(1)[0]


def reachable_box(qp: QP) -> tuple[Array, Array]:
    """Interval over-approximation of the states reachable under the input bounds (ignoring state
    bounds and rows): x_n in [lo[n], hi[n]]. Inputs must be bounded."""
    lo = np.zeros((qp.horizon + 1, NX))
    hi = np.zeros((qp.horizon + 1, NX))
    lo[0] = hi[0] = qp.x0
    for n in range(qp.horizon):
        cx, rx = (lo[n] + hi[n]) / 2, (hi[n] - lo[n]) / 2
        cu, ru = (qp.lbu[n] + qp.ubu[n]) / 2, (qp.ubu[n] - qp.lbu[n]) / 2
        c = qp.A[n] @ cx + qp.B[n] @ cu + qp.b[n]
        r = np.abs(qp.A[n]) @ rx + np.abs(qp.B[n]) @ ru
        lo[n + 1], hi[n + 1] = c - r, c + r
    return lo, hi


def make_infeasible(rng: np.random.Generator, qp: QP, kind: str) -> QP:
    """Copies qp and adds hard constraints that no trajectory can meet.

    rows: two hard rows at one stage with D' p >= a and -D' p >= -a + gap;
    unreachable_row: a hard row whose half-plane lies beyond every reachable position;
    unreachable_state: a state bound beyond the reachable interval (contradictory under dynamics)."""
    qp = qp.copy()
    N = qp.horizon
    qp.lbu[~present(qp.lbu)] = -1.0
    qp.ubu[~present(qp.ubu)] = 1.0
    n = int(rng.integers(1, N + 1))
    if kind == "rows":
        if qp.ng[n] < 2:
            _grow_rows(qp, n, 2)
        d = qp.D[n, 0]
        a = float(rng.standard_normal())
        qp.D[n, 1] = -d
        qp.lg[n, 0], qp.lg[n, 1] = a, -a + 0.1 + rng.random()
        qp.soft[n, :2] = 0
        return qp
    lo, hi = reachable_box(qp)
    if kind == "unreachable_row":
        if qp.ng[n] < 1:
            _grow_rows(qp, n, 1)
        d = qp.D[n, 0]
        reach = max(d[0] * px + d[1] * py for px in (lo[n, 0], hi[n, 0]) for py in (lo[n, 1], hi[n, 1]))
        qp.lg[n, 0] = reach + 0.1 + rng.random()
        qp.soft[n, 0] = 0
        return qp
    if kind == "unreachable_state":
        j = int(rng.integers(0, NX))
        if rng.random() < 0.5:
            qp.lbx[n, j] = hi[n, j] + 0.1 + rng.random()
            qp.ubx[n, j] = max(qp.ubx[n, j], qp.lbx[n, j] + 1.0) if present(qp.ubx[n, j]) else HM_INF
        else:
            qp.ubx[n, j] = lo[n, j] - 0.1 - rng.random()
            qp.lbx[n, j] = min(qp.lbx[n, j], qp.ubx[n, j] - 1.0) if present(qp.lbx[n, j]) else -HM_INF
        return qp
    raise ValueError(kind)


def _grow_rows(qp: QP, n: int, count: int) -> None:
    for i in range(qp.ng[n], count):
        qp.D[n, i] = (1.0, 0.0)
        qp.lg[n, i] = -1e3  # a loose hard row
        qp.soft[n, i] = 0
    qp.ng[n] = max(qp.ng[n], count)
