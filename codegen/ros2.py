"""The ROS 2 face of a generated solver: ``humanmpc-gen ros2 DIR`` (docs/ros.md, "ROS 2").

``write_ros2(SOLVER_DIR, OUT)`` writes, atomically, a folder that runs the rclpy node
(``humanmpc.ros2.node``) over a copy of the built solver through the package's own cffi face:

    OUT/humanmpc_ros2.json        what humanmpc wrote (solver name, spec hash): --force replaces only such a folder
    OUT/<name>_node.py            the node's launcher: the wheels' environment, then humanmpc.ros2.node
    OUT/config/<name>.yaml        every parameter (the node's and the controller's) with its value and rule
    OUT/launch/<name>.launch.py   for a robot with ROS 2's launch (not on PyPI)
    OUT/solver/                   a copy of the generated and built package

The node converts messages into the controller's arrays and its result back into messages; the
navigation is the C controller's. This module holds the node's tables (its own parameters and stop
reasons), shared by the generator and the node.
"""

from __future__ import annotations

import dataclasses
import json
import shutil
from pathlib import Path
from typing import Any

from . import __version__
from .build import is_stale, library_path
from .generate import GenerateError, write_atomically, write_files
from .params import PARAMS, Range, spec_params
from .render import c_identifier, make_environment
from .ros import NODE_PARAMS, NODE_STOP_REASONS, NodeParam, NodeStopReason, solver_spec, yaml_float
from .spec import Spec

ROS2_MARKER = "humanmpc_ros2.json"

# The ROS 1 node's stop reasons, the frame's reworded: without tf2 this node takes its inputs in the
# odometry frame (or the robot's, for a scan) and stops on any other.
NODE2_STOP_REASONS: tuple[NodeStopReason, ...] = tuple(
    dataclasses.replace(r, message="protective stop (node): an input is in another frame than the odometry's "
                        "(a scan: or the robot's); this node has no tf2") if r.name == "no_transform" else r
    for r in NODE_STOP_REASONS)

# The ROS 1 node's own parameters without the tf2 wait, and the choice of command message.
NODE2_PARAMS: tuple[NodeParam, ...] = (
    *(q for q in NODE_PARAMS if q.name != "transform_timeout"),
    NodeParam("twist_stamped", "flag", False,
              "true: cmd_vel is a geometry_msgs/TwistStamped (stamped in the base frame), false: a Twist"),
)


def node2_param(name: str) -> NodeParam:
    return next(q for q in NODE2_PARAMS if q.name == name)


def ros2_node_name(solver_name: str) -> str:
    return f"{c_identifier(solver_name).lower()}_controller"


def _yaml2(value: Any, kind: str) -> str:
    """A parameter value as ROS 2's parameter file types it (a real always with a point)."""
    if kind == "flag":
        return "true" if bool(value) else "false"
    if kind == "integer":
        return str(int(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(yaml_float(float(x)) for x in value) + "]"
    return yaml_float(float(value))


def _comment(text: str) -> str:
    return " ".join(text.split()).replace("\n", " ")


def ros2_context(spec: Spec) -> dict[str, Any]:
    name = c_identifier(spec.name)
    values = spec_params(spec)
    params = [{"name": c_identifier(p.name), "yaml": _yaml2(values[p.name], p.kind),
               "doc": _comment(f"{p.described}; must be {p.rule}")} for p in PARAMS]
    node_params = []
    for q in NODE2_PARAMS:
        default = spec.dt if q.default is None else q.default
        unit = f" [{q.unit}]" if q.unit else ""
        node_params.append({"name": c_identifier(q.name), "yaml": _yaml2(default, q.kind),
                            "doc": _comment(f"{q.doc}{unit}; must be {q.rule}")})
    return {"name": name, "node": ros2_node_name(name), "version": __version__, "spec_hash": spec.digest(),
            "params": params, "node_params": node_params}


ROS2_TEMPLATES = {
    "node.py.j2": "{name}_node.py",
    "params.yaml.j2": "config/{name}.yaml",
    "launch.py.j2": "launch/{name}.launch.py",
}


def render_ros2(context: dict[str, Any]) -> dict[str, str]:
    env = make_environment()
    return {out.format(name=context["name"]): env.get_template(f"ros2/{tpl}").render(**context)
            for tpl, out in ROS2_TEMPLATES.items()}


def _populate(solver_dir: Path, spec: Spec, out: Path) -> None:
    context = ros2_context(spec)
    write_files(out, render_ros2(context))
    (out / f"{context['name']}_node.py").chmod(0o755)
    shutil.copytree(solver_dir, out / "solver", symlinks=True)
    (out / ROS2_MARKER).write_text(json.dumps({
        "generator": "humanmpc", "generator_version": __version__, "solver": spec.name,
        "spec_hash": spec.digest(), "node": context["node"]}, indent=2) + "\n")


def default_ros2_dir(solver_dir: Path, spec: Spec) -> Path:
    """Beside the solver: <solver_dir's parent>/<name>_ros2."""
    return solver_dir.resolve().parent / f"{c_identifier(spec.name).lower()}_ros2"


def write_ros2(solver_dir: str | Path, out_dir: str | Path | None = None, *, force: bool = False) -> Path:
    """Write the ROS 2 node folder of the generated, built solver in ``solver_dir``; return its folder."""
    d = Path(solver_dir).resolve()
    spec = solver_spec(d)
    if not library_path(d).is_file() or is_stale(d):
        raise GenerateError(f"{d} holds no up-to-date library: the ROS 2 node loads the built solver, so build it "
                            f"first (humanmpc-gen build {d})")
    dest = Path(out_dir) if out_dir is not None else default_ros2_dir(d, spec)
    if dest.resolve() == d or d in dest.resolve().parents:
        raise GenerateError(f"{dest}: the ROS 2 node goes beside the solver folder {d}, not inside it")
    write_atomically(dest, lambda tmp: _populate(d, spec, tmp), force, marker=ROS2_MARKER)
    return dest.resolve()


__all__ = ["NODE2_PARAMS", "NODE2_STOP_REASONS", "ROS2_MARKER", "Range", "ros2_node_name", "write_ros2"]
