"""The world of tests/test_ros2.py, in its own process: a simulated robot and crowd over real DDS.

It integrates the node's cmd_vel as a base would (humanmpc.sim.robot, within the acceleration bounds),
walks a social-force crowd of 30 people (humanmpc.sim.crowd), publishes odometry, the people (a
PointCloud2, humanmpc.ros2.convert's form) and a 360-beam scan of a wall in the robot's frame, and
drives a script; what it saw goes to a JSON file for the test to judge:

1. goal A among the walking crowd; on the way a person steps 0.3 m beside the robot (d_h 0.5) for 1 s;
2. a parameter out of range (d_h = -1) through the parameter service: refused, the reason kept; then
   speed_limit lowered to 0.3 m/s through it;
3. goal B (slower now); on the way odometry stops for 1.5 s;
4. goal B reached.

Usage: sim_node.py NODE_NAME SUMMARY_JSON
"""

from __future__ import annotations

import json
import math
import sys
import time

from humanmpc.ros2.env import reexec_with_ros_env

reexec_with_ros_env()

import numpy as np  # noqa: E402
import rclpy  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import PoseStamped, Twist  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue  # noqa: E402
from rcl_interfaces.srv import SetParameters  # noqa: E402
from rclpy.qos import qos_profile_sensor_data  # noqa: E402
from sensor_msgs.msg import LaserScan  # noqa: E402
from std_msgs.msg import Header  # noqa: E402

from humanmpc.ros2 import convert  # noqa: E402
from humanmpc.ros2.node import LATCHED, RELIABLE  # noqa: E402
from humanmpc.sim.crowd import Crowd, CrowdSpec  # noqa: E402
from humanmpc.sim.robot import RobotLimits, RobotModel  # noqa: E402
from humanmpc.sim.robot import step as robot_step  # noqa: E402
from humanmpc.sim.social_force import SocialForceParams  # noqa: E402
from humanmpc.sim.world import Polygon, World  # noqa: E402

SIM_DT = 0.02
GOAL_A = (7.0, 0.0)
GOAL_B = (1.0, 0.5)
INTRUDER = 1000
WALL = World(obstacles=(Polygon.rectangle((4.0, -1.6), 14.0, 0.2),), bounds=(-5.0, 13.0, -5.0, 12.0))


class Sim:
    def __init__(self, node_name: str) -> None:
        self.node = rclpy.create_node("humanmpc_sim")
        n = self.node
        self.odom_pub = n.create_publisher(Odometry, "odom", RELIABLE)
        self.people_pub = n.create_publisher(convert.PointCloud2, "people", RELIABLE)
        self.scan_pub = n.create_publisher(LaserScan, "scan", qos_profile_sensor_data)
        self.goal_pub = n.create_publisher(PoseStamped, "goal", RELIABLE)
        n.create_subscription(Twist, "cmd_vel", self.on_cmd, RELIABLE)
        n.create_subscription(DiagnosticArray, f"/{node_name}/protective_stop", self.on_stop, LATCHED)
        n.create_subscription(DiagnosticArray, "/diagnostics", self.on_diag, RELIABLE)
        self.set_params = n.create_client(SetParameters, f"/{node_name}/set_parameters")
        self.model = RobotModel(RobotLimits(v_min=0.0, v_max=1.0, a_min=-1.0, a_max=1.0, omega_min=-1.0,
                                            omega_max=1.0))
        self.x = np.zeros(4)
        self.cmd = np.zeros(2)
        self.cmds: list[tuple[float, float, float]] = []     # (sim time, v, omega)
        self.stops: list[tuple[float, bool, str]] = []       # (sim time, stop, reason_name)
        self.diags: list[dict[str, str]] = []
        self.t = 0.0
        rng = np.random.default_rng(0)
        k = 30
        start = np.column_stack([rng.uniform(-1.0, 9.0, k), rng.uniform(2.0, 8.0, k)])
        ends = start + np.column_stack([rng.choice([-4.0, 4.0], k), np.zeros(k)])
        walks = [np.vstack([e, s]) for s, e in zip(start, ends, strict=True)]
        self.crowd = Crowd(CrowdSpec.build(start, walks, 0.8, loop=True),
                           world=World(bounds=(-10.0, 15.0, -10.0, 15.0)), params=SocialForceParams(dt=0.1))
        self.intruder: np.ndarray | None = None
        self.odom_on = True
        self.angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
        self.steps = 0

    def on_cmd(self, msg: Twist) -> None:
        self.cmd = np.array([msg.linear.x, msg.angular.z])
        self.cmds.append((self.t, msg.linear.x, msg.angular.z))

    def on_stop(self, msg: DiagnosticArray) -> None:
        kv = {v.key: v.value for v in msg.status[0].values}
        self.stops.append((self.t, kv["stop"] == "True", kv["reason_name"]))

    def on_diag(self, msg: DiagnosticArray) -> None:
        for st in msg.status:
            if st.hardware_id:
                self.diags.append({kv.key: kv.value for kv in st.values} | {"t": f"{self.t:.3f}"})

    def header(self, frame: str) -> Header:
        return Header(stamp=self.node.get_clock().now().to_msg(), frame_id=frame)

    def tick(self) -> None:
        """One 20 ms step of the world, paced to the wall clock."""
        a = float(np.clip((self.cmd[0] - self.x[3]) / SIM_DT, -1.0, 1.0))
        self.x = robot_step(self.model, self.x, [a, float(self.cmd[1])], SIM_DT)
        self.t += SIM_DT
        self.steps += 1
        if self.odom_on:
            o = Odometry(header=self.header("odom"), child_frame_id="base_link")
            o.pose.pose.position.x, o.pose.pose.position.y = float(self.x[0]), float(self.x[1])
            o.pose.pose.orientation = convert.quaternion_of(float(self.x[2]))
            o.twist.twist.linear.x, o.twist.twist.angular.z = float(self.x[3]), float(self.cmd[1])
            self.odom_pub.publish(o)
        if self.steps % 5 == 0:
            self.crowd.step(self.x[:2], self.x[3] * np.array([math.cos(self.x[2]), math.sin(self.x[2])]))
            pos, vel, ids = self.crowd.positions, self.crowd.velocities, np.asarray(self.crowd.ids)
            if self.intruder is not None:
                pos, vel = np.vstack([pos, self.intruder]), np.vstack([vel, np.zeros(2)])
                ids = np.append(ids, INTRUDER)
            tracks = np.column_stack([pos, vel])
            cov = np.tile([0.01, 0.0, 0.01], (len(tracks), 1))
            self.people_pub.publish(convert.people_cloud(self.header("odom"), tracks, ids, cov))
            self.publish_scan()
        rclpy.spin_once(self.node, timeout_sec=0.0)

    def publish_scan(self) -> None:
        x, y, th, _ = self.x
        d = np.column_stack([np.cos(self.angles + th), np.sin(self.angles + th)])
        t = np.zeros(len(self.angles))
        for _ in range(40):
            s = WALL.signed_distance(np.array([x, y]) + t[:, None] * d)
            t = np.where((s > 1e-3) & (t <= 8.0), t + np.maximum(s, 1e-3), t)
        m = LaserScan(header=self.header("base_link"))
        m.angle_min, m.angle_max = float(self.angles[0]), float(self.angles[-1])
        m.angle_increment = float(self.angles[1] - self.angles[0])
        m.range_min, m.range_max = 0.05, 8.0
        m.ranges = [float(r) if r <= 8.0 else math.inf for r in t]
        self.scan_pub.publish(m)

    def goal(self, g: tuple[float, float]) -> None:
        m = PoseStamped(header=self.header("odom"))
        m.pose.position.x, m.pose.position.y = g
        m.pose.orientation.w = 1.0
        self.goal_pub.publish(m)

    def run_until(self, done, limit: float) -> bool:  # type: ignore[no-untyped-def]
        end = self.t + limit
        wall = time.monotonic()
        while self.t < end:
            self.tick()
            if done():
                return True
            wall += SIM_DT
            time.sleep(max(0.0, wall - time.monotonic()))
        return False

    def near(self, g: tuple[float, float], tol: float = 0.3) -> bool:
        return math.hypot(self.x[0] - g[0], self.x[1] - g[1]) < tol and abs(self.x[3]) < 0.05

    def set_param(self, name: str, value: float) -> tuple[bool, str]:
        req = SetParameters.Request()
        req.parameters = [Parameter(name=name, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE,
                                                                    double_value=value))]
        fut = self.set_params.call_async(req)
        self.run_until(fut.done, 5.0)
        res = fut.result().results[0]
        return bool(res.successful), str(res.reason)


def main() -> int:
    node_name, out = sys.argv[1], sys.argv[2]
    rclpy.init()
    sim = Sim(node_name)
    s: dict = {}
    # wait for the node (its latched stop topic) and publish the goal until it is heard
    sim.run_until(lambda: bool(sim.stops) and sim.set_params.service_is_ready(), 20.0)
    sim.goal(GOAL_A)
    t_goal = sim.t
    stepped = {"in": None}

    def phase_a() -> bool:
        if sim.intruder is None and stepped["in"] is None and sim.x[0] > 2.5:
            c, sn = math.cos(sim.x[2]), math.sin(sim.x[2])
            sim.intruder = sim.x[:2] + 0.3 * np.array([-sn, c])
            stepped["in"] = sim.t
            s["v_at_intruder"] = float(sim.cmd[0])
        if stepped["in"] is not None and sim.intruder is not None and sim.t - stepped["in"] > 1.0:
            sim.intruder = None
        return sim.near(GOAL_A)

    s["goal_a_reached"] = sim.run_until(phase_a, 40.0)
    s["goal_a_time"] = sim.t - t_goal
    s["intruder_time"] = stepped["in"]
    s["max_v_a"] = max((v for t, v, _ in sim.cmds if t_goal < t), default=0.0)
    ok, reason = sim.set_param("d_h", -1.0)
    s["d_h_refused"], s["d_h_reason"] = not ok, reason
    ok, reason = sim.set_param("speed_limit", 0.3)
    s["speed_limit_set"], s["speed_limit_reason"] = ok, reason
    t_b = sim.t
    sim.goal(GOAL_B)
    sim.run_until(lambda: abs(sim.x[0] - GOAL_A[0]) > 1.5, 20.0)
    sim.odom_on = False
    s["odom_off"] = sim.t
    sim.run_until(lambda: False, 1.5)
    s["v_true_after_outage"] = float(sim.x[3])
    sim.odom_on = True
    s["odom_on"] = sim.t
    s["goal_b_reached"] = sim.run_until(lambda: sim.near(GOAL_B), 60.0)
    s["max_v_b"] = max((v for t, v, _ in sim.cmds if t > t_b + 1.0), default=0.0)
    s["cmds"], s["stops"] = sim.cmds, sim.stops
    s["diags"] = sim.diags
    s["robot"] = sim.x.tolist()
    with open(out, "w") as f:
        json.dump(s, f)
    sim.node.destroy_node()
    rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
