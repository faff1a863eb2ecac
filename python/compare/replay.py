"""Replays: the inputs of every step of a closed loop, fed again to any number of solvers.

A :class:`Replay` holds, per control step t, everything one solver step needs: the measured state
``x0``, the goal, the humans (current positions and predictions, padded to N_h, with the number
actually present) and the closest obstacle point (or none). Every solver of a comparison gets the
same inputs in the same order, each keeping its own warm start between steps, so their plans and
times are comparable step by step.

Files are ``.npz`` (numpy only, so the acados peer, which runs under another interpreter, reads
them too): the arrays below plus ``meta``, a JSON string with the sizes, the spec (resolved, with
its sha256), the problem parameters, the scenario and the seed. ``Replay.load`` checks all of it.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..codegen.reference_nlp import PROBLEM_PARAMS, ReferenceNlp, check_problem_params, problem_params
from ..codegen.spec import Spec, SpecError, resolve_spec

FloatArray = NDArray[np.float64]

FORMAT = "humanmpc-replay"
VERSION = 1
ARRAYS = ("x0", "goal", "n_humans", "humans_now", "humans_pred", "has_obstacle", "obstacle")


class ReplayError(ValueError):
    """A replay that cannot be used; the message says what is wrong and where."""


def _plain_params(params: Mapping[str, Any]) -> dict[str, float | list[float]]:
    arrays = check_problem_params(params)
    return {k: (float(v[0]) if size == 1 else [float(a) for a in v]) for (k, size), v in
            ((item, arrays[item[0]]) for item in PROBLEM_PARAMS)}


@dataclass
class Replay:
    """The inputs of T solver steps (arrays over t = 0..T-1) and what they were recorded with."""

    x0: FloatArray  # (T, 4) measured state [px, py, theta, v]
    goal: FloatArray  # (T, 4) [gx, gy, gtheta, v_ref]
    n_humans: NDArray[np.int64]  # (T,) humans present, <= NH
    humans_now: FloatArray  # (T, NH, 2) current positions, rows >= n_humans are padding (zeros)
    humans_pred: FloatArray  # (T, N+1, NH, 2) predictions at the nodes, padded the same way
    has_obstacle: NDArray[np.bool_]  # (T,)
    obstacle: FloatArray  # (T, 2) closest obstacle point (zeros when there is none)
    N: int
    dt: float
    NH: int
    spec: dict[str, Any]  # the resolved spec (Spec.to_dict())
    params: dict[str, Any] = field(default_factory=dict)  # the problem parameters in force
    scenario: str = ""
    seed: int = -1

    def __post_init__(self) -> None:
        if not self.params:
            self.params = _plain_params(problem_params(self.resolved_spec()))
        self.validate()

    # -- properties -------------------------------------------------------------------------
    @property
    def steps(self) -> int:
        return int(self.x0.shape[0])

    def __len__(self) -> int:
        return self.steps

    @property
    def spec_hash(self) -> str:
        return self.resolved_spec().digest()

    def resolved_spec(self) -> Spec:
        try:
            return resolve_spec(self.spec, "replay spec")
        except SpecError as err:
            raise ReplayError(f"the replay's spec is not valid: {err}") from None

    # -- checks -----------------------------------------------------------------------------
    def validate(self) -> None:
        """Raise ReplayError listing every shape, size or value that is wrong."""
        problems: list[str] = []
        T, N, NH = self.steps, self.N, self.NH
        expected = {
            "x0": (T, 4), "goal": (T, 4), "n_humans": (T,), "humans_now": (T, NH, 2),
            "humans_pred": (T, N + 1, NH, 2), "has_obstacle": (T,), "obstacle": (T, 2),
        }
        for key, shape in expected.items():
            arr = np.asarray(getattr(self, key))
            if arr.shape != shape:
                problems.append(f"{key}: shape {arr.shape}, expected {shape} (T={T}, N={N}, NH={NH})")
            elif arr.dtype.kind == "f" and not np.all(np.isfinite(arr)):
                bad = np.argwhere(~np.isfinite(arr.reshape(T, -1)).all(axis=1)).ravel()
                problems.append(f"{key}: non-finite values at step(s) {bad[:10].tolist()}")
        if not problems:
            n = np.asarray(self.n_humans)
            if np.any(n < 0) or np.any(n > NH):
                bad = np.argwhere((n < 0) | (n > NH)).ravel()
                problems.append(f"n_humans: must be in [0, NH={NH}], wrong at step(s) {bad[:10].tolist()}")
        if not (isinstance(self.N, (int, np.integer)) and self.N >= 1):
            problems.append(f"N: {self.N!r} must be a positive integer")
        if not (math.isfinite(self.dt) and self.dt > 0):
            problems.append(f"dt: {self.dt!r} must be a positive number")
        try:
            spec = self.resolved_spec()
        except ReplayError as err:
            problems.append(str(err))
        else:
            if spec.horizon.N != self.N or abs(spec.dt - self.dt) > 1e-12 or spec.humans.max != self.NH:
                problems.append(f"sizes N={self.N}, dt={self.dt}, NH={self.NH} do not match the spec's "
                                f"N={spec.horizon.N}, dt={spec.dt}, N_h={spec.humans.max}")
        try:
            check_problem_params(self.params)
        except ValueError as err:
            problems.append(str(err))
        if problems:
            raise ReplayError("invalid replay:\n  - " + "\n  - ".join(problems))

    # -- per step ---------------------------------------------------------------------------
    def inputs(self, t: int) -> dict[str, Any]:
        """Keyword arguments of ``solver.step(x0, goal, humans_now, humans_pred, obstacle)`` at step t."""
        if not -self.steps <= t < self.steps:
            raise IndexError(f"step {t} is outside the replay's {self.steps} steps")
        k = int(self.n_humans[t])
        return {
            "x0": self.x0[t].copy(),
            "goal": self.goal[t].copy(),
            "humans_now": self.humans_now[t, :k].copy(),
            "humans_pred": self.humans_pred[t, :, :k].copy(),
            "obstacle": self.obstacle[t].copy() if self.has_obstacle[t] else None,
        }

    def meta(self) -> dict[str, Any]:
        return {
            "format": FORMAT, "version": VERSION, "steps": self.steps, "N": int(self.N), "dt": float(self.dt),
            "NH": int(self.NH), "spec_hash": self.spec_hash, "spec": self.spec, "params": self.params,
            "scenario": self.scenario, "seed": int(self.seed),
        }

    # -- files ------------------------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        p = Path(path)
        if p.suffix != ".npz":
            raise ReplayError(f"{p}: a replay file must end in .npz")
        p.parent.mkdir(parents=True, exist_ok=True)
        arrays: dict[str, Any] = {k: np.asarray(getattr(self, k)) for k in ARRAYS}
        arrays["meta"] = np.array(json.dumps(self.meta()))
        np.savez_compressed(p, **arrays)
        return p

    @classmethod
    def load(cls, path: str | Path) -> Replay:
        p = Path(path)
        if not p.is_file():
            raise ReplayError(f"{p}: no such replay file")
        try:
            data = np.load(p, allow_pickle=False)
        except (OSError, ValueError) as err:
            raise ReplayError(f"{p}: not a readable .npz file ({err})") from None
        with data:
            missing = [k for k in ("meta", *ARRAYS) if k not in data.files]
            if missing:
                raise ReplayError(f"{p}: not a humanmpc replay: missing {', '.join(missing)}")
            try:
                meta = json.loads(str(data["meta"]))
            except json.JSONDecodeError as err:
                raise ReplayError(f"{p}: its metadata is not valid JSON ({err})") from None
            if meta.get("format") != FORMAT:
                raise ReplayError(f"{p}: not a humanmpc replay (format {meta.get('format')!r})")
            if meta.get("version") != VERSION:
                raise ReplayError(f"{p}: replay format version {meta.get('version')!r}; this humanmpc reads {VERSION}")
            arrays = {k: data[k] for k in ARRAYS}
        try:
            replay = cls(
                x0=arrays["x0"].astype(np.float64), goal=arrays["goal"].astype(np.float64),
                n_humans=arrays["n_humans"].astype(np.int64), humans_now=arrays["humans_now"].astype(np.float64),
                humans_pred=arrays["humans_pred"].astype(np.float64),
                has_obstacle=arrays["has_obstacle"].astype(bool), obstacle=arrays["obstacle"].astype(np.float64),
                N=int(meta["N"]), dt=float(meta["dt"]), NH=int(meta["NH"]), spec=meta["spec"],
                params=meta["params"], scenario=str(meta.get("scenario", "")), seed=int(meta.get("seed", -1)),
            )
        except KeyError as err:
            raise ReplayError(f"{p}: metadata lacks {err}") from None
        except ReplayError as err:
            raise ReplayError(f"{p}: {err}") from None
        if replay.spec_hash != meta.get("spec_hash"):
            raise ReplayError(f"{p}: the stored spec hashes to {replay.spec_hash[:12]}, the metadata says "
                              f"{str(meta.get('spec_hash'))[:12]}: the file was altered")
        return replay

    # -- building ---------------------------------------------------------------------------
    @classmethod
    def from_steps(cls, steps: Iterable[Mapping[str, Any] | Any], spec: Spec, *, scenario: str = "",
                   seed: int = -1, params: Mapping[str, Any] | None = None) -> Replay:
        """A replay from per-step inputs, in order.

        Each step is a mapping (or an object with attributes, e.g. a planner Observation) with
        ``x0`` (or ``x``), ``goal``, ``humans_now`` (k, 2), ``humans_pred`` (N+1, k, 2) and
        ``obstacle`` ((2,) or None). ``params`` overrides the spec's problem parameters.
        """
        N, NH = spec.horizon.N, spec.humans.max
        rows: dict[str, list[Any]] = {k: [] for k in ARRAYS}
        for t, step in enumerate(steps):
            def get(key: str, step: Any = step) -> Any:
                if isinstance(step, Mapping):
                    return step[key] if key in step else step.get("x") if key == "x0" else None
                return getattr(step, key, getattr(step, "x", None) if key == "x0" else None)

            x0, goal = get("x0"), get("goal")
            if x0 is None or goal is None:
                raise ReplayError(f"step {t}: needs x0 (or x) and goal")
            now = np.zeros((0, 2)) if get("humans_now") is None else np.asarray(get("humans_now"), dtype=np.float64)
            if now.ndim != 2 or now.shape[1] != 2:
                raise ReplayError(f"step {t}: humans_now must have shape (k, 2), got {now.shape}")
            k = now.shape[0]
            if k > NH:
                raise ReplayError(f"step {t}: {k} humans, but the spec handles at most N_h = {NH}")
            pred_in = get("humans_pred")
            pred = np.zeros((N + 1, 0, 2)) if pred_in is None else np.asarray(pred_in, dtype=np.float64)
            if pred.shape != (N + 1, k, 2):
                raise ReplayError(f"step {t}: humans_pred must have shape (N+1, k, 2) = ({N + 1}, {k}, 2), "
                                  f"got {pred.shape}")
            hn = np.zeros((NH, 2))
            hn[:k] = now
            hp = np.zeros((N + 1, NH, 2))
            hp[:, :k] = pred
            obs = get("obstacle")
            rows["x0"].append(np.asarray(x0, dtype=np.float64).reshape(4))
            rows["goal"].append(np.asarray(goal, dtype=np.float64).reshape(4))
            rows["n_humans"].append(k)
            rows["humans_now"].append(hn)
            rows["humans_pred"].append(hp)
            rows["has_obstacle"].append(obs is not None)
            rows["obstacle"].append(np.zeros(2) if obs is None else np.asarray(obs, dtype=np.float64).reshape(2))
        T = len(rows["x0"])
        shapes = {"x0": (4,), "goal": (4,), "n_humans": (), "humans_now": (NH, 2), "humans_pred": (N + 1, NH, 2),
                  "has_obstacle": (), "obstacle": (2,)}
        arrays = {k: np.array(v).reshape(T, *shapes[k]) for k, v in rows.items()}
        return cls(
            x0=arrays["x0"], goal=arrays["goal"], n_humans=arrays["n_humans"].astype(np.int64),
            humans_now=arrays["humans_now"], humans_pred=arrays["humans_pred"],
            has_obstacle=arrays["has_obstacle"].astype(bool), obstacle=arrays["obstacle"],
            N=N, dt=spec.dt, NH=NH, spec=spec.to_dict(),
            params=_plain_params(params if params is not None else problem_params(spec)),
            scenario=scenario, seed=seed,
        )


# ----------------------------------------------------------------------------------------------
# Feeding a replay to a solver
# ----------------------------------------------------------------------------------------------


@dataclass
class ReplayRun:
    """What one solver did on every step of a replay."""

    solver: str
    x: FloatArray  # (T, N+1, 4) plans
    u: FloatArray  # (T, N, 2)
    status: NDArray[np.int64]  # (T,) the solver's own status (0: success)
    qp_iterations: NDArray[np.int64]  # (T,) -1 where the solver does not say
    time_ms: FloatArray  # (T,) the solver's own step time (its timer), or the wall time
    wall_ms: FloatArray  # (T,) wall time of the call, measured around it
    results: list[Any] = field(default_factory=list)  # the solver's result objects, when kept

    @property
    def failures(self) -> int:
        return int(np.count_nonzero(self.status != 0))


def replay_solver(solver: Any, replay: Replay, *, name: str | None = None, reset: bool = True,
                  apply_params: bool = True, keep_results: bool = False) -> ReplayRun:
    """Feed every step of ``replay`` to ``solver.step(**replay.inputs(t))``, in order.

    ``solver`` is anything with ``step(x0, goal, humans_now, humans_pred, obstacle)`` returning an
    object with ``x`` (N+1, 4), ``u`` (N, 2) and ``status``, and optionally ``qp_iterations`` and
    ``time_total_ms`` (humanmpc's ``StepResult`` has all of them). The solver keeps its own warm
    start from step to step; ``reset`` calls ``solver.reset()`` first, and ``apply_params`` gives a
    solver with ``set_params`` the replay's problem parameters so that all solve the same problem.
    """
    dims = getattr(solver, "dims", None)
    if dims is not None:
        if int(dims.N) != replay.N or abs(float(dims.dt) - replay.dt) > 1e-12:
            raise ReplayError(f"the solver has N={dims.N}, dt={dims.dt}; the replay N={replay.N}, dt={replay.dt}")
        if int(dims.nh) < int(np.max(replay.n_humans, initial=0)):
            raise ReplayError(f"the replay has up to {int(np.max(replay.n_humans))} humans, the solver handles "
                              f"N_h = {dims.nh}")
    if reset and hasattr(solver, "reset"):
        solver.reset()
    if apply_params and hasattr(solver, "set_params"):
        solver.set_params(**replay.params)
    T, N = replay.steps, replay.N
    x = np.full((T, N + 1, 4), np.nan)
    u = np.full((T, N, 2), np.nan)
    status = np.zeros(T, dtype=np.int64)
    qp_it = np.full(T, -1, dtype=np.int64)
    time_ms = np.zeros(T)
    wall_ms = np.zeros(T)
    kept: list[Any] = []
    for t in range(T):
        inputs = replay.inputs(t)
        t0 = time.perf_counter()
        result = solver.step(**inputs)
        wall_ms[t] = (time.perf_counter() - t0) * 1e3
        x[t] = np.asarray(result.x, dtype=np.float64).reshape(N + 1, 4)
        u[t] = np.asarray(result.u, dtype=np.float64).reshape(N, 2)
        status[t] = int(result.status)
        qp_it[t] = int(getattr(result, "qp_iterations", -1))
        own = getattr(result, "time_total_ms", None)
        time_ms[t] = float(own) if own is not None else wall_ms[t]
        if keep_results:
            kept.append(result)
    return ReplayRun(solver=str(name or getattr(solver, "name", type(solver).__name__)), x=x, u=u, status=status,
                     qp_iterations=qp_it, time_ms=time_ms, wall_ms=wall_ms, results=kept)


# ----------------------------------------------------------------------------------------------
# A synthetic replay: random walkers, the robot driven by the reference optimum
# ----------------------------------------------------------------------------------------------


def synthetic_replay(spec: Spec, n_humans: int, steps: int, seed: int, *, goal_distance: float = 8.0,
                     with_obstacle: bool = True, v_ref: float = 0.8) -> Replay:
    """A closed loop in a random crowd, recorded as a replay (for benchmarks and tests).

    ``n_humans`` people walk at constant velocity (0.3 to 1.2 m/s, random headings) in the box
    [1, goal_distance + 1] x [-4, 4] and bounce off its borders; they start at least 1.5 m from
    the robot, and a person about to come closer than d_h + 0.7 m to the robot waits (stands
    still) for that step, so that the hard human rows stay feasible nearly always. Predictions are
    constant-velocity from the velocity observed over the last step. The robot starts at
    the origin, heading to the goal (goal_distance, 0), and is driven by the reference optimum
    (CasADi's Ipopt on the reference NLP, warm-started), braking when that fails. With
    ``with_obstacle`` a disc of radius 0.3 m lies near the straight path and the obstacle input is
    its closest boundary point.
    """
    NH = spec.humans.max
    if not 0 <= n_humans <= NH:
        raise ValueError(f"n_humans = {n_humans} must be in [0, N_h = {NH}] of the spec")
    if steps < 1:
        raise ValueError(f"steps = {steps} must be >= 1")
    rng = np.random.default_rng(seed)
    N, dt = spec.horizon.N, spec.dt
    pos = np.zeros((n_humans, 2))
    for i in range(n_humans):
        for _ in range(10_000):
            c = rng.uniform([1.0, -4.0], [goal_distance + 1.0, 4.0])
            if np.linalg.norm(c) >= 1.5:
                pos[i] = c
                break
    heading = rng.uniform(-np.pi, np.pi, n_humans)
    speed = rng.uniform(0.3, 1.2, n_humans)
    vel = np.stack([np.cos(heading), np.sin(heading)], axis=1) * speed[:, None]
    observed = vel.copy()  # the velocity the predictor sees: 0 for someone who waited
    lo, hi = np.array([1.0, -4.0]), np.array([goal_distance + 1.0, 4.0])
    keep_off = spec.humans.d_h + 0.7
    centre = np.array([rng.uniform(2.0, goal_distance - 2.0), rng.uniform(-0.8, 0.8)])
    radius = 0.3

    nlp = ReferenceNlp(spec)
    solve = nlp.nlp_solver(tol=1e-8, max_iter=500)
    params = problem_params(spec)
    x = np.array([0.0, 0.0, 0.0, 0.0])
    goal = np.array([goal_distance, 0.0, 0.0, v_ref])
    w_prev: FloatArray | None = None
    records: list[dict[str, Any]] = []
    for _ in range(steps):
        pred = pos[None, :, :] + observed[None, :, :] * (dt * np.arange(N + 1))[:, None, None]
        obstacle: FloatArray | None = None
        if with_obstacle:
            d = x[:2] - centre
            obstacle = centre + radius * d / max(float(np.linalg.norm(d)), 1e-9)
        records.append({"x0": x.copy(), "goal": goal.copy(), "humans_now": pos.copy(), "humans_pred": pred,
                        "obstacle": obstacle})
        p = nlp.params.pack(x, goal, pos, pred, obstacle, params)
        lbw, ubw, lbg, ubg = nlp.bounds(p)
        if w_prev is None:
            w_init = np.asarray(nlp.cold_guess(p)).ravel()
        else:
            X, U, S = nlp.decision.unpack(w_prev)
            w_init = nlp.decision.pack(np.vstack([x, X[2:], X[-1:]]), np.vstack([U[1:], U[-1:]]),
                                       np.concatenate([S[1:], S[-1:]]))
        sol = solve(x0=w_init, p=p, lbx=lbw, ubx=ubw, lbg=lbg, ubg=ubg)
        if solve.stats()["success"]:
            w_prev = np.asarray(sol["x"]).ravel()
            a, om = nlp.decision.unpack(w_prev)[1][0]
        else:  # brake, no turning, and start cold next time
            w_prev = None
            a, om = (max(spec.bounds.a[0], -x[3] / dt), 0.0)
        x_next = np.asarray(nlp.rollout(x, np.tile([a, om], (N, 1)))).reshape(N + 1, 4)[1]
        tentative = pos + vel * dt
        closer = np.linalg.norm(tentative - x_next[:2], axis=1) < np.linalg.norm(pos - x_next[:2], axis=1)
        wait = closer & (np.linalg.norm(tentative - x_next[:2], axis=1) < keep_off)
        new_pos = np.where(wait[:, None], pos, tentative)
        out = (new_pos < lo) | (new_pos > hi)
        vel = np.where(out, -vel, vel)
        new_pos = np.clip(new_pos, lo, hi)
        observed = (new_pos - pos) / dt
        pos, x = new_pos, x_next
    return Replay.from_steps(records, spec, scenario=f"synthetic-{n_humans}-humans", seed=seed)


def concatenate(replays: Sequence[Replay]) -> Replay:
    """One replay made of several of the same spec, one after the other (warm starts carry over)."""
    if not replays:
        raise ReplayError("nothing to concatenate")
    first = replays[0]
    for r in replays[1:]:
        if r.spec_hash != first.spec_hash or r.params != first.params:
            raise ReplayError("replays of different specs or parameters cannot be concatenated")
    cat = {k: np.concatenate([np.asarray(getattr(r, k)) for r in replays]) for k in ARRAYS}
    return Replay(**cat, N=first.N, dt=first.dt, NH=first.NH, spec=first.spec, params=dict(first.params),
                  scenario="+".join(r.scenario for r in replays), seed=first.seed)
