"""The runtime parameters: one table, the single source of their contract.

Every field of ``<name>_params`` (what the solver reads) and of ``<name>_controller_params`` (what
the controller around it reads, rows with ``controller=True``) is a row of ``PARAMS``: its name, the
spec key whose value is its default, its shape, unit, valid range and meaning. Derived from this table,
and from nothing else:

- the spec schema's rules and defaults for those keys (``humanmpc.codegen.spec``);
- the two C params structs, their ``_default`` functions and the C checks ``<name>_params_check`` /
  ``<name>_params_rule`` and ``<name>_controller_params_check`` / ``<name>_controller_params_rule``
  (``templates/``), which the safety monitor and the controller apply before every step;
- the manifest's ``params`` table, from which the Python binding's ``set_params`` checks its values;
- the problem parameters of the Ipopt reference (rows with ``problem=True``).

A broken rule is reported with the same text everywhere: ``Param.rule``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

# Kinds of parameter: a real number, a vector of reals, an interval [lower, upper] of reals, an
# integer, a 0/1 flag.
KINDS = ("real", "vector", "interval", "integer", "flag")


@dataclass(frozen=True)
class Range:
    """lo <= x <= hi, or lo < x (lo_open) / x < hi (hi_open)."""

    lo: float
    hi: float
    lo_open: bool = False
    hi_open: bool = False

    def holds(self, x: float) -> bool:
        above = x > self.lo if self.lo_open else x >= self.lo
        below = x < self.hi if self.hi_open else x <= self.hi
        return bool(above and below)  # False for NaN

    def text(self, var: str) -> str:
        lo = f"{_num(self.lo)} {'<' if self.lo_open else '<='} "
        hi = f" {'<' if self.hi_open else '<='} {_num(self.hi)}"
        return f"{lo}{var}{hi}"


def _num(x: float) -> str:
    return f"{x:g}" if not float(x).is_integer() or abs(x) >= 1e6 else str(int(x))


@dataclass(frozen=True)
class Param:
    name: str                  # field of <name>_params (<name>_controller_params), keyword of set_params
    key: str                   # spec key path whose value is the default
    kind: str                  # one of KINDS
    default: Any               # the spec's default (the evaluation's winning value, docs/evaluation.md)
    doc: str
    unit: str = ""
    size: int = 1              # entries in C (vectors, intervals)
    valid: Range | None = None  # every entry (real, vector, integer)
    lower: Range | None = None  # interval: the lower bound
    upper: Range | None = None  # interval: the upper bound
    problem: bool = False      # part of the optimal control problem itself (the Ipopt reference's parameters)
    spec_choices: tuple[str, ...] = field(default=())  # flag set in the spec by a choice: its index is the flag
    reason: str = ""           # why the range is what it is, said with the rule
    paper: Any = None          # the paper's value, when the default is not (spec `preset: paper`)
    controller: bool = False   # read by the controller around the solver: in <name>_controller_params

    @property
    def described(self) -> str:
        """The meaning with its unit, for listings."""
        return f"{self.doc} [{self.unit}]" if self.unit else self.doc

    @property
    def ctype(self) -> str:
        return "int" if self.kind in ("integer", "flag") else "real"

    @property
    def rule(self) -> str:
        """The rule in words: the same text in the spec's, C's and Python's messages ('must be ...')."""
        if self.kind == "real":
            assert self.valid is not None
            return f"a number with {self.valid.text(self.name)}"
        if self.kind == "vector":
            assert self.valid is not None
            return f"{self.size} numbers, each with {self.valid.text('w')}"
        if self.kind == "interval":
            assert self.lower is not None and self.upper is not None
            return (f"[lower, upper] with {self.lower.text('lower')}, {self.upper.text('upper')} and lower < upper"
                    + (f" ({self.reason})" if self.reason else ""))
        if self.kind == "integer":
            assert self.valid is not None
            return f"an integer with {self.valid.text(self.name)}"
        return "0 or 1 (false or true)"

    def spec_value(self, value: Any) -> Any:
        """The parameter's value for a spec value (a choice becomes its index, a boolean 0 or 1)."""
        if self.spec_choices:
            return self.spec_choices.index(value)
        if self.kind == "flag":
            return int(bool(value))
        return value

    def check(self, value: Any) -> tuple[Any, str | None]:
        """(the value as C stores it, None) when it keeps the rule, else (None, what is wrong with it)."""
        checked, why, _ = self.examine(value)
        return checked, why

    def examine(self, value: Any) -> tuple[Any, str | None, int | None]:
        """check(), and the index of the offending entry of a vector (None when the whole value is)."""
        if self.ctype == "int":
            if isinstance(value, (bool, np.bool_)):
                if self.kind == "flag":
                    return int(value), None, None
                return None, f"{value!r} has the wrong type", None
            if not isinstance(value, (int, np.integer)):
                return None, f"{value!r} has the wrong type", None
            i = int(value)
            ok = i in (0, 1) if self.kind == "flag" else self.valid is not None and self.valid.holds(i)
            return (i, None, None) if ok else (None, f"{value!r} is out of range", None)
        what = "an interval [lower, upper]" if self.kind == "interval" else f"a list of {self.size} numbers"
        if self.size == 1:
            items = [value]
        elif isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray) and value.ndim == 1):
            items = list(value)
        else:
            return None, f"{value!r} is not {what}", None
        if len(items) != self.size:
            return None, f"{value!r} has {len(items)} entries: it is not {what} (must have exactly {self.size})", None
        nums: list[float] = []
        for i, v in enumerate(items):
            entry = i if self.kind == "vector" else None
            if isinstance(v, (bool, np.bool_, str, bytes)) or not isinstance(v, (int, float, np.integer, np.floating)):
                return None, f"{v!r} has the wrong type: not a number", entry
            try:
                x = float(v)
            except OverflowError:
                return None, f"{v!r} is too large", entry
            if not math.isfinite(x):
                return None, f"{v!r} is not finite", entry
            nums.append(x)
        if self.kind == "interval":
            assert self.lower is not None and self.upper is not None
            if not nums[0] < nums[1]:
                return None, f"{value!r} is reversed or empty: lower bound must be < upper bound", None
            if not (self.lower.holds(nums[0]) and self.upper.holds(nums[1])):
                return None, f"{value!r} is out of range", None
            return tuple(nums), None, None
        assert self.valid is not None
        for i, x in enumerate(nums):
            if not self.valid.holds(x):
                return None, f"{items[i]!r} is out of range", (i if self.kind == "vector" else None)
        return (tuple(nums) if self.size > 1 else nums[0]), None, None

    @classmethod
    def from_manifest_row(cls, row: Mapping[str, Any]) -> Param:
        """The row as a generated package's manifest records it (what a binding checks against)."""
        def rng(part: str) -> Range | None:
            r = row.get(part)
            return None if r is None else Range(float(r[0]), float(r[1]), bool(r[2]), bool(r[3]))

        if row["kind"] not in KINDS:
            raise ValueError(f"unknown parameter kind {row['kind']!r} in the manifest")
        return cls(name=str(row["name"]), key=str(row["key"]), kind=str(row["kind"]), default=row.get("default"),
                   doc=str(row["doc"]), unit=str(row.get("unit", "")), size=int(row["size"]),
                   reason=str(row.get("reason", "")), valid=rng("valid"), lower=rng("lower"), upper=rng("upper"),
                   controller=bool(row.get("controller", False)))

    def manifest_row(self) -> dict[str, Any]:
        row: dict[str, Any] = {"name": self.name, "key": self.key, "kind": self.kind, "size": self.size,
                               "unit": self.unit, "doc": self.doc, "reason": self.reason, "rule": self.rule,
                               "controller": self.controller}
        for part in ("valid", "lower", "upper"):
            r = getattr(self, part)
            if r is not None:
                row[part] = [r.lo, r.hi, r.lo_open, r.hi_open]
        return row


# The weakest braking a protective stop may be configured with [m/s^2]: 1 m/s stopped in at most 10 s, in
# either direction (forward motion brakes at the lower acceleration bound, reverse motion at the upper). A
# bound of 0 (or 1e-9) let a stop command no braking: the robot drove on at its speed with a person ahead
# or behind. The spec, the C check and Python all apply this row.
BRAKING_MIN = 0.1

# Caps: far beyond any robot, but finite, so that no value overflows the solver's arithmetic.
_WEIGHT = Range(0.0, 1e9)
_DIST = Range(0.0, 100.0)

PARAMS: tuple[Param, ...] = (
    Param("w_goal", "weights.goal", "vector", (0.5, 0.5, 0.0, 50.0), "stage weights on x - g", size=4,
          valid=_WEIGHT, problem=True, paper=(0.5, 0.5, 0.0, 250.0)),
    Param("w_goal_terminal", "weights.goal_terminal", "vector", (40.0, 40.0, 2.0, 0.0),
          "terminal weights on x_N - g", size=4, valid=_WEIGHT, problem=True),
    Param("w_control", "weights.control", "vector", (0.0, 2.0), "stage weights on u = [a, omega]", size=2,
          valid=_WEIGHT, problem=True, paper=(0.0, 0.0)),
    Param("q", "collision_cost.q", "real", 50.0, "height of the collision potential", valid=Range(0.0, 1e6),
          problem=True, paper=2.0),
    Param("d_th", "collision_cost.d_th", "real", 1.0, "distance at which the potential is q/2", unit="m",
          valid=_DIST, problem=True),
    Param("kappa", "collision_cost.kappa", "real", 5.0, "steepness of the potential", unit="1/m",
          valid=Range(0.0, 1e3, lo_open=True), problem=True),
    # Not in the Ipopt reference (like speed and separation): its OCP has the potential at every node, the
    # default here; the controller shortens it during the approach only (controller.arrival_margin).
    Param("collision_horizon", "collision_cost.horizon", "real", 1e4,
          "time ahead over which the collision potential acts on people's predictions: nodes later than this "
          "carry none (default: every node)", unit="s", valid=Range(0.0, 1e4)),
    Param("d_h", "humans.d_h", "real", 0.5, "hard minimum distance to a human's current position", unit="m",
          valid=_DIST, problem=True),
    Param("human_slack_l1", "humans.slack_l1", "real", 1e4,
          "exact-penalty weight on the human rows: must exceed their multipliers", valid=_WEIGHT),
    Param("human_slack_l2", "humans.slack_l2", "real", 100.0, "L2 penalty on the human-row slack (0.5*l2*s^2)",
          valid=_WEIGHT),
    # Speed and separation (ISO/TS 15066's protective separation, for people): the paper keeps
    # the plan d_h from where people are now; a person walking towards the robot covers a metre while it
    # brakes from 0.8 m/s. Not in the Ipopt reference: the bound is frozen at each linearisation point.
    Param("separation", "humans.separation", "flag", True,
          "speed and separation: at every node the speed towards each person is at most the speed from which "
          "braking after reaction_time at the lower acceleration bound stops the robot before it comes within "
          "d_h of them, while they close in at their velocity; the monitor checks the command the same way",
          paper=False),
    Param("reaction_time", "humans.reaction_time", "real", 0.3,
          "time before braking starts (the command's period, the base's latency) in the speed-and-separation "
          "bound", unit="s", valid=Range(0.0, 10.0)),
    Param("d_s", "obstacle.d_s", "real", 0.5, "soft minimum distance to the closest obstacle", unit="m",
          valid=_DIST, problem=True),
    Param("slack_l1", "obstacle.slack_l1", "real", 1000.0, "L1 penalty on the obstacle slack", valid=_WEIGHT,
          problem=True, paper=100.0),
    Param("slack_l2", "obstacle.slack_l2", "real", 100.0, "L2 penalty on the obstacle slack (0.5*l2*s^2)",
          valid=_WEIGHT, problem=True),
    # The bounds must admit the protective stop: standstill (v = 0), braking and no turning. Braking means a
    # real deceleration, not a lower bound a hair below 0: a_min <= -BRAKING_MIN (docs/reliability.md).
    Param("v_bounds", "bounds.v", "interval", (0.0, 1.0), "forward speed", unit="m/s", size=2,
          lower=Range(-100.0, 0.0), upper=Range(0.0, 100.0, lo_open=True), problem=True,
          reason="the robot must be able to come to a standstill, and to move"),
    Param("a_bounds", "bounds.a", "interval", (-1.0, 1.0), "acceleration", unit="m/s^2", size=2,
          lower=Range(-100.0, -BRAKING_MIN), upper=Range(BRAKING_MIN, 100.0), problem=True,
          reason="a protective stop must be able to brake from either direction, by at least 0.1 m/s^2 "
                 "(a reversing robot brakes at the upper bound)"),
    Param("omega_bounds", "bounds.omega", "interval", (-1.5, 1.5), "turn rate", unit="rad/s", size=2,
          lower=Range(-100.0, 0.0), upper=Range(0.0, 100.0), problem=True,
          reason="the robot must be able to hold its heading"),
    Param("regularization", "solver.regularization", "real", 1e-6,
          "Levenberg-Marquardt term added to the QP Hessian", valid=Range(0.0, 1e3)),
    Param("qp_tol", "solver.qp_tol", "real", 1e-6, "QP convergence tolerance", valid=Range(0.0, 1.0, lo_open=True)),
    Param("deadline_ms", "monitor.deadline_ms", "real", 20.0, "time allowed for one solver step", unit="ms",
          valid=Range(0.0, 1e5, lo_open=True)),
    Param("qp_max_iter", "solver.qp_max_iter", "integer", 50, "interior-point iteration limit per QP",
          valid=Range(1, 1000)),
    Param("line_search", "solver.line_search", "flag", False,
          "RTI: damp the QP step by a backtracking line search on the l1 merit (false: full step)"),
    Param("row_screening", "solver.row_screening", "flag", True,
          "leave distance rows far from binding out of each QP and check them at its solution (re-solving "
          "with any that are violated): the same solution, at the cost of the rows that matter"),
    Param("exact_hessian", "solver.hessian", "flag", "exact",
          "RTI Hessian: gauss_newton (acados' default), or exact: the Hessian of the Lagrangian at the shifted "
          "multipliers, projected per stage onto the PSD cone (no omega chatter when the goal is far)",
          spec_choices=("gauss_newton", "exact"), paper="gauss_newton"),
    # The controller around the solver (c_runtime/controller*.c). The defaults are the evaluation's
    # (docs/evaluation.md); the paper's values hand the OCP the final goal with nothing around it but the
    # goal taper.
    Param("v_ref", "controller.v_ref", "real", 0.8, "cruising speed the OCP is asked to track", unit="m/s",
          valid=Range(0.0, 100.0, lo_open=True), controller=True),
    Param("speed_limit", "controller.speed_limit", "real", 0.8,
          "cap on the planned speed (the OCP's upper speed bound is min(v_bounds upper, speed_limit))", unit="m/s",
          valid=Range(0.0, 100.0, lo_open=True), controller=True, paper=100.0),
    Param("lookahead", "controller.lookahead", "real", 0.0,
          "carrot distance along the path (0: v_ref * T, the plan's length at cruising speed)", unit="m",
          valid=Range(0.0, 1e4), controller=True, paper=1e4),
    Param("progress", "controller.progress", "flag", True,
          "the progress objective: the OCP tracks a goal per node along the path, each where the robot would be "
          "at the cruising speed (from its speed, within the acceleration bound, braking to arrive at rest), "
          "weighted by progress_weights, instead of one carrot with a speed to track in any direction (the "
          "paper's objective; goal_taper and the approach then apply)", controller=True, paper=False),
    Param("progress_weights", "controller.progress_weights", "vector", (20.0, 20.0, 0.0, 1.0),
          "stage weights on x - g_n with the progress objective (g_n: the node's goal along the path)", size=4,
          valid=_WEIGHT, controller=True),
    Param("passing", "controller.passing", "flag", True,
          "solve the candidate plans of controller.candidates in every period (false: the main plan alone, "
          "whatever the package's size; the paper's configuration)", controller=True, paper=False),
    Param("candidate_hysteresis", "controller.candidate_hysteresis", "real", 0.1,
          "with several candidate plans: another plan replaces the one applied last period only when it costs "
          "less by this fraction of its cost (the robot does not switch sides back and forth)",
          valid=Range(0.0, 1.0, hi_open=True), controller=True),
    Param("goal_clearance", "controller.goal_clearance", "real", 1.5,
          "people who stand (below 0.2 m/s) within this distance of the final goal carry no collision potential: "
          "a goal beside people who stand still is reachable up to d_h (the hard distance, C2 and speed and "
          "separation still apply; 0: every person carries it)", unit="m", valid=_DIST, controller=True, paper=0.0),
    Param("goal_taper", "controller.goal_taper", "real", 0.5,
          "the speed to track is at most goal_taper times the distance left to the goal", unit="1/s",
          valid=Range(0.0, 100.0, lo_open=True), controller=True),
    Param("goal_tolerance", "controller.goal_tolerance", "real", 0.3,
          "distance to the final goal at which it counts as reached (the robot then brakes)", unit="m",
          valid=Range(0.0, 100.0, lo_open=True), controller=True),
    Param("yaw_goal_tolerance", "controller.yaw_goal_tolerance", "real", 0.25,
          "within goal_tolerance of a goal pose, the robot turns in place until its heading is this close to "
          "the goal's (3.2, above pi: any heading; a path without a goal pose has none to meet)", unit="rad",
          valid=Range(0.0, 3.2, lo_open=True), controller=True, paper=3.2),
    Param("approach", "controller.approach", "flag", True,
          "once the horizon reaches the goal: track no speed, weigh the position at every node "
          "(approach_position) and arrive at rest (approach_stop)", controller=True, paper=False),
    Param("approach_position", "controller.approach_position", "real", 5.0,
          "stage weight on px, py during the approach", valid=_WEIGHT, controller=True),
    Param("approach_stop", "controller.approach_stop", "real", 40.0,
          "terminal weight on v (to 0) during the approach", valid=_WEIGHT, controller=True),
    Param("arrival_margin", "controller.arrival_margin", "real", 0.1,
          "during the approach the collision potential ends (collision_horizon) at the robot's earliest "
          "arrival within goal_tolerance, from rest at v_ref and the upper acceleration bound, plus this "
          "margin: predictions of people crossing the goal after the robot has stopped there do not hold it "
          "off (large: no end)", unit="s", valid=Range(0.0, 1e4), controller=True),
    Param("loop_ratio", "controller.loop_ratio", "real", 0.5,
          "a plan whose end is nearer its start than loop_ratio times its length is a loop (0: never)",
          valid=Range(0.0, 1.0, hi_open=True), controller=True, paper=0.0),
    Param("loop_min_length", "controller.loop_min_length", "real", 1.0,
          "plans shorter than this are never loops (stopping, waiting, arriving)", unit="m", valid=_DIST,
          controller=True),
    Param("recovery_iterations", "controller.recovery_iterations", "integer", 10,
          "SQP iterations of a recovery from a cold start after a loop or a stall (0: no recovery)",
          valid=Range(0, 100), controller=True, paper=0),
    Param("stall_time", "controller.stall_time", "real", 5.0,
          "time without progress towards the goal, while not stopping, after which the robot is stalled",
          unit="s", valid=Range(0.0, 1e4, lo_open=True), controller=True),
    Param("stall_distance", "controller.stall_distance", "real", 0.2,
          "the distance left to the goal must shrink by this much to count as progress", unit="m",
          valid=_DIST, controller=True),
)

BY_KEY: Mapping[str, Param] = {p.key: p for p in PARAMS}
PROBLEM_PARAMS: tuple[Param, ...] = tuple(p for p in PARAMS if p.problem)
# The fields of <name>_params and of <name>_controller_params, each in the table's order (the C checks
# number them so: 1 + the index in their own struct).
SOLVER_PARAMS: tuple[Param, ...] = tuple(p for p in PARAMS if not p.controller)
CONTROLLER_PARAMS: tuple[Param, ...] = tuple(p for p in PARAMS if p.controller)


def paper_values() -> dict[str, Any]:
    """Spec key -> the paper's value, for every parameter whose default is not the paper's."""
    return {p.key: p.paper for p in PARAMS if p.paper is not None}


def spec_params(spec: Any) -> dict[str, Any]:
    """The runtime parameters' values in a resolved spec (the defaults of its generated solver)."""
    out: dict[str, Any] = {}
    for p in PARAMS:
        value: Any = spec
        for part in p.key.split("."):
            value = getattr(value, part)
        out[p.name] = p.spec_value(value)
    return out
