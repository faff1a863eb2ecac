"""The problem spec: schema, defaults (the paper's values), validation and the resolved form.

The schema is the set of frozen dataclasses below; each field carries its rule in its metadata, so
the defaults, the types and the checks live in one place. ``load_spec`` / ``resolve_spec`` return a
``Spec`` or raise ``SpecError`` listing every problem found, each naming the key path, the value
and the rule broken. Everything that reaches generated C from a spec passes through here: names
must be C identifiers (and not keywords), numbers must be finite and in range.
"""

from __future__ import annotations

import dataclasses
import difflib
import hashlib
import io
import json
import math
import os
import re
import stat
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import yaml

from .names import clash, reserved_prefix
from .params import BY_KEY, Param, paper_values


class SpecError(ValueError):
    """A spec that cannot be used; ``problems`` holds one line per broken rule."""

    def __init__(self, problems: Sequence[str], source: str = "spec") -> None:
        self.problems = list(problems)
        self.source = source
        lines = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(f"invalid {source}: {len(self.problems)} problem(s)\n{lines}")


# --------------------------------------------------------------------------------------------
# Field rules
# --------------------------------------------------------------------------------------------

# C99 and C11 keywords plus names that would collide with the runtime or the C library's macros
# once the spec's name becomes a prefix.
C_KEYWORDS = frozenset(
    [
        "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else",
        "enum", "extern", "float", "for", "goto", "if", "inline", "int", "long", "register",
        "restrict", "return", "short", "signed", "sizeof", "static", "struct", "switch", "typedef",
        "union", "unsigned", "void", "volatile", "while", "_Alignas", "_Alignof", "_Atomic", "_Bool",
        "_Complex", "_Generic", "_Imaginary", "_Noreturn", "_Static_assert", "_Thread_local", "asm",
        "bool", "true", "false", "NULL",
    ]
)
RESERVED_NAMES = frozenset({"hm", "casadi", "humanmpc", "main", "errno", "assert"})
# The package writes <name>.h beside the sources that include the system's headers: a name that is
# a standard C or POSIX header's would shadow it (a spec named "time" silently replaced <time.h>, and
# with it the deadline monitor's clock). C99/C11/C23 headers, POSIX's, and common others.
SYSTEM_HEADER_NAMES = frozenset({
    "assert", "complex", "ctype", "errno", "fenv", "float", "inttypes", "iso646", "limits", "locale", "math",
    "setjmp", "signal", "stdalign", "stdarg", "stdatomic", "stdbit", "stdbool", "stdckdint", "stddef", "stdint",
    "stdio", "stdlib", "stdnoreturn", "string", "tgmath", "threads", "time", "uchar", "wchar", "wctype",
    "aio", "arpa", "cpio", "dirent", "dlfcn", "fcntl", "fmtmsg", "fnmatch", "ftw", "glob", "grp", "iconv",
    "langinfo", "libgen", "monetary", "mqueue", "ndbm", "net", "netdb", "netinet", "nl_types", "poll",
    "pthread", "pwd", "regex", "sched", "search", "semaphore", "spawn", "strings", "stropts", "sys", "syslog",
    "tar", "termios", "trace", "ulimit", "unistd", "utime", "utmpx", "wordexp", "alloca", "malloc", "features",
    "endian", "memory", "cffi", "casadi", "printf",
})
# Matched with fullmatch: "$" alone also matches before a trailing newline.
IDENT_RE = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
MAX_NAME_LEN = 31
# Smallest QP tolerance a single-precision solver reaches reliably: measured on replays in crowds of
# 10 and 30 humans, QPs solved to 1e-7 fail at the rounding floor (a third to three quarters of
# them), to 3e-7 and above they do not (docs/firmware.md). The RTI line search solves its QPs to
# 0.1 * qp_tol (ocp_nlp_step.c), so with it qp_tol must be ten times larger.
FLOAT_MIN_QP_TOL = 1e-6


@dataclass(frozen=True)
class Rule:
    """How one spec value is checked. ``kind``: number, integer, boolean, choice, name, or param (a
    runtime parameter, checked by its row of the parameter table)."""

    kind: str
    doc: str
    gt: float | None = None
    ge: float | None = None
    le: float | None = None
    choices: tuple[str, ...] = ()
    param: Param | None = None

    def check(self, path: str, value: Any) -> tuple[Any, list[str]]:
        """Return the normalised value and the problems found (empty when valid)."""
        checker = getattr(self, f"_check_{self.kind}")
        return checker(path, value)

    # -- scalars --------------------------------------------------------------------------------
    def _range_problems(self, path: str, value: float | int) -> list[str]:
        if self.gt is not None and not value > self.gt:
            return [f"{path}: {value!r} is out of range: must be > {self.gt:g}"]
        if self.ge is not None and not value >= self.ge:
            return [f"{path}: {value!r} is out of range: must be >= {self.ge:g}"]
        if self.le is not None and not value <= self.le:
            return [f"{path}: {value!r} is out of range: must be <= {self.le:g}"]
        return []

    def _check_number(self, path: str, value: Any) -> tuple[Any, list[str]]:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return None, [f"{path}: {value!r} has the wrong type: must be a number"]
        try:
            x = float(value)
        except OverflowError:
            return None, [f"{path}: {value!r} is too large: must be a finite number"]
        if not math.isfinite(x):
            return None, [f"{path}: {value!r} is not finite: must be a finite number"]
        return x, self._range_problems(path, x)

    def _check_integer(self, path: str, value: Any) -> tuple[Any, list[str]]:
        if isinstance(value, bool) or not isinstance(value, int):
            return None, [f"{path}: {value!r} has the wrong type: must be an integer"]
        return int(value), self._range_problems(path, int(value))

    def _check_param(self, path: str, value: Any) -> tuple[Any, list[str]]:
        assert self.param is not None
        checked, why, entry = self.param.examine(value)
        if why is not None:
            where = path if entry is None else f"{path}[{entry}]"
            return None, [f"{where}: {why}: {self.param.name} must be {self.param.rule}"]
        return checked, []

    # -- strings --------------------------------------------------------------------------------
    def _check_boolean(self, path: str, value: Any) -> tuple[Any, list[str]]:
        if not isinstance(value, bool):
            return None, [f"{path}: {value!r} has the wrong type: must be true or false"]
        return value, []

    def _check_choice(self, path: str, value: Any) -> tuple[Any, list[str]]:
        if not isinstance(value, str) or value not in self.choices:
            return None, [f"{path}: {value!r} is not allowed: must be one of {', '.join(self.choices)}"]
        return value, []

    def _check_name(self, path: str, value: Any) -> tuple[Any, list[str]]:
        if not isinstance(value, str):
            return None, [f"{path}: {value!r} has the wrong type: must be a string (a C identifier)"]
        if not IDENT_RE.fullmatch(value):
            return None, [
                f"{path}: {value!r} is not a C identifier: use a letter followed by letters, "
                "digits or underscores"
            ]
        if len(value) > MAX_NAME_LEN:
            return None, [f"{path}: {value!r} is too long: at most {MAX_NAME_LEN} characters"]
        if value in C_KEYWORDS or value.lower() in RESERVED_NAMES:
            return None, [f"{path}: {value!r} is reserved (a C keyword or a runtime prefix): choose another name"]
        if value.lower() in SYSTEM_HEADER_NAMES:
            return None, [f"{path}: {value!r} is reserved: the package's {value}.h would shadow the system header "
                          f"<{value.lower()}.h>: choose another name"]
        if value != value.lower():
            return None, [f"{path}: {value!r} has capital letters: the name becomes file names (one file on a "
                          f"case-insensitive file system) and upper-case macros ({value.upper()}_N), the same for "
                          f"{value.lower()!r}: use lower case"]
        why = reserved_prefix(value)
        if why is not None:
            return None, [f"{path}: {value!r} is reserved: its external symbols ({value}_solver_step, ...) would "
                          f"begin like {why}: choose another name"]
        found = clash(value)
        if found is not None:
            return None, [f"{path}: {value!r} could clash with another package: {found.explain()}"]
        return value, []


def _field(default: Any, rule: Rule) -> Any:
    return field(default=default, metadata={"rule": rule})


def number(default: float, doc: str, *, gt: float | None = None, ge: float | None = None,
           le: float | None = None) -> Any:
    return _field(default, Rule("number", doc, gt=gt, ge=ge, le=le))


def integer(default: int, doc: str, *, ge: float | None = None, le: float | None = None) -> Any:
    return _field(default, Rule("integer", doc, ge=ge, le=le))


def choice(default: str, doc: str, choices: tuple[str, ...]) -> Any:
    return _field(default, Rule("choice", doc, choices=choices))


def param(key: str) -> Any:
    """A key whose value is a runtime parameter's default: rule, default and meaning from its row of
    the parameter table (humanmpc.codegen.params)."""
    p = BY_KEY[key]
    if p.kind == "flag":  # a boolean or a choice in the spec, 0 or 1 in C
        rule = Rule("choice", p.described, choices=p.spec_choices) if p.spec_choices else Rule("boolean", p.described)
        return _field(p.default, rule)
    return _field(p.default, Rule("param", p.described, param=p))


# --------------------------------------------------------------------------------------------
# The schema (defaults: the paper's experiment, section "Parameters and Model")
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Horizon:
    T: float = number(5.0, "horizon length [s]", gt=0.0, le=600.0)
    N: int = integer(50, "number of shooting intervals (a fixed size)", ge=1, le=1000)


@dataclass(frozen=True)
class Integrator:
    method: str = choice("rk4", "integration scheme of the dynamics over one interval", ("rk4",))
    steps: int = integer(1, "integrator steps per shooting interval", ge=1, le=100)


@dataclass(frozen=True)
class Humans:
    max: int = integer(10, "N_h: how many humans the solver handles (a fixed size)", ge=0, le=200)
    d_h: float = param("humans.d_h")
    slack_l1: float = param("humans.slack_l1")
    slack_l2: float = param("humans.slack_l2")
    separation: bool = param("humans.separation")
    reaction_time: float = param("humans.reaction_time")


@dataclass(frozen=True)
class CollisionCost:
    q: float = param("collision_cost.q")
    d_th: float = param("collision_cost.d_th")
    kappa: float = param("collision_cost.kappa")
    horizon: float = param("collision_cost.horizon")


@dataclass(frozen=True)
class Obstacle:
    d_s: float = param("obstacle.d_s")
    slack_l1: float = param("obstacle.slack_l1")
    slack_l2: float = param("obstacle.slack_l2")


@dataclass(frozen=True)
class Weights:
    goal: tuple[float, ...] = param("weights.goal")
    goal_terminal: tuple[float, ...] = param("weights.goal_terminal")
    control: tuple[float, ...] = param("weights.control")


@dataclass(frozen=True)
class Bounds:
    v: tuple[float, float] = param("bounds.v")
    a: tuple[float, float] = param("bounds.a")
    omega: tuple[float, float] = param("bounds.omega")


# Distance rows one QP holds at most when the spec leaves solver.qp_rows at 0 (fewer if the problem has
# fewer): measured on the evaluation's closed loops, docs/benchmarks.md ("Row capacity").
DEFAULT_QP_ROWS = 256


@dataclass(frozen=True)
class Solver:
    qp_rows: int = integer(
        0, "distance rows one QP holds at most (a fixed size: the QP solvers' memory and the work of an "
        "iteration are sized by it); a QP with more holds those of smallest margin and checks the others at "
        f"its solution. 0: {DEFAULT_QP_ROWS}, or every row ((N + 1) (N_h + 1)) if there are fewer; with "
        "solver.row_screening off every row is in the QP, so give every row to solve whole QPs",
        ge=0, le=10_000_000)
    regularization: float = param("solver.regularization")
    qp_max_iter: int = param("solver.qp_max_iter")
    qp_tol: float = param("solver.qp_tol")
    line_search: bool = param("solver.line_search")
    row_screening: bool = param("solver.row_screening")
    hessian: str = param("solver.hessian")


@dataclass(frozen=True)
class Monitor:
    deadline_ms: float = param("monitor.deadline_ms")


_DEFAULT_MAX_TRACKS = 32  # M, tracked people per controller step, unless humans.max is larger


@dataclass(frozen=True)
class Controller:
    max_tracks: int = integer(_DEFAULT_MAX_TRACKS, "M: tracked people the controller takes per step (a fixed size, "
                              ">= humans.max; default 32, or humans.max when larger)", ge=1, le=1000)
    max_path_points: int = integer(256, "P: waypoints of the reference path (a fixed size)", ge=2, le=100_000)
    max_obstacle_points: int = integer(256, "K: obstacle points (a scan's or a costmap's) per step (a fixed size)",
                                       ge=1, le=100_000)
    candidates: int = integer(3, "candidate plans per period (a fixed size): the main plan and ones that pass the "
                                 "nearest people on either side, the cheapest safe one applied (1: one plan; "
                                 "preset paper: 1)", ge=1, le=8)
    v_ref: float = param("controller.v_ref")
    speed_limit: float = param("controller.speed_limit")
    lookahead: float = param("controller.lookahead")
    progress: bool = param("controller.progress")
    progress_weights: tuple[float, ...] = param("controller.progress_weights")
    passing: bool = param("controller.passing")
    candidate_hysteresis: float = param("controller.candidate_hysteresis")
    goal_clearance: float = param("controller.goal_clearance")
    goal_taper: float = param("controller.goal_taper")
    goal_tolerance: float = param("controller.goal_tolerance")
    yaw_goal_tolerance: float = param("controller.yaw_goal_tolerance")
    approach: bool = param("controller.approach")
    approach_position: float = param("controller.approach_position")
    approach_stop: float = param("controller.approach_stop")
    arrival_margin: float = param("controller.arrival_margin")
    loop_ratio: float = param("controller.loop_ratio")
    loop_min_length: float = param("controller.loop_min_length")
    recovery_iterations: int = param("controller.recovery_iterations")
    stall_time: float = param("controller.stall_time")
    stall_distance: float = param("controller.stall_distance")


PRESETS = ("humanmpc", "paper")


@dataclass(frozen=True)
class Spec:
    name: str = _field("paper", Rule("name", "C identifier; prefix of every public C name"))
    preset: str = choice(
        "humanmpc", "defaults of the keys not given: humanmpc (the values that won the evaluation, "
        "docs/evaluation.md) or paper (the paper's values exactly: its weights, Gauss-Newton, the final goal "
        "with nothing around the OCP but the goal taper)", PRESETS,
    )
    precision: str = choice(
        "double", "real type of the generated C: double, or float for single-precision FPUs (Cortex-M4; "
        f"needs solver.qp_tol >= {FLOAT_MIN_QP_TOL:g}, >= {10 * FLOAT_MIN_QP_TOL:g} with solver.line_search)",
        ("double", "float"),
    )
    horizon: Horizon = field(default_factory=Horizon)
    integrator: Integrator = field(default_factory=Integrator)
    humans: Humans = field(default_factory=Humans)
    collision_cost: CollisionCost = field(default_factory=CollisionCost)
    obstacle: Obstacle = field(default_factory=Obstacle)
    weights: Weights = field(default_factory=Weights)
    bounds: Bounds = field(default_factory=Bounds)
    solver: Solver = field(default_factory=Solver)
    monitor: Monitor = field(default_factory=Monitor)
    controller: Controller = field(default_factory=Controller)

    @staticmethod
    def paper(name: str = "paper") -> Spec:
        """The paper's configuration (``preset: paper``)."""
        return resolve_spec({"name": name, "preset": "paper"})

    @property
    def dt(self) -> float:
        return self.horizon.T / self.horizon.N

    @property
    def n_rows(self) -> int:
        """General rows per stage: one per human and one for the closest obstacle."""
        return self.humans.max + 1

    @property
    def qp_row_capacity(self) -> int:
        """Distance rows one QP holds at most: solver.qp_rows (0: DEFAULT_QP_ROWS), never more than the
        (N + 1) (N_h + 1) rows the problem has."""
        rows = (self.horizon.N + 1) * self.n_rows
        return min(rows, self.solver.qp_rows or DEFAULT_QP_ROWS)

    def to_dict(self) -> dict[str, Any]:
        return _plain(dataclasses.asdict(self))

    def to_yaml(self) -> str:
        return yaml.safe_dump(self.to_dict(), sort_keys=False, default_flow_style=None)

    def digest(self) -> str:
        """SHA-256 of the resolved spec in canonical JSON: what a generated solver was made from."""
        canonical = json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(canonical.encode()).hexdigest()


def _plain(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    return obj


# --------------------------------------------------------------------------------------------
# Validation
# --------------------------------------------------------------------------------------------


def _unknown_key_problem(path: str, key: Any, valid: Sequence[str]) -> str:
    where = f"{path}.{key}" if path else str(key)
    if not isinstance(key, str):
        return f"{where}: key {key!r} is not a string: valid keys here are {', '.join(valid)}"
    lowered = {v.lower(): v for v in valid}
    guess = difflib.get_close_matches(key.lower(), list(lowered), n=1, cutoff=0.5)
    hint = f"did you mean '{lowered[guess[0]]}'?" if guess else f"valid keys here are {', '.join(valid)}"
    return f"{where}: unknown key: {hint}"


def _resolve_section(cls: type, data: Any, path: str, problems: list[str]) -> Any:
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        problems.append(f"{path or 'spec'}: {data!r} has the wrong type: must be a mapping of keys to values")
        return cls()
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for key in data:
        if key not in fields:
            problems.append(_unknown_key_problem(path, key, list(fields)))
    values: dict[str, Any] = {}
    for name, f in fields.items():
        if name not in data:
            continue
        sub_path = f"{path}.{name}" if path else name
        rule = f.metadata.get("rule")
        if rule is None:  # a nested section
            section_cls = cast(type, f.default_factory)
            values[name] = _resolve_section(section_cls, data[name], sub_path, problems)
            continue
        value, found = rule.check(sub_path, data[name])
        problems += found
        if not found:
            values[name] = value
    return cls(**values)


def _cross_checks(spec: Spec) -> list[str]:
    """Rules that involve more than one key."""
    problems = []
    if spec.controller.max_tracks < spec.humans.max:
        problems.append(f"controller.max_tracks: {spec.controller.max_tracks} is below humans.max "
                        f"({spec.humans.max}): the controller chooses the solver's N_h people among its tracks, "
                        "so it must take at least as many")
    floor = FLOAT_MIN_QP_TOL * (10.0 if spec.solver.line_search else 1.0)
    if spec.precision == "float" and spec.solver.qp_tol < floor:
        why = " (the line search solves its QPs to 0.1 * qp_tol)" if spec.solver.line_search else ""
        problems.append(
            f"solver.qp_tol: {spec.solver.qp_tol!r} is below what single precision reaches{why}: the QP "
            f"residuals stop at their rounding floor and the QPs fail; with precision: float set "
            f"solver.qp_tol >= {floor:g}"
        )
    return problems


def _with_defaults(data: Mapping[str, Any], defaults: Mapping[str, Any]) -> dict[str, Any]:
    """data with the values of defaults (dotted key paths) where data gives none."""
    out: dict[str, Any] = dict(data)
    for key, value in defaults.items():
        *sections, leaf = key.split(".")
        node = out
        for section in sections:
            sub = node.get(section)
            if sub is None:
                sub = {}
            elif not isinstance(sub, Mapping):
                break  # a wrong type: reported by the resolution
            node[section] = sub = dict(sub)
            node = sub
        else:
            node.setdefault(leaf, list(value) if isinstance(value, tuple) else value)
    return out


def resolve_spec(data: Any, source: str = "spec") -> Spec:
    """Validate a parsed spec (a mapping, or None for all defaults) and fill in the defaults."""
    problems: list[str] = []
    if isinstance(data, Mapping) and data.get("preset") == "paper":
        # the paper's objective and one plan (no passing decisions)
        data = _with_defaults(data, {**paper_values(), "controller.candidates": 1})
    humans = data.get("humans") if isinstance(data, Mapping) else None
    if isinstance(humans, Mapping) and isinstance(humans.get("max"), int) and humans["max"] > _DEFAULT_MAX_TRACKS:
        # The controller takes at least the solver's N_h tracks: a larger N_h raises the default M with it
        # (an M given below N_h is still an error).
        data = _with_defaults(data, {"controller.max_tracks": humans["max"]})
    spec = _resolve_section(Spec, data, "", problems)
    if not problems:
        problems = _cross_checks(spec)
    if problems:
        raise SpecError(problems, source)
    return spec


class _UniqueKeyLoader(yaml.SafeLoader):
    """yaml.SafeLoader that refuses duplicate keys instead of silently keeping the last one, and
    refuses aliases: a spec needs none, and nested aliases expand exponentially (a 510-byte
    document to gigabytes)."""

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.AliasEvent):
            mark = self.peek_event().start_mark
            raise SpecError([f"line {mark.line + 1}: YAML aliases (*name) are not allowed in a spec: "
                             "write the value out"])
        return super().compose_node(parent, index)


def _construct_unique_mapping(loader: _UniqueKeyLoader, node: yaml.MappingNode, deep: bool = False) -> Any:
    seen: dict[Any, int] = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise SpecError(
                [f"{key}: duplicate key (lines {seen[key] + 1} and {key_node.start_mark.line + 1}): keep one"]
            )
        seen[key] = key_node.start_mark.line
    return loader.construct_mapping(node, deep=deep)


# YAML 1.1 (PyYAML) reads 1e-6 as a string; specs are written by people who expect a number.
_UniqueKeyLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)
_UniqueKeyLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG,
    _construct_unique_mapping,
)


# A spec is a few dozen lines, a few levels deep: anything much larger or deeper is a mistake (or an
# attack on the loader: PyYAML composes nested collections recursively, 400 levels in 1 KB raised
# RecursionError).
MAX_SPEC_BYTES = 64 * 1024
MAX_SPEC_DEPTH = 16


def _line_text(text: str, line: int) -> str:
    """Line ``line`` (0-based) of text, stripped and cut short, for a message."""
    lines = text.splitlines()
    got = lines[line].strip() if 0 <= line < len(lines) else ""
    return got if len(got) <= 60 else got[:57] + "..."


def _yaml_problem(err: yaml.MarkedYAMLError, text: str) -> str:
    """PyYAML's error in our words, naming the line of the mistake: PyYAML marks where it noticed it,
    for a key without ':' or an unclosed bracket or quote the line after; its context mark is the line
    where the unfinished thing began."""
    problem = err.problem or "a syntax error"
    context = err.context or ""
    pm, cm = err.problem_mark, err.context_mark
    at = pm.line if pm is not None else 0
    began = cm.line if cm is not None else at
    if "simple key" in context:
        return (f"line {began + 1}: {_line_text(text, began)!r} is a key without ':' (write 'key: value'); "
                f"not valid YAML")
    if "flow" in context:
        return (f"line {began + 1}: a '[' or '{{' opened on this line is not closed ({problem} on line {at + 1}); "
                "not valid YAML")
    if "quoted scalar" in context:
        return f"line {began + 1}: a quoted string opened on this line is not closed; not valid YAML"
    if "'\\t'" in problem:
        return f"line {at + 1}: a tab character: indent with spaces; not valid YAML"
    if "another document" in problem:
        return f"line {at + 1}: a second YAML document ('---'): a spec is one document; not valid YAML"
    if "mapping values are not allowed" in problem:
        return (f"line {at + 1}: {_line_text(text, at)!r} has a ':' where YAML cannot start a key: quote a value "
                "that holds ': ', or indent the key under its section; not valid YAML")
    if "block end" in problem:
        return (f"line {at + 1}: {_line_text(text, at)!r} does not fit the indentation or the lines above "
                f"({problem}); not valid YAML")
    where = f" ({context} from line {began + 1})" if context and began != at else ""
    return f"line {at + 1}: {problem}{where}; not valid YAML"


def _reader_problem(err: yaml.reader.ReaderError, text: str) -> str:
    """A character YAML does not accept (a control character), by line and column."""
    line = text.count("\n", 0, err.position) + 1
    column = err.position - (text.rfind("\n", 0, err.position) + 1) + 1
    char = err.character if isinstance(err.character, int) else ord(err.character)
    return (f"line {line}, column {column}: the character U+{char:04X} is not allowed in YAML "
            "(a control character): remove it; not valid YAML")


def _yaml_error(err: yaml.YAMLError, text: str) -> str:
    if isinstance(err, yaml.MarkedYAMLError):
        return _yaml_problem(err, text)
    if isinstance(err, yaml.reader.ReaderError):
        return _reader_problem(err, text)
    return f"not valid YAML: {err}"


def _check_depth(text: str, source: str) -> None:
    """Refuse collections nested deeper than MAX_SPEC_DEPTH by scanning the parser's events, which
    PyYAML produces without recursion, before anything is composed."""
    depth = 0
    try:
        for event in yaml.parse(io.StringIO(text), Loader=_UniqueKeyLoader):
            if isinstance(event, yaml.CollectionStartEvent):
                depth += 1
                if depth > MAX_SPEC_DEPTH:
                    line = event.start_mark.line + 1 if event.start_mark is not None else 0
                    raise SpecError([f"line {line}: lists and maps nested more than {MAX_SPEC_DEPTH} deep: a spec "
                                     "is a few levels deep (see humanmpc-gen keys)"], source)
            elif isinstance(event, yaml.CollectionEndEvent):
                depth -= 1
    except yaml.YAMLError as err:
        raise SpecError([_yaml_error(err, text)], source) from None


def _parse_yaml(text: str, source: str) -> Any:
    """The YAML document in text: safe loader, duplicate keys and aliases refused, size and nesting
    bounded, errors naming the source and the line."""
    if len(text.encode("utf-8", errors="replace")) > MAX_SPEC_BYTES:
        raise SpecError([f"the spec is {len(text):,} characters long: at most {MAX_SPEC_BYTES:,} bytes"], source)
    _check_depth(text, source)
    stream = io.StringIO(text)
    stream.name = source  # PyYAML names this in its error marks
    try:
        return yaml.load(stream, Loader=_UniqueKeyLoader)
    except SpecError as err:
        raise SpecError(err.problems, source) from None
    except yaml.YAMLError as err:
        raise SpecError([_yaml_error(err, text)], source) from None


def parse_spec_text(text: str, source: str = "spec") -> Spec:
    """Parse YAML text (safe loader, duplicate keys and aliases refused) and resolve it."""
    return resolve_spec(_parse_yaml(text, source), source)


_FILE_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
               (stat.S_ISFIFO, "a pipe (FIFO)"), (stat.S_ISSOCK, "a socket"))


def read_spec_file(path: Path) -> str:
    """The text of the spec file at path, read with bounds whatever the path is: a regular file of at most
    MAX_SPEC_BYTES (at most that many bytes are read, so a file that grows or lies about its size, such as
    one under /proc, cannot exhaust memory); a device, pipe, socket or folder is refused without reading
    from it (opened non-blocking, so a FIFO without a writer cannot hang the command)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0))
    except OSError as err:
        raise SpecError([f"cannot read {path}: {err.strerror}"], str(path)) from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            kind = next((what for test, what in _FILE_KINDS if test(mode)), "not a regular file")
            raise SpecError([f"{path} is {kind}, not a spec file: give a YAML file"], str(path))
        with os.fdopen(os.dup(fd), "rb") as f:
            data = f.read(MAX_SPEC_BYTES + 1)
    except OSError as err:
        raise SpecError([f"cannot read {path}: {err.strerror}"], str(path)) from None
    finally:
        os.close(fd)
    if len(data) > MAX_SPEC_BYTES:
        raise SpecError([f"{path} is larger than {MAX_SPEC_BYTES:,} bytes, the most a spec may be"], str(path))
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise SpecError([f"{path} is not UTF-8 text: {err.reason} at byte {err.start}"], str(path)) from None


def load_spec(path: str | Path | None) -> Spec:
    """The spec in the YAML file at ``path``, or the built-in default spec when ``path`` is None."""
    if path is None:
        return Spec()
    p = Path(path)
    text = read_spec_file(p)
    data = _parse_yaml(text, str(p))
    if data is None:
        raise SpecError([f"{p} holds no keys: write at least one (e.g. name: mysolver), or give no file to use "
                         "the built-in spec"], str(p))
    return resolve_spec(data, str(p))


def describe_schema() -> list[tuple[str, str, Any]]:
    """(key path, doc, default) for every leaf key: for the CLI's help and the docs."""
    rows: list[tuple[str, str, Any]] = []

    def walk(cls: type, prefix: str) -> None:
        for f in dataclasses.fields(cls):
            path = f"{prefix}{f.name}"
            rule = f.metadata.get("rule")
            if rule is None:
                walk(cast(type, f.default_factory), f"{path}.")
            else:
                rows.append((path, rule.doc, _plain(f.default)))

    walk(Spec, "")
    return rows
