"""The ROS 1 face of a generated solver: a catkin package set beside it (docs/ros.md).

``write_ros(SOLVER_DIR, OUT)`` writes into OUT, a folder to put into a catkin workspace's src/:

    OUT/humanmpc_ros.json        what humanmpc wrote (solver name, spec hash): --force replaces only such a folder
    OUT/humanmpc_msgs/           the messages: TrackedPerson(s) in, ProtectiveStop out
    OUT/<name>_ros/              the node: src/<name>_node.cpp over the C controller, launch/, config/,
                                 solver/ (a copy of the generated C package, compiled by the node's CMakeLists)

The node only converts messages into ``<name>_controller_input`` and the output into messages; the
navigation is the C controller's. Everything printed into C++ comes from the solver's validated spec,
the parameter table and the status table, through ``c_identifier`` / ``c_float`` / ``_c_string``.
"""

from __future__ import annotations

import json
import re
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import __version__
from .build import BuildError, read_manifest
from .generate import GenerateError, write_atomically, write_files
from .params import PARAMS, Range, spec_params
from .render import _c_string, c_float, c_identifier, make_environment
from .spec import Spec, SpecError, load_spec
from .status import status_tables

ROS_MARKER = "humanmpc_ros.json"
MSGS_PACKAGE = "humanmpc_msgs"
# REP 144: a package name is lower case letters, digits and underscores, starting with a letter.
_ROS_PACKAGE = re.compile(r"[a-z][a-z0-9_]*")
# The solver's files the package copies: everything but the build folders.
_BUILD_DIRS = ("build", "build-cmake")


@dataclass(frozen=True)
class NodeStopReason:
    """A stop reason of the node's own, above the controller's (docs/ros.md)."""

    id: str
    value: int
    name: str
    message: str


# The node's own stop reasons: what the controller cannot see (the age, the stamps and the frames of its
# inputs, and a message beyond the node's buffers).
NODE_STOP_REASONS = (
    NodeStopReason("STOP_STALE_ODOMETRY", 100, "stale_odometry",
                   "protective stop (node): no odometry stamped within odom_timeout"),
    NodeStopReason("STOP_STALE_PEOPLE", 101, "stale_people",
                   "protective stop (node): no tracked people stamped within people_timeout"),
    NodeStopReason("STOP_NO_TRANSFORM", 102, "no_transform",
                   "protective stop (node): no tf2 transform of the path, goal, people or scan into the "
                   "odometry frame"),
    NodeStopReason("STOP_STALE_SCAN", 103, "stale_scan",
                   "protective stop (node): the last scan is stamped more than scan_timeout ago"),
    NodeStopReason("STOP_FUTURE_STAMP", 104, "future_stamp",
                   "protective stop (node): an input is stamped more than stamp_tolerance ahead of the node's "
                   "clock (clocks out of step)"),
    NodeStopReason("STOP_TOO_MANY_TRACKS", 105, "too_many_tracks",
                   "protective stop (node): a people message holds more tracks than the node's buffer"),
)



def node_stop_reason(name: str, table: tuple[NodeStopReason, ...] = NODE_STOP_REASONS) -> NodeStopReason:
    """The row of the node's stop reason ``name`` (a KeyError naming the table's reasons otherwise): how the
    nodes' code names a reason, so that the table is the only place its value and message are written."""
    for r in table:
        if r.name == name:
            return r
    raise KeyError(f"no node stop reason {name!r}; the table has {', '.join(r.name for r in table)}")


# The most tracks one people message may hold (the node's buffer; the controller keeps the nearest
# max_tracks of them). More is not a crowd but a broken tracker: a protective stop, too_many_tracks.
NODE_MAX_TRACKS = 1024


@dataclass(frozen=True)
class NodeParam:
    """A private parameter of the node's own (docs/ros.md), checked at start like the controller's."""

    name: str
    kind: str                  # "real" or "flag"
    default: float | bool | None  # None: the spec's control period
    doc: str
    unit: str = ""
    valid: Range | None = None
    period_share: float = 0.0  # > 0: also at most this share of control_period

    @property
    def rule(self) -> str:
        if self.kind == "flag":
            return "true or false"
        assert self.valid is not None
        text = f"a number with {self.valid.text(self.name)}"
        if self.period_share:
            text += f" and {self.name} <= {self.period_share:g} * control_period"
        return text


_TIMEOUT = Range(0.0, 10.0, lo_open=True)

# Checked in this order: control_period first, since a rule below depends on it.
NODE_PARAMS = (
    NodeParam("control_period", "real", None, "the timer; by default the spec's T / N", "s",
              Range(0.0, 1.0, lo_open=True)),
    NodeParam("odom_timeout", "real", 0.5, "odometry stamped longer ago: protective stop stale_odometry", "s",
              _TIMEOUT),
    NodeParam("people_timeout", "real", 0.5, "tracked people stamped longer ago: protective stop stale_people", "s",
              _TIMEOUT),
    NodeParam("require_people", "flag", True,
              "false: run without a people tracker until its first message (then as true)"),
    NodeParam("scan_timeout", "real", 0.5, "a scan stamped longer ago: protective stop stale_scan", "s", _TIMEOUT),
    NodeParam("require_scan", "flag", False, "true: no scan yet is a protective stop stale_scan too"),
    NodeParam("stamp_tolerance", "real", 0.05,
              "an input stamped further ahead of the node's clock: protective stop future_stamp", "s",
              Range(0.0, 1.0)),
    NodeParam("transform_timeout", "real", 0.0,
              "how long a tf2 lookup waits for the transform at a message's stamp (else the latest is used); "
              "up to three lookups a period, each delays the command", "s", Range(0.0, 1.0), period_share=0.25),
)


def ros_package_name(solver_name: str) -> str:
    """The node's catkin package: <name>_ros in lower case (REP 144)."""
    package = f"{c_identifier(solver_name).lower()}_ros"
    if not _ROS_PACKAGE.fullmatch(package):
        raise GenerateError(f"{package!r} is not a ROS package name (REP 144: [a-z][a-z0-9_]*)")
    return package


def yaml_float(x: float) -> str:
    """A float as YAML 1.1 (rosparam's PyYAML) reads it back as a float: 1e-06 would be a string."""
    text = c_float(x)
    mantissa, e, exponent = text.partition("e")
    if e and "." not in mantissa:
        text = f"{mantissa}.0e{exponent}"
    return text


def _yaml_value(value: Any, ctype: str) -> str:
    if ctype == "int":
        return str(int(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(yaml_float(float(x)) for x in value) + "]"
    return yaml_float(float(value))


def ros_context(spec: Spec) -> dict[str, Any]:
    """What the ROS templates print, each item checked as it enters C++ or YAML."""
    name = c_identifier(spec.name)
    values = spec_params(spec)
    tables = status_tables()
    codes = {r.value for r in tables["stop_reason"]}
    for r in NODE_STOP_REASONS:
        if r.value in codes:
            raise GenerateError(f"the node's stop reason {r.name} = {r.value} is a value of the controller's "
                                "stop reasons (runtime/hm_status.h): renumber it in humanmpc.codegen.ros")
    params = [
        {
            "c_name": c_identifier(p.name),
            "c_type": "int" if p.ctype == "int" else f"{name}_real",
            "size": p.size,
            "yaml": _yaml_value(values[p.name], p.ctype),
            "doc": _c_string(f"{p.described}; must be {p.rule}"),
            "kind": p.kind if p.ctype == "int" else "real",
            "rule": _c_string(f"{p.name} must be {p.rule}"),
            "controller": p.controller,   # a field of <name>_controller_params, not of <name>_params
        }
        for p in PARAMS
    ]
    node_params = []
    for q in NODE_PARAMS:
        default = spec.dt if q.default is None else q.default
        row: dict[str, Any] = {
            "c_name": c_identifier(q.name),
            "kind": q.kind,
            "rule": _c_string(f"{q.name} must be {q.rule}" + (f" [{q.unit}]" if q.unit else "")),
            "doc": _c_string(f"[{q.unit}] {q.doc}" if q.unit else q.doc),
        }
        if q.kind == "flag":
            row.update(yaml="true" if default else "false", cpp="true" if default else "false")
        else:
            assert q.valid is not None
            row.update(yaml=yaml_float(float(default)), cpp=c_float(float(default)),
                       lo=c_float(q.valid.lo), hi=c_float(q.valid.hi), lo_open=q.valid.lo_open,
                       hi_open=q.valid.hi_open, period_share=c_float(q.period_share), share=q.period_share > 0)
        node_params.append(row)

    def rows(key: str) -> list[dict[str, Any]]:
        return [{"value": int(r.value), "name": c_identifier(r.name), "message": _c_string(r.message)}
                for r in tables[key]]

    return {
        "name": name,
        "NAME": name.upper(),
        "package": ros_package_name(name),
        "version": __version__,
        "spec_hash": spec.digest(),
        "N": int(spec.horizon.N),
        "NT": int(spec.controller.max_tracks),
        "MAX_PATH_POINTS": int(spec.controller.max_path_points),
        "NK": int(spec.controller.max_obstacle_points),
        "dt": c_float(spec.dt),
        "params": params,
        "node_params": node_params,
        "node_max_tracks": NODE_MAX_TRACKS,
        "stop_reasons": rows("stop_reason"),
        "outcomes": rows("outcome"),
        "node_reasons": [{"id": c_identifier(r.id), "value": int(r.value), "name": c_identifier(r.name),
                          "message": _c_string(r.message)} for r in NODE_STOP_REASONS],
    }


# template (templates/ros/) -> path in OUT ({package}, {name} filled in)
ROS_TEMPLATES = {
    "msgs_package.xml.j2": f"{MSGS_PACKAGE}/package.xml",
    "msgs_CMakeLists.txt.j2": f"{MSGS_PACKAGE}/CMakeLists.txt",
    "TrackedPerson.msg.j2": f"{MSGS_PACKAGE}/msg/TrackedPerson.msg",
    "TrackedPersons.msg.j2": f"{MSGS_PACKAGE}/msg/TrackedPersons.msg",
    "ProtectiveStop.msg.j2": f"{MSGS_PACKAGE}/msg/ProtectiveStop.msg",
    "package.xml.j2": "{package}/package.xml",
    "CMakeLists.txt.j2": "{package}/CMakeLists.txt",
    "node.cpp.j2": "{package}/src/{name}_node.cpp",
    "node.launch.j2": "{package}/launch/{name}.launch",
    "params.yaml.j2": "{package}/config/{name}.yaml",
}


def render_ros(context: dict[str, Any]) -> dict[str, str]:
    """Relative path -> rendered text, for every ROS template."""
    env = make_environment()
    return {out.format(package=context["package"], name=context["name"]):
            env.get_template(f"ros/{tpl}").render(**context) for tpl, out in ROS_TEMPLATES.items()}


def solver_spec(solver_dir: Path) -> Spec:
    """The spec of a generated solver folder: its spec.yaml, checked against its manifest's hash."""
    try:
        manifest = read_manifest(solver_dir)
    except BuildError as err:
        raise GenerateError(str(err)) from None
    spec_file = solver_dir / "spec.yaml"
    if not spec_file.is_file():
        raise GenerateError(f"{spec_file} is missing: regenerate the solver with humanmpc-gen generate")
    try:
        spec = load_spec(spec_file)
    except SpecError as err:
        raise GenerateError(f"{spec_file}: {err}") from None
    if manifest.spec_hash != spec.digest():
        raise GenerateError(f"{spec_file} does not hold the spec of {solver_dir / 'manifest.json'} (spec_hash "
                            f"{manifest.spec_hash}, spec.yaml's {spec.digest()}): regenerate the solver")
    return spec


def _populate(solver_dir: Path, spec: Spec, out: Path) -> None:
    context = ros_context(spec)
    write_files(out, render_ros(context))
    shutil.copytree(solver_dir, out / context["package"] / "solver",
                    ignore=lambda d, names: [n for n in names if Path(d) == solver_dir and n in _BUILD_DIRS])
    (out / ROS_MARKER).write_text(json.dumps({
        "generator": "humanmpc",
        "generator_version": __version__,
        "solver": spec.name,
        "spec_hash": spec.digest(),
        "packages": [MSGS_PACKAGE, context["package"]],
    }, indent=2) + "\n")


def default_ros_dir(solver_dir: Path, spec: Spec) -> Path:
    """Beside the solver: <solver_dir's parent>/<name>_ros_src."""
    return solver_dir.resolve().parent / f"{ros_package_name(spec.name)}_src"


def write_ros(solver_dir: str | Path, out_dir: str | Path | None = None, *, force: bool = False) -> Path:
    """Write the ROS package set of the generated solver in ``solver_dir``; return its folder."""
    d = Path(solver_dir).resolve()
    spec = solver_spec(d)
    dest = Path(out_dir) if out_dir is not None else default_ros_dir(d, spec)
    if dest.resolve() == d or d in dest.resolve().parents:
        raise GenerateError(f"{dest}: the ROS packages go beside the solver folder {d}, not inside it")
    write_atomically(dest, lambda tmp: _populate(d, spec, tmp), force, marker=ROS_MARKER)
    return dest.resolve()
