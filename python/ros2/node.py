"""The ROS 2 node: rclpy around the package's own controller (``humanmpc.load(DIR).controller()``).

Each timer period: the inputs' ages from their ``header.stamp`` (stale or future: the node's own
protective stop, a braking command, the controller not stepped), their frames (the odometry's; a scan
also the robot's), then one ``Controller.step`` and its result out as messages. Everything the robot
does is the C controller's decision; this module converts. Topics, parameters, QoS: docs/ros.md.
"""

from __future__ import annotations

import contextlib
import math
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

try:  # the ros2 extra
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import PoseStamped, Twist, TwistStamped
    from nav_msgs.msg import Odometry
    from nav_msgs.msg import Path as PathMsg
    from rcl_interfaces.msg import (
        FloatingPointRange,
        IntegerRange,
        ParameterDescriptor,
        ParameterType,
        SetParametersResult,
    )
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan, PointCloud2
    from std_msgs.msg import Header
    from visualization_msgs.msg import MarkerArray
except ImportError as err:
    raise ImportError(f"the ROS 2 node needs rclpy and the ROS 2 message packages ({err}): "
                      "pip install 'humanmpc[ros2]', or source ROS 2 Jazzy (docs/ros.md)") from None

from .. import load
from ..codegen.params import PARAMS, Param
from ..codegen.ros import NodeParam, node_stop_reason
from ..codegen.ros2 import NODE2_PARAMS, NODE2_STOP_REASONS
from ..controller import Controller
from ..status import STOP_REASONS
from . import convert

REASON = {r.name: r for r in NODE2_STOP_REASONS}
# The node's own stops by their cause, from the one table (codegen.ros.NODE_STOP_REASONS, as the ROS 1 node's):
# a name it lacks fails at import, not at the first stop.
STALE = {key: node_stop_reason(name, NODE2_STOP_REASONS).name
         for key, name in (("odom", "stale_odometry"), ("people", "stale_people"), ("scan", "stale_scan"))}
FUTURE_STAMP = node_stop_reason("future_stamp", NODE2_STOP_REASONS).name
NO_TRANSFORM = node_stop_reason("no_transform", NODE2_STOP_REASONS).name
TOO_MANY_TRACKS = node_stop_reason("too_many_tracks", NODE2_STOP_REASONS).name
LATCHED = QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
RELIABLE = QoSProfile(depth=5, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE)


def _descriptor(p: Param) -> ParameterDescriptor:
    """The ROS 2 descriptor of a controller parameter: its type, meaning, rule and (for a single number)
    its closed range."""
    d = ParameterDescriptor(description=p.described, additional_constraints=f"must be {p.rule}")
    if p.kind == "flag":
        d.type = ParameterType.PARAMETER_BOOL
    elif p.kind == "integer":
        d.type = ParameterType.PARAMETER_INTEGER
        assert p.valid is not None
        lo, hi = p.valid.lo, p.valid.hi
        if math.isfinite(lo) and math.isfinite(hi):
            d.integer_range = [IntegerRange(from_value=math.ceil(lo), to_value=math.floor(hi), step=1)]
    elif p.size > 1:
        d.type = ParameterType.PARAMETER_DOUBLE_ARRAY
    else:
        d.type = ParameterType.PARAMETER_DOUBLE
        assert p.valid is not None
        if math.isfinite(p.valid.lo) and math.isfinite(p.valid.hi):
            d.floating_point_range = [FloatingPointRange(from_value=float(p.valid.lo), to_value=float(p.valid.hi),
                                                         step=0.0)]
    return d


def _node_descriptor(q: NodeParam) -> ParameterDescriptor:
    d = ParameterDescriptor(description=f"{q.doc} [{q.unit}]" if q.unit else q.doc,
                            additional_constraints=f"must be {q.rule}", read_only=True)
    if q.kind == "flag":
        d.type = ParameterType.PARAMETER_BOOL
    else:
        d.type = ParameterType.PARAMETER_DOUBLE
        assert q.valid is not None
        d.floating_point_range = [FloatingPointRange(from_value=q.valid.lo, to_value=q.valid.hi, step=0.0)]
    return d


def _check_node_param(q: NodeParam, value: Any) -> str | None:
    if q.kind == "flag":
        return None if isinstance(value, bool) else f"{value!r} has the wrong type"
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return f"{value!r} is not a finite number"
    assert q.valid is not None
    return None if q.valid.holds(float(value)) else f"{value!r} is out of range"


def _ros_value(p: Param, value: Any) -> Any:
    """A controller parameter's value as ROS 2 types it."""
    if p.kind == "flag":
        return bool(value)
    if p.kind == "integer":
        return int(value)
    if p.size > 1:
        return [float(x) for x in value]
    return float(value)


class ParameterRefusedError(ValueError):
    pass


@dataclass
class Latest:
    """The last message of an input and its stamp [s] (None before the first)."""

    msg: Any = None
    stamp: float | None = None


class ControllerNode(Node):
    """The controller's ROS 2 node."""

    def __init__(self, name: str, controller: Controller) -> None:
        super().__init__(name)
        self.ctl = controller
        self.rows = {p.name: p for p in PARAMS}
        values = controller.params
        for q in NODE2_PARAMS:
            default = float(controller.dims.dt) if q.default is None else q.default
            self.declare_parameter(q.name, default, _node_descriptor(q))
        for p in PARAMS:
            self.declare_parameter(p.name, _ros_value(p, values[p.name]), _descriptor(p))
        self.node_params = self._read_node_params()
        self.ctl.set_params(**self._controller_values([self.get_parameter(p.name) for p in PARAMS]))
        self.add_on_set_parameters_callback(self._on_set_parameters)

        self.inputs = {k: Latest() for k in ("odom", "people", "scan")}
        self.goal: PoseStamped | None = None
        self.path: PathMsg | None = None
        self.node_stop: str | None = None
        self.announced: tuple[bool, int] | None = None
        self.command = (0.0, 0.0)
        self.t0 = time.monotonic()
        self.warned: set[str] = set()

        self.create_subscription(Odometry, "odom", lambda m: self._keep("odom", m), RELIABLE)
        self.create_subscription(PointCloud2, "people", lambda m: self._keep("people", m), RELIABLE)
        self.create_subscription(LaserScan, "scan", lambda m: self._keep("scan", m), qos_profile_sensor_data)
        self.create_subscription(PoseStamped, "goal", self._on_goal, RELIABLE)
        self.create_subscription(PathMsg, "plan", self._on_plan, RELIABLE)
        stamped = bool(self.node_params["twist_stamped"])
        self.cmd_pub = self.create_publisher(TwistStamped if stamped else Twist, "cmd_vel", RELIABLE)
        self.plan_pub = self.create_publisher(PathMsg, "~/local_plan", RELIABLE)
        self.pred_pub = self.create_publisher(MarkerArray, "~/predictions", RELIABLE)
        self.stop_pub = self.create_publisher(DiagnosticArray, "~/protective_stop", LATCHED)
        self.diag_pub = self.create_publisher(DiagnosticArray, "/diagnostics", RELIABLE)
        self.period = float(self.node_params["control_period"])
        self.timer = self.create_timer(self.period, self._tick)

    # -- parameters ---------------------------------------------------------------------------
    def _read_node_params(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for q in NODE2_PARAMS:
            value = self.get_parameter(q.name).value
            why = _check_node_param(q, value)
            if why is not None:
                raise ParameterRefusedError(f"parameter {q.name}: {why}: {q.name} must be {q.rule}")
            out[q.name] = value
        return out

    def _controller_values(self, params: Sequence[Parameter]) -> dict[str, Any]:
        return {p.name: list(p.value) if isinstance(p.value, (list, tuple)) or hasattr(p.value, "tolist")
                else p.value for p in params if p.name in self.rows}

    def _on_set_parameters(self, params: list[Parameter]) -> SetParametersResult:
        """The controller's rules (the same as Controller.set_params, which applies them): all or none."""
        for p in params:
            if p.name not in self.rows:
                return SetParametersResult(successful=False, reason=f"{p.name} is read at start only (restart "
                                           "the node to change it)")
        try:
            self.ctl.set_params(**self._controller_values(params))
        except (ValueError, KeyError) as err:
            return SetParametersResult(successful=False, reason=str(err))
        return SetParametersResult(successful=True)

    def set_parameters_atomically(self, parameter_list: list[Parameter]) -> SetParametersResult:
        """The parameter services' entry: the controller's rule is checked before rclpy's range check,
        so a refusal names the rule (rclpy's own says only the range)."""
        problems = []
        for p in parameter_list:
            row = self.rows.get(p.name)
            if row is None or p.type_ == Parameter.Type.NOT_SET:
                continue
            value = self._controller_values([p])[p.name]
            _, why = row.check(value)
            if why is not None:
                problems.append(f"{p.name}: {why}: {row.name} must be {row.rule}")
        if problems:
            return SetParametersResult(successful=False, reason="invalid runtime parameter(s), none changed:\n  - "
                                       + "\n  - ".join(problems))
        return super().set_parameters_atomically(parameter_list)

    # -- inputs -------------------------------------------------------------------------------
    def _keep(self, key: str, msg: Any) -> None:
        self.inputs[key] = Latest(msg, convert.stamp_seconds(msg.header.stamp))

    def _on_goal(self, msg: PoseStamped) -> None:
        self.goal, self.path = msg, None

    def _on_plan(self, msg: PathMsg) -> None:
        self.goal, self.path = None, (msg if msg.poses else None)

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _age_problem(self, key: str, now: float, timeout: float, required: bool) -> tuple[str, str] | None:
        """(reason, detail) when the input ``key`` is stale, missing while required, or from the future."""
        latest = self.inputs[key]
        stale = STALE[key]
        if latest.stamp is None:
            return (stale, f"no {key} yet") if required else None
        age = now - latest.stamp
        if latest.stamp == 0.0 or age > timeout:
            return stale, f"{key} stamped {age:.3f} s ago (timeout {timeout:g} s)"
        if -age > float(self.node_params["stamp_tolerance"]):
            return FUTURE_STAMP, f"{key} stamped {-age:.3f} s ahead of the node's clock"
        return None

    def _check_inputs(self, now: float) -> tuple[str, str] | None:
        np_ = self.node_params
        return (self._age_problem("odom", now, np_["odom_timeout"], True)
                or self._age_problem("people", now, np_["people_timeout"], bool(np_["require_people"]))
                or self._age_problem("scan", now, np_["scan_timeout"], bool(np_["require_scan"])))

    def _frames(self, odom: Odometry) -> str | None:
        """None when every input is in a frame the node can use, else what is not."""
        frame = odom.header.frame_id
        for key, msg in (("goal", self.goal), ("plan", self.path), ("people", self.inputs["people"].msg)):
            if msg is not None and msg.header.frame_id != frame:
                return f"{key} is in frame {msg.header.frame_id!r}, the odometry in {frame!r}"
        scan = self.inputs["scan"].msg
        if scan is not None and scan.header.frame_id not in (frame, odom.child_frame_id):
            return (f"scan is in frame {scan.header.frame_id!r}, neither the odometry's {frame!r} nor the robot's "
                    f"{odom.child_frame_id!r}")
        return None

    # -- one period ---------------------------------------------------------------------------
    def _tick(self) -> None:
        start = time.perf_counter()
        now = self._now()
        header = Header(stamp=self.get_clock().now().to_msg())
        problem = self._check_inputs(now)
        odom = self.inputs["odom"].msg
        if problem is None:
            header.frame_id = odom.header.frame_id
            frames = self._frames(odom)
            if frames is not None:
                problem = (NO_TRANSFORM, frames)
        if problem is None:
            try:
                result = self._step(odom, now)
            except convert.MessageError as err:
                problem = (err.reason, str(err))
        if problem is not None:
            self._node_brake(header, *problem)
            values: dict[str, Any] = {"node_stop": problem[0], "detail": problem[1]}
            stop, code, name, message = True, REASON[problem[0]].value, problem[0], REASON[problem[0]].message
        else:
            if self.node_stop is not None:
                self.node_stop = None
            v, w = (float(x) for x in result.command)
            self.command = (v, w)
            self._publish_cmd(header, v, w)
            values = self._result_values(result)
            stop, code = bool(result.stop), int(result.stop_reason)
            name = result.reason or "none"
            message = result.outcome_name if not stop else f"protective stop: {name}"
            if self.plan_pub.get_subscription_count():
                self.plan_pub.publish(convert.plan_path(header, result.plan))
            if self.pred_pub.get_subscription_count():
                self.pred_pub.publish(convert.prediction_markers(header, result.people_ids, result.predictions,
                                                                 float(self.ctl.params["d_h"])))
        cycle_ms = 1e3 * (time.perf_counter() - start)
        if (stop, code) != self.announced:
            self.announced = (stop, code)
            self.stop_pub.publish(convert.status(header, "protective_stop", convert.WARN if stop else convert.OK,
                                                 message, {"stop": stop, "reason": code, "reason_name": name}))
        values.update(cycle_ms=f"{cycle_ms:.3f}", stop=stop, stop_reason=name,
                      odom_age_s=self._age(now, "odom"), people_age_s=self._age(now, "people"),
                      scan_age_s=self._age(now, "scan"))
        self.diag_pub.publish(convert.status(header, f"{self.get_name()}: controller",
                                             convert.WARN if stop else convert.OK, message, values,
                                             hardware_id=self.ctl.name))

    def _age(self, now: float, key: str) -> str:
        s = self.inputs[key].stamp
        return "none" if s is None else f"{now - s:.3f}"

    def _step(self, odom: Odometry, now: float) -> Any:
        if self.node_stop is not None:
            self.ctl.reset()  # the inputs are back: a cold start
        pose, v, w = convert.odometry_state(odom)
        people = ids = cov = None
        if self.inputs["people"].msg is not None:
            people, ids, cov = convert.people_arrays(self.inputs["people"].msg)
            if len(people) > convert.MAX_PEOPLE:
                raise convert.MessageError(f"{len(people)} tracks in one message, more than {convert.MAX_PEOPLE}",
                                           reason=TOO_MANY_TRACKS)
        obstacles = None
        scan = self.inputs["scan"].msg
        if scan is not None:
            pts = convert.scan_points(scan)
            if scan.header.frame_id != odom.header.frame_id:
                pts = convert.to_frame(pts, pose)
            obstacles = convert.nearest(pts, pose, self.ctl.max_obstacle_points)
        goal = convert.pose_of(self.goal) if self.goal is not None else None
        path = convert.path_points(self.path, self.ctl.max_path_points) if self.path is not None else None
        return self.ctl.step(now - self._t_origin(now), pose, v, w, path=path, goal=goal, people=people, ids=ids,
                             covariances=cov, obstacles=obstacles)

    def _t_origin(self, now: float) -> float:
        if not hasattr(self, "_origin"):
            self._origin = now
        return self._origin

    def _node_brake(self, header: Header, reason: str, detail: str) -> None:
        """The node's own stop: the speed falls towards 0 per period by the acceleration bound that brakes in
        its direction (a_bounds[0] moving forward, a_bounds[1] reversing), no turning."""
        if self.node_stop != reason:
            self.get_logger().warn(f"{REASON[reason].message}: {detail}")
        self.node_stop = reason
        a_lo, a_hi = (float(a) for a in self.ctl.params["a_bounds"])
        v = self.command[0]
        v = max(0.0, v + a_lo * self.period) if v >= 0.0 else min(0.0, v + a_hi * self.period)
        self.command = (v, 0.0)
        self._publish_cmd(header, v, 0.0)

    def _publish_cmd(self, header: Header, v: float, w: float) -> None:
        t = Twist()
        t.linear.x, t.angular.z = v, w
        if self.node_params["twist_stamped"]:
            msg = TwistStamped()
            msg.header = Header(stamp=header.stamp, frame_id=self._base_frame())
            msg.twist = t
            self.cmd_pub.publish(msg)
        else:
            self.cmd_pub.publish(t)

    def _base_frame(self) -> str:
        odom = self.inputs["odom"].msg
        return odom.child_frame_id if odom is not None else ""

    @staticmethod
    def _result_values(r: Any) -> dict[str, Any]:
        return {"outcome": r.outcome_name, "command_v": f"{r.command[0]:.4f}", "command_omega": f"{r.command[1]:.4f}",
                "goal_reached": r.goal_reached, "stalled": r.stalled, "people_used": r.n_people,
                "tracks_dropped": r.n_tracks_dropped, "solver_status": r.status_name,
                "distance_to_goal_m": f"{r.distance_to_goal:.3f}",
                "min_human_distance_m": f"{r.min_human_distance:.3f}", "time_total_ms": f"{r.time_ms:.3f}"}


def main(solver_dir: str | Path, params_file: str | Path | None = None, node_name: str = "humanmpc_controller",
         spec_hash: str | None = None, argv: Sequence[str] | None = None) -> int:
    """Run the node until SIGINT / SIGTERM; 1 (with the message) for a broken parameter or solver."""
    args = list(sys.argv[1:] if argv is None else argv)
    ros_args = ["--ros-args", "--params-file", str(params_file)] if params_file is not None else []
    try:
        solver = load(solver_dir, build_if_needed=False)
    except Exception as err:
        print(f"{node_name}: cannot load the solver in {solver_dir}: {err}", file=sys.stderr)
        return 1
    if spec_hash is not None and getattr(solver, "spec_hash", spec_hash) != spec_hash:
        print(f"{node_name}: the solver in {solver_dir} is not the one this node was generated for", file=sys.stderr)
        return 1
    rclpy.init(args=[sys.argv[0], *ros_args, *args])
    try:
        try:
            node = ControllerNode(node_name, solver.controller())
        except (ParameterRefusedError, ValueError, KeyError) as err:
            print(f"{node_name}: {err}", file=sys.stderr)
            return 1
        except rclpy.exceptions.InvalidParameterValueException as err:
            print(f"{node_name}: {err}", file=sys.stderr)
            return 1
        with contextlib.suppress(KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
            rclpy.spin(node)
        node.destroy_node()
    finally:
        if rclpy.ok():
            rclpy.shutdown()
    return 0


__all__ = ["STOP_REASONS", "ControllerNode", "main"]
