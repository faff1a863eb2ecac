"""Ipopt in C, against Debian's Ipopt: the optimal reference of the comparison.

``build_ipopt_reference(spec, build_dir)`` writes the reference NLP of the spec
(codegen/reference_nlp.py: the whole OCP as one NLP with the exact Hessian of the Lagrangian) as
CasADi-generated C, renders ``templates/ipopt_reference.c.j2`` into a small program
``<name>_ipopt`` and compiles it with its Makefile against Ipopt's C interface
(``IpStdCInterface.h``; Debian: ``apt-get install coinor-libipopt-dev libblas-dev liblapack-dev``).
The build folder is separate from the solver package, which stays free of Ipopt.

``IpoptReference.run(replay, warm=...)`` packs the replay's parameter vectors into the program's
binary input, runs it, and reads back per step: Ipopt's status, its iterations, the optimal
objective, the solve time (``clock_gettime`` around ``IpoptSolve``) and the trajectory.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...codegen import __version__
from ...codegen.reference_nlp import GeneratedNlp, ReferenceNlp, generate_c
from ...codegen.render import c_identifier, make_environment
from ...codegen.spec import Spec
from ..replay import Replay, ReplayError

FloatArray = NDArray[np.float64]

IPOPT_HEADER = "IpStdCInterface.h"
IPOPT_INCLUDE_DIRS = (Path("/usr/include/coin"), Path("/usr/include/coin-or"), Path("/usr/local/include/coin-or"))
APT_HINT = "apt-get install coinor-libipopt-dev libblas-dev liblapack-dev"

# Ipopt's ApplicationReturnStatus (IpReturnCodes_inc.h, the same in 3.11 and 3.14).
IPOPT_STATUS = {
    0: "Solve_Succeeded",
    1: "Solved_To_Acceptable_Level",
    2: "Infeasible_Problem_Detected",
    3: "Search_Direction_Becomes_Too_Small",
    4: "Diverging_Iterates",
    5: "User_Requested_Stop",
    6: "Feasible_Point_Found",
    -1: "Maximum_Iterations_Exceeded",
    -2: "Restoration_Failed",
    -3: "Error_In_Step_Computation",
    -4: "Maximum_CpuTime_Exceeded",
    -10: "Not_Enough_Degrees_Of_Freedom",
    -11: "Invalid_Problem_Definition",
    -12: "Invalid_Option",
    -13: "Invalid_Number_Detected",
    -100: "Unrecoverable_Exception",
    -101: "NonIpopt_Exception_Thrown",
    -102: "Insufficient_Memory",
    -199: "Internal_Error",
}
SUCCESS = (0, 1)


class IpoptUnavailableError(RuntimeError):
    """Ipopt's C interface (headers or library) is not installed; the message says what to install."""


class IpoptRunError(RuntimeError):
    """The Ipopt program could not run a replay (not an Ipopt failure: those are per-step statuses)."""


def status_name(status: int) -> str:
    return IPOPT_STATUS.get(int(status), f"unknown({int(status)})")


def find_ipopt() -> tuple[str, str]:
    """(cflags, libs) for Ipopt's C interface, or IpoptUnavailableError with what to install."""
    cflags = os.environ.get("IPOPT_CFLAGS")
    libs = os.environ.get("IPOPT_LIBS", "-lipopt")
    if cflags is None:
        for d in IPOPT_INCLUDE_DIRS:
            if (d / IPOPT_HEADER).is_file():
                cflags = f"-I{d} -DHAVE_CSTDDEF"
                break
    if cflags is None:
        raise IpoptUnavailableError(
            f"Ipopt's C interface ({IPOPT_HEADER}) was not found in {', '.join(map(str, IPOPT_INCLUDE_DIRS))}: "
            f"install it with `{APT_HINT}` (as root), or set IPOPT_CFLAGS and IPOPT_LIBS"
        )
    return cflags, libs


def ipopt_unavailable_reason() -> str | None:
    """None when the Ipopt reference can be built here, else why not (for pytest.skip / reports)."""
    try:
        find_ipopt()
    except IpoptUnavailableError as err:
        return str(err)
    if shutil.which(os.environ.get("CC", "cc").split()[0]) is None or shutil.which("make") is None:
        return "a C compiler (cc) and make are needed to build the Ipopt reference"
    return None


@dataclass
class IpoptRun:
    """Ipopt's results on every step of a replay."""

    warm: bool
    status: NDArray[np.int64]  # (T,) Ipopt's ApplicationReturnStatus
    iterations: NDArray[np.int64]  # (T,)
    cost: FloatArray  # (T,) optimal objective (NaN when Ipopt gave none)
    solve_ms: FloatArray  # (T,) IpoptSolve alone
    total_ms: FloatArray  # (T,) bounds + problem creation + options + IpoptSolve + release
    w: FloatArray  # (T, NW) the solutions (the last iterate where Ipopt failed)
    x: FloatArray  # (T, N+1, 4)
    u: FloatArray  # (T, N, 2)
    s: FloatArray  # (T, N) obstacle slacks

    @property
    def success(self) -> NDArray[np.bool_]:
        return np.isin(self.status, SUCCESS)

    @property
    def failures(self) -> int:
        return int(np.count_nonzero(~self.success))

    def status_names(self) -> list[str]:
        return [status_name(s) for s in self.status]


class IpoptReference:
    """A built ``<name>_ipopt`` program and the NLP it solves."""

    def __init__(self, spec: Spec, build_dir: Path, nlp: ReferenceNlp, program: Path) -> None:
        self.spec = spec
        self.build_dir = build_dir
        self.nlp = nlp
        self.program = program

    def pack(self, replay: Replay, path: Path) -> Path:
        """Write the program's input: the replay's parameter vectors, one per step."""
        if replay.spec_hash != self.spec.digest():
            raise ReplayError(f"the replay was recorded for spec {replay.spec_hash[:12]}, this Ipopt reference "
                              f"was built for {self.spec.digest()[:12]}")
        P = np.empty((replay.steps, self.nlp.n_param))
        for t in range(replay.steps):
            P[t] = self.nlp.params.pack(**replay.inputs(t), params=replay.params)
        with path.open("wb") as f:
            f.write(b"HMIPIN01")
            f.write(self.spec.digest().encode("ascii"))
            f.write(np.array([self.nlp.n_param, self.nlp.nw, replay.steps], dtype="<i4").tobytes())
            f.write(np.ascontiguousarray(P, dtype="<f8").tobytes())
        return path

    def run(self, replay: Replay, *, warm: bool = False, tol: float = 1e-8, max_iter: int = 3000,
            print_level: int = 0, timeout_s: float | None = None) -> IpoptRun:
        """Solve every step of the replay with Ipopt; cold starts, or shifted warm starts with ``warm``."""
        with tempfile.TemporaryDirectory(prefix="hm_ipopt_") as tmp:
            inp, out = Path(tmp) / "replay.bin", Path(tmp) / "results.bin"
            self.pack(replay, inp)
            cmd = [str(self.program), str(inp), str(out), "--tol", repr(float(tol)), "--max-iter", str(int(max_iter)),
                   "--print-level", str(int(print_level))]
            if warm:
                cmd.append("--warm")
            # Ipopt reads an ipopt.opt in its working directory: run in the empty temporary folder.
            proc = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True, check=False, timeout=timeout_s)
            if proc.returncode != 0:
                raise IpoptRunError(f"{self.program.name} failed (exit {proc.returncode}): "
                                    f"{(proc.stderr or proc.stdout).strip()[-2000:]}")
            return self._read(out, replay.steps, warm)

    def _read(self, path: Path, steps: int, warm: bool) -> IpoptRun:
        data = path.read_bytes()
        if data[:8] != b"HMIPOUT1":
            raise IpoptRunError(f"{path}: not the Ipopt program's output")
        nw, n_steps, w_flag = np.frombuffer(data[8:20], dtype="<i4")
        if nw != self.nlp.nw or n_steps != steps or bool(w_flag) != warm:
            raise IpoptRunError(f"{path}: header nw={nw} steps={n_steps} warm={w_flag} does not match the run")
        rec = np.dtype([("status", "<i4"), ("iterations", "<i4"), ("cost", "<f8"), ("solve_ms", "<f8"),
                        ("total_ms", "<f8"), ("w", "<f8", (int(nw),))])
        body = data[20:]
        if len(body) != rec.itemsize * steps:
            raise IpoptRunError(f"{path}: {len(body)} bytes of results, expected {rec.itemsize * steps}")
        r = np.frombuffer(body, dtype=rec, count=steps)
        w = np.array(r["w"]).reshape(steps, int(nw))
        X, U, S = self.nlp.decision.unpack(w)
        return IpoptRun(
            warm=warm, status=r["status"].astype(np.int64), iterations=r["iterations"].astype(np.int64),
            cost=r["cost"].astype(np.float64), solve_ms=r["solve_ms"].astype(np.float64),
            total_ms=r["total_ms"].astype(np.float64), w=w, x=X, u=U, s=S,
        )


def render_program(nlp: ReferenceNlp, gen: GeneratedNlp, name: str) -> dict[str, str]:
    """File name -> text of the C program and its Makefile."""
    env = make_environment()

    def ints(values: list[int]) -> str:
        return ", ".join(str(int(v)) for v in values)

    context = {
        "name": c_identifier(name), "prefix": c_identifier(gen.prefix), "version": __version__,
        "spec_hash": nlp.spec.digest(), "nw": gen.nw, "ng": gen.ng, "n_param": gen.n_param, "N": nlp.N,
        "u_offset": nlp.decision.u_offset, "s_offset": nlp.decision.s_offset,
        "nnz_jac": len(gen.jac_rows), "nnz_hess": len(gen.hess_rows),
        "jac_rows": ints(gen.jac_rows), "jac_cols": ints(gen.jac_cols),
        "hess_rows": ints(gen.hess_rows), "hess_cols": ints(gen.hess_cols),
        "sz_arg": gen.sz_arg, "sz_res": gen.sz_res, "sz_iw": gen.sz_iw, "sz_w": gen.sz_w,
    }
    return {
        f"{name}_ipopt.c": env.get_template("ipopt_reference.c.j2").render(**context),
        "Makefile": env.get_template("ipopt_reference.Makefile.j2").render(**context),
    }


def build_ipopt_reference(spec: Spec, build_dir: str | Path, *, force: bool = False,
                          cflags: str = "-O2") -> IpoptReference:
    """Generate and compile ``<name>_ipopt`` for ``spec`` into ``build_dir`` (reused when up to date)."""
    ipopt_cflags, ipopt_libs = find_ipopt()
    make = shutil.which("make")
    if make is None:
        raise IpoptUnavailableError("`make` was not found on PATH: install it (Debian: apt-get install make)")
    d = Path(build_dir).resolve()
    name = spec.name
    program = d / f"{name}_ipopt"
    stamp = d / "reference.json"
    nlp = ReferenceNlp(spec)
    want = {"generator_version": __version__, "spec_hash": spec.digest(), "cflags": cflags}
    if not force and program.is_file() and stamp.is_file():
        try:
            if json.loads(stamp.read_text()) == want:
                return IpoptReference(spec, d, nlp, program)
        except json.JSONDecodeError:
            pass
    d.mkdir(parents=True, exist_ok=True)
    for old in (program, stamp):
        old.unlink(missing_ok=True)
    gen = generate_c(nlp, f"{name}_nlp", d)
    for filename, text in render_program(nlp, gen, name).items():
        (d / filename).write_text(text)
    env = dict(os.environ, CFLAGS=cflags, IPOPT_CFLAGS=ipopt_cflags, IPOPT_LIBS=ipopt_libs)
    proc = subprocess.run([make, "-C", str(d), "--no-print-directory", "all"], env=env, capture_output=True,
                          text=True, check=False)
    if proc.returncode != 0:
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-30:])
        if "IpStdCInterface.h" in tail or "-lipopt" in tail or "cannot find" in tail:
            raise IpoptUnavailableError(f"building {program.name} against Ipopt failed; install it with `{APT_HINT}`:\n"
                                   f"{tail}")
        raise IpoptRunError(f"building {program.name} failed (make exit {proc.returncode}):\n{tail}")
    stamp.write_text(json.dumps(want))
    return IpoptReference(spec, d, nlp, program)
