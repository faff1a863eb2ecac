"""The solver object of a loaded package: real-time iteration, full SQP and runtime parameters.

The binding is deliberately thin: the C input and output structs are allocated once per solver,
numpy arrays view the input's fields, and a step copies the caller's arrays into those views, makes
one C call and copies the output struct in one piece (a structured numpy record whose fields
StepResult reads on access). No cffi object is created per call; measured on the development
machine: 1.5 us to load the inputs, 0.4 us for the result in a tight loop, 4.4 us in all per step in
the bench's closed loop (where the solver's data have pushed Python's out of the caches).
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .codegen.params import Param
from .controller import Controller
from .results import StepResult, c_array_view, record_dtype
from .runtime_params import RuntimeParams
from .status import StatusEnums
from .steplog import StepLog


def implied_velocities(humans_pred: np.ndarray, dt: float) -> np.ndarray:
    """(k, 2) velocities [vx, vy] m/s that predictions (N+1, k, 2) imply over their first interval: what
    a caller without the people's velocities hands the solver (a constant-velocity prediction's own)."""
    return np.asarray((humans_pred[1] - humans_pred[0]) / dt, dtype=np.float64)


class Solver:
    """A generated solver, loaded with ``humanmpc.load(DIR)``."""

    def __init__(self, name: str, dims: Any, ffi: Any, lib: Any, model: Any, path: Any, spec_hash: str,
                 params_table: tuple[Param, ...]) -> None:
        self.name = name
        self.dims = dims
        self.model = model
        self.path = path
        self.spec_hash = spec_hash
        self.statuses: StatusEnums | None = None  # the package's status enums (humanmpc.load sets them)
        self._ffi = ffi
        self._lib = lib
        fn = lambda suffix: getattr(lib, f"{name}_{suffix}")  # noqa: E731
        self._c_step = fn("solver_step")
        self._c_prepare = fn("solver_prepare")
        self._c_feedback = fn("solver_feedback")
        self._c_solve = fn("solver_solve")
        self._c_reset = fn("solver_reset")
        self._status_message = fn("status_message")
        self._qp_status_message = fn("qp_status_message")
        self._stop_reason_message = fn("stop_reason_message")
        self._mem = ffi.new("char[]", int(fn("solver_memsize")()))
        self._solver = fn("solver_create")(self._mem)
        self._params = fn("solver_params")(self._solver)
        self._in = ffi.new(f"{name}_input *")
        self._out = ffi.new(f"{name}_output *")
        N, nh_alloc = dims.N, max(1, dims.nh)
        # The C arrays hold the solver's real type; inputs are rounded to it on assignment, results
        # are handed out as float64 copies either way.
        self.dtype = np.dtype(np.float32 if ffi.sizeof(f"{name}_real") == 4 else np.float64)
        rt = self.dtype
        self._x0 = c_array_view(ffi, self._in.x0, (4,), rt)
        self._goal = c_array_view(ffi, self._in.goal, (4,), rt)
        self._refs = c_array_view(ffi, self._in.refs, (N + 1, 4), rt)
        self._has_refs = False   # what _in.has_refs holds
        self._obstacle = c_array_view(ffi, self._in.obstacle, (2,), rt)
        self._nh, self._nodes = dims.nh, N + 1
        self._counts = (0, False)   # what _in.n_humans, _in.has_obstacle hold (ffi.new zeroes them)
        # the first k humans' rows, for every k, as views made once
        h_now = c_array_view(ffi, self._in.humans_now, (nh_alloc, 2), rt)
        h_vel = c_array_view(ffi, self._in.humans_vel, (nh_alloc, 2), rt)
        h_pred = c_array_view(ffi, self._in.humans_pred, (N + 1, nh_alloc, 2), rt)
        self._dt = float(dims.dt)
        self._h_now_first = [h_now[:k] for k in range(nh_alloc + 1)]
        self._h_vel_first = [h_vel[:k] for k in range(nh_alloc + 1)]
        self._h_pred_first = [h_pred[:, :k] for k in range(nh_alloc + 1)]
        self._out_buffer = ffi.buffer(self._out)
        self._out_dtype = record_dtype(ffi, f"{name}_output")
        self.log: StepLog | None = None
        # One solver, one step at a time: cffi releases the GIL in C, and two threads stepping the
        # same solver memory crashed. Callers from several threads are serialised.
        self._lock = threading.Lock()
        self._table = params_table
        self._table_names = {p.name for p in params_table}
        # the solver's parameters; the controller's own are its (Solver.controller())
        self._runtime_params = RuntimeParams(
            ffi, lib, ((f"{name}_params", self._params, [p for p in params_table if not p.controller]),), self._lock)

    def start_log(self, capacity: int = 10000) -> StepLog:
        """Keep the newest `capacity` steps (status, stop reason, timings, closest human) in self.log."""
        self.log = StepLog(capacity)
        return self.log

    # -- inputs -------------------------------------------------------------------------------
    def _load_inputs(self, x0: ArrayLike, goal: ArrayLike, humans_now: ArrayLike | None,
                     humans_pred: ArrayLike | None, obstacle: ArrayLike | None,
                     humans_vel: ArrayLike | None = None) -> None:
        nh = self._nh
        x0a = np.asarray(x0, dtype=np.float64)
        if x0a.shape != (4,):
            raise ValueError(f"x0 must have shape (4,) = [px, py, theta, v], got {x0a.shape}")
        ga = np.asarray(goal, dtype=np.float64)
        if ga.shape not in ((4,), (self._nodes, 4)):
            raise ValueError(f"goal must have shape (4,) = [gx, gy, gtheta, v_ref], or (N+1, 4) = ({self._nodes}, 4) "
                             f"for a goal per node, got {ga.shape}")
        if humans_now is None:
            now = np.zeros((0, 2))
        else:
            now = np.asarray(humans_now, dtype=np.float64)
            if now.ndim != 2 or now.shape[1] != 2:
                raise ValueError(f"humans_now must have shape (k, 2), got {now.shape}")
        k = now.shape[0]
        if k > nh:
            raise ValueError(f"{k} humans given but this solver handles at most N_h = {nh}")
        if humans_pred is None:
            if k:
                raise ValueError("humans_pred is required when humans_now holds humans: shape (N+1, k, 2)")
            pred = np.zeros((self._nodes, 0, 2))
        else:
            pred = np.asarray(humans_pred, dtype=np.float64)
            if pred.shape != (self._nodes, k, 2):
                raise ValueError(f"humans_pred must have shape (N+1, k, 2) = ({self._nodes}, {k}, 2), got {pred.shape}")
        if humans_vel is None:
            vel = implied_velocities(pred, self._dt)
        else:
            vel = np.asarray(humans_vel, dtype=np.float64)
            if vel.shape != (k, 2):
                raise ValueError(f"humans_vel must have shape (k, 2) = ({k}, 2) [vx, vy] m/s, one row per person of "
                                 f"humans_now, got {vel.shape}")
        has_obstacle = obstacle is not None
        if has_obstacle:
            oa = np.asarray(obstacle, dtype=np.float64)
            if oa.shape != (2,):
                raise ValueError(f"obstacle must have shape (2,) = [ox, oy] or be None, got {oa.shape}")
            self._obstacle[...] = oa
        # whole-view assignments ([...]): a slice index costs numpy as much again as the copy
        self._x0[...] = x0a
        per_node = ga.ndim == 2
        if per_node:
            self._refs[...] = ga
            self._goal[...] = ga[-1]
        else:
            self._goal[...] = ga
        if per_node != self._has_refs:
            self._in.has_refs = int(per_node)
            self._has_refs = per_node
        self._h_now_first[k][...] = now
        self._h_vel_first[k][...] = vel
        self._h_pred_first[k][...] = pred
        # the counts only when they change: a cffi attribute store costs as much as an array copy
        if (k, has_obstacle) != self._counts:
            self._in.n_humans = k
            self._in.has_obstacle = int(has_obstacle)
            self._counts = (k, has_obstacle)

    def _result(self) -> StepResult:
        # a 0-d record over a bytes copy of the struct (cheaper to make than np.frombuffer(...)[0])
        r = StepResult(np.ndarray((), self._out_dtype, self._out_buffer[:]))
        if self.log is not None:
            self.log.append(r)
        return r

    # -- solving ------------------------------------------------------------------------------
    def step(self, x0: ArrayLike, goal: ArrayLike, humans_now: ArrayLike | None = None,
             humans_pred: ArrayLike | None = None, obstacle: ArrayLike | None = None, *,
             humans_vel: ArrayLike | None = None) -> StepResult:
        """One real-time iteration: preparation around the shifted previous plan, then feedback.

        goal: (4,) [gx, gy, gtheta, v_ref] for every node, or (N+1, 4) a goal per node (the progress
        objective's references along a path); humans_now: (k, 2) current positions, k <= N_h;
        humans_pred: (N+1, k, 2) predicted positions at the nodes (the collision potential);
        obstacle: (2,) closest obstacle point or None; humans_vel: (k, 2) the people's velocities
        [vx, vy] m/s now (speed and separation: the OCP's speed bounds and the command's check). Without
        humans_vel, the velocities the predictions imply over their first interval,
        (humans_pred[1] - humans_pred[0]) / dt: a constant-velocity prediction's own.
        """
        with self._lock:
            self._load_inputs(x0, goal, humans_now, humans_pred, obstacle, humans_vel)
            self._c_step(self._solver, self._in, self._out)
            return self._result()

    def prepare(self, goal: ArrayLike, humans_now: ArrayLike | None = None, humans_pred: ArrayLike | None = None,
                obstacle: ArrayLike | None = None, x0_guess: ArrayLike | None = None, *,
                humans_vel: ArrayLike | None = None) -> None:
        """The preparation phase alone (before the measurement): x0_guess is used only on a cold start;
        the people as for ``step``."""
        with self._lock:
            guess = self._x0.copy() if x0_guess is None else x0_guess
            self._load_inputs(guess, goal, humans_now, humans_pred, obstacle, humans_vel)
            self._c_prepare(self._solver, self._in)

    def feedback(self, x0: ArrayLike) -> StepResult:
        """The feedback phase: insert the measured state into the prepared QP and solve it."""
        x0a = np.asarray(x0, dtype=np.float64)
        if x0a.shape != (4,):
            raise ValueError(f"x0 must have shape (4,) = [px, py, theta, v], got {x0a.shape}")
        with self._lock:
            self._x0[...] = x0a
            self._c_feedback(self._solver, self._in, self._out)
            return self._result()

    def solve(self, x0: ArrayLike, goal: ArrayLike, humans_now: ArrayLike | None = None,
              humans_pred: ArrayLike | None = None, obstacle: ArrayLike | None = None, *,
              max_iter: int = 100, tol: float = 1e-8, humans_vel: ArrayLike | None = None) -> StepResult:
        """Full SQP to the KKT tolerance, from the current plan (after reset(): a cold start), under the
        monitors of ``step``: the deadline (``deadline_ms``: raise it for a reference solve), every QP
        solved (one stopped at its iteration limit ends the SQP in a stop, reason qp_failed), the clock,
        C1 / C2 and the command guard. The people as for ``step``."""
        if max_iter < 1:
            raise ValueError(f"max_iter must be >= 1, got {max_iter}")
        if not (math.isfinite(tol) and tol > 0):
            raise ValueError(f"tol must be a positive finite number, got {tol}")
        with self._lock:
            self._load_inputs(x0, goal, humans_now, humans_pred, obstacle, humans_vel)
            self._c_solve(self._solver, self._in, self._out, int(max_iter), float(tol))
            return self._result()

    def reset(self) -> None:
        """Forget the previous plan: the next step starts cold. Parameters are kept."""
        with self._lock:
            self._c_reset(self._solver)

    # -- parameters ---------------------------------------------------------------------------
    @property
    def params(self) -> dict[str, Any]:
        """The solver's runtime parameters now in force (``<name>_params``; the controller's own are
        ``controller().params``)."""
        return self._runtime_params.values

    def set_params(self, **values: Any) -> None:
        """Change runtime parameters, e.g. set_params(q=3.0, w_goal=[1, 1, 0, 100]).

        Every value is checked against its row of the parameter table (type, size, range: the rules of
        the spec and of the C check, named in the same words) before any is written; a ValueError
        lists every value that breaks its rule (a KeyError names unknown parameters), and nothing is
        changed. The controller's own parameters (``v_ref``, ``goal_tolerance``, ...) are set on a
        controller: ``controller().set_params``.
        """
        own = [key for key in values if key in self._table_names and key not in self._runtime_params.rows]
        if own:
            raise KeyError(f"{', '.join(repr(k) for k in own)}: a parameter of the controller, not of the solver "
                           f"(the solver does not read it): set it on the controller, solver.controller().set_params")
        self._runtime_params.set(**values)

    def controller(self) -> Controller:
        """A new navigation controller over this package's library (its own solver memory and
        parameters, the spec's defaults): ``humanmpc.load(DIR).controller()``."""
        return Controller(self.name, self.dims, self._ffi, self._lib, self._table)

    def status_message(self, status: int) -> str:
        return str(self._ffi.string(self._status_message(status)).decode())

    def stop_reason_message(self, reason: int) -> str:
        return str(self._ffi.string(self._stop_reason_message(reason)).decode())

    def qp_status_message(self, status: int) -> str:
        return str(self._ffi.string(self._qp_status_message(status)).decode())

    def __repr__(self) -> str:
        d = self.dims
        return f"<humanmpc.Solver {self.name!r} N={d.N} nh={d.nh} dt={d.dt:g} from {self.path}>"
