#!/usr/bin/python3
"""The rostest of the generated ROS node: a simulation in the loop, and the checks (tests/test_ros.py).

This node is the world: the robot (humanmpc.sim.robot, integrating the node's cmd_vel as a base's
velocity controller would, within the acceleration bounds), a crowd of 30 people (humanmpc.sim.crowd,
the social force model) and a wall that a simulated laser scans (ray-cast against humanmpc.sim.world).
It publishes odometry and tf (odom -> base_link, static map -> odom and base_link -> base_laser), the
people as humanmpc_msgs/TrackedPersons and the goal in the map frame, so the node's tf2 conversions
are on the path to the goal. A script drives the scene:

1. drive to goal A (a geometry_msgs/PoseStamped on goal); on the way a person steps beside the
   robot, within d_h, and leaves again;
2. goal A reached; goal B given as a global plan (nav_msgs/Path of 300 poses on plan); while driving,
   the odometry stops for 2 s, then the people for 2 s;
3. goal B reached.

Checked: both goals reached; the protective stop topic reports the person within one control period
(plus a transport allowance, STOP_ALLOWANCE) of the first people message that holds them; each outage
gives a stop with the node's reason and the commands brake the robot to a standstill; every command
is finite. A JSON summary (latencies, the node's cycle times at 30 tracked people) goes to ~summary.

The interpreter: tests/test_ros.py writes the project's venv Python into the first line; ROS 1's packages
are imported from Debian's path ahead of the venv's (whose ROS 2 message packages share their names),
numpy and humanmpc's dependencies from the venv.
"""

from __future__ import annotations

import itertools
import json
import math
import sys
import threading
import time
import unittest
from dataclasses import dataclass, field

import numpy as np  # the venv's, before Debian's packages are on the path

from humanmpc.sim.crowd import Crowd, CrowdSpec
from humanmpc.sim.robot import RobotLimits, RobotModel
from humanmpc.sim.robot import step as robot_step
from humanmpc.sim.social_force import SocialForceParams
from humanmpc.sim.world import Polygon, World

# ROS 1's packages from Debian's path, ahead of the venv's: the ros2 extra installs ROS 2's message packages
# of the same names (rosgraph_msgs, std_msgs, geometry_msgs ...) into the venv, which rospy cannot use
DEBIAN = "/usr/lib/python3/dist-packages"
sys.path.insert(0, DEBIAN)
for _shadowed in [m for m in sys.modules if m.split(".")[0].endswith("_msgs")]:
    del sys.modules[_shadowed]
import rospy  # noqa: E402
import rostest  # noqa: E402
import tf2_ros  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import PoseStamped, TransformStamped, Twist  # noqa: E402
from humanmpc_msgs.msg import ProtectiveStop, TrackedPerson, TrackedPersons  # noqa: E402
from nav_msgs.msg import Odometry, Path  # noqa: E402
from sensor_msgs.msg import LaserScan  # noqa: E402

sys.path.remove(DEBIAN)
sys.path.append(DEBIAN)  # anything imported later from the venv first

SIM_DT = 0.02              # [s] robot integration, odometry and tf
PEOPLE_EVERY = 5           # people and scan every 5 sim steps (10 Hz, the crowd model's period)
MAP_TO_ODOM = (1.0, 2.0, 0.3)   # x, y, yaw of the odometry frame in the map frame
LASER_OFFSET = 0.1         # [m] base_laser ahead of base_link
GOAL_A = (8.0, 0.0)        # in the odometry frame (published in the map frame)
GOAL_B = (0.0, 0.5)
INTRUDER_ID = 1000
STOP_ALLOWANCE = 0.02      # [s] transport and scheduling between a message's stamp and the node's timer
OUTAGE = 2.0               # [s] each input outage


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    return 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)


def map_from_odom(p: np.ndarray) -> np.ndarray:
    x, y, yaw = MAP_TO_ODOM
    c, s = math.cos(yaw), math.sin(yaw)
    return np.asarray(p, dtype=float) @ np.array([[c, s], [-s, c]]) + np.array([x, y])


def rotate_to_map(v: np.ndarray) -> np.ndarray:
    c, s = math.cos(MAP_TO_ODOM[2]), math.sin(MAP_TO_ODOM[2])
    return np.asarray(v, dtype=float) @ np.array([[c, s], [-s, c]])


@dataclass
class Log:
    """What the node published, with arrival times (guarded: rospy calls back from its threads)."""

    lock: threading.Lock = field(default_factory=threading.Lock)
    cmds: list[tuple[float, float, float]] = field(default_factory=list)   # (time, v, omega)
    stops: list[tuple[float, bool, str]] = field(default_factory=list)     # (stamp, stop, reason_name)
    diags: list[dict[str, str]] = field(default_factory=list)
    last_cmd: tuple[float, float] = (0.0, 0.0)


class ClosedLoop(unittest.TestCase):
    def setUp(self) -> None:
        rospy.init_node("humanmpc_sim_test")
        ns = rospy.get_param("~controller", "/paper_controller")
        self.period = float(rospy.get_param(f"{ns}/control_period"))
        self.d_h = float(rospy.get_param(f"{ns}/d_h"))
        self.goal_tolerance = float(rospy.get_param(f"{ns}/goal_tolerance"))
        self.odom_timeout = float(rospy.get_param(f"{ns}/odom_timeout"))
        self.people_timeout = float(rospy.get_param(f"{ns}/people_timeout"))
        a_bounds = rospy.get_param(f"{ns}/a_bounds")
        omega_bounds = rospy.get_param(f"{ns}/omega_bounds")
        v_bounds = rospy.get_param(f"{ns}/v_bounds")
        self.decel = -float(a_bounds[0])
        self.model = RobotModel(RobotLimits(v_min=float(v_bounds[0]), v_max=float(v_bounds[1]),
                                            a_min=float(a_bounds[0]), a_max=float(a_bounds[1]),
                                            omega_min=float(omega_bounds[0]), omega_max=float(omega_bounds[1])))
        self.summary_path = rospy.get_param("~summary")
        self.log = Log()
        self.odom_pub = rospy.Publisher("odom", Odometry, queue_size=5)
        self.people_pub = rospy.Publisher("people", TrackedPersons, queue_size=5)
        self.scan_pub = rospy.Publisher("scan", LaserScan, queue_size=5)
        self.goal_pub = rospy.Publisher("goal", PoseStamped, queue_size=1, latch=True)
        self.plan_pub = rospy.Publisher("plan", Path, queue_size=1, latch=True)
        self.tf_pub = tf2_ros.TransformBroadcaster()
        self.static_tf = tf2_ros.StaticTransformBroadcaster()
        rospy.Subscriber("cmd_vel", Twist, self.on_cmd, tcp_nodelay=True)
        rospy.Subscriber(f"{ns}/protective_stop", ProtectiveStop, self.on_stop, tcp_nodelay=True)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diag)

        self.wall = World(obstacles=(Polygon.rectangle((4.0, -1.6), 14.0, 0.2),), bounds=(-5.0, 13.0, -5.0, 12.0))
        rng = np.random.default_rng(0)
        k = 30
        start = np.column_stack([rng.uniform(-1.0, 9.0, k), rng.uniform(4.0, 10.0, k)])
        ends = start + np.column_stack([rng.choice([-4.0, 4.0], k), np.zeros(k)])
        walks = [np.vstack([e, s]) for s, e in zip(start, ends, strict=True)]
        self.crowd = Crowd(CrowdSpec.build(start, walks, 0.8, loop=True),
                           world=World(bounds=(-10.0, 15.0, -10.0, 15.0)), params=SocialForceParams(dt=0.1))
        self.x = np.zeros(4)       # robot [x, y, theta, v] in the odometry frame
        self.omega = 0.0
        self.intruder: np.ndarray | None = None
        self.angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)

    # --- what the node publishes -------------------------------------------------------------------
    def on_cmd(self, msg: Twist) -> None:
        with self.log.lock:
            self.log.cmds.append((time.monotonic(), msg.linear.x, msg.angular.z))
            self.log.last_cmd = (msg.linear.x, msg.angular.z)

    def on_stop(self, msg: ProtectiveStop) -> None:
        with self.log.lock:
            self.log.stops.append((msg.header.stamp.to_sec(), bool(msg.stop), msg.reason_name))

    def last_outcome(self) -> str | None:
        """The controller's outcome in the node's latest diagnostics (None before any)."""
        with self.log.lock:
            return self.log.diags[-1].get("outcome") if self.log.diags else None

    def on_diag(self, msg: DiagnosticArray) -> None:
        for st in msg.status:
            if st.hardware_id:
                with self.log.lock:
                    self.log.diags.append({kv.key: kv.value for kv in st.values})

    # --- what the world publishes ------------------------------------------------------------------
    def publish_odometry(self, now: rospy.Time) -> None:
        x, y, th, v = self.x
        q = yaw_quaternion(th)
        o = Odometry()
        o.header.stamp = now
        o.header.frame_id = "odom"
        o.child_frame_id = "base_link"
        o.pose.pose.position.x, o.pose.pose.position.y = x, y
        (o.pose.pose.orientation.x, o.pose.pose.orientation.y, o.pose.pose.orientation.z,
         o.pose.pose.orientation.w) = q
        o.twist.twist.linear.x = v
        o.twist.twist.angular.z = self.omega
        self.odom_pub.publish(o)
        self.tf_pub.sendTransform(self.transform(now, "odom", "base_link", x, y, th))

    @staticmethod
    def transform(now: rospy.Time, parent: str, child: str, x: float, y: float, yaw: float) -> TransformStamped:
        t = TransformStamped()
        t.header.stamp = now
        t.header.frame_id = parent
        t.child_frame_id = child
        t.transform.translation.x, t.transform.translation.y = x, y
        r = t.transform.rotation
        r.x, r.y, r.z, r.w = yaw_quaternion(yaw)
        return t

    def publish_people(self, now: rospy.Time) -> None:
        pos, vel = self.crowd.positions, self.crowd.velocities
        ids = list(self.crowd.ids)
        if self.intruder is not None:
            pos = np.vstack([pos, self.intruder])
            vel = np.vstack([vel, np.zeros(2)])
            ids.append(INTRUDER_ID)
        msg = TrackedPersons()
        msg.header.stamp = now
        msg.header.frame_id = "map"
        for i, p, v in zip(ids, map_from_odom(pos), rotate_to_map(vel), strict=True):
            tp = TrackedPerson()
            tp.track_id = int(i)
            tp.pose.pose.position.x, tp.pose.pose.position.y = float(p[0]), float(p[1])
            tp.pose.pose.orientation.w = 1.0
            tp.pose.covariance[0] = tp.pose.covariance[7] = 0.01
            tp.twist.twist.linear.x, tp.twist.twist.linear.y = float(v[0]), float(v[1])
            msg.tracks.append(tp)
        self.people_pub.publish(msg)

    def publish_scan(self, now: rospy.Time) -> None:
        x, y, th, _ = self.x
        origin = np.array([x + LASER_OFFSET * math.cos(th), y + LASER_OFFSET * math.sin(th)])
        d = np.column_stack([np.cos(self.angles + th), np.sin(self.angles + th)])
        t = np.zeros(len(self.angles))
        range_max = 8.0
        for _ in range(60):  # sphere tracing against the world's signed distance
            s = self.wall.signed_distance(origin + t[:, None] * d)
            t = np.where((s > 1e-3) & (t <= range_max), t + np.maximum(s, 1e-3), t)
        msg = LaserScan()
        msg.header.stamp = now
        msg.header.frame_id = "base_laser"
        msg.angle_min = float(self.angles[0])
        msg.angle_max = float(self.angles[-1])
        msg.angle_increment = float(self.angles[1] - self.angles[0])
        msg.range_min, msg.range_max = 0.05, range_max
        msg.ranges = [float(r) if r <= range_max else math.inf for r in t]
        self.scan_pub.publish(msg)

    def publish_goal(self, goal: tuple[float, float]) -> None:
        g = PoseStamped()
        g.header.stamp = rospy.Time.now()
        g.header.frame_id = "map"
        p = map_from_odom(np.array(goal))
        g.pose.position.x, g.pose.position.y = float(p[0]), float(p[1])
        g.pose.orientation.w = 1.0
        self.goal_pub.publish(g)

    def publish_plan(self, goal: tuple[float, float], n: int) -> None:
        """A straight global plan of n poses from the robot to goal, in the map frame (n above the
        controller's max_path_points: the node subsamples it)."""
        path = Path()
        path.header.stamp = rospy.Time.now()
        path.header.frame_id = "map"
        for p in map_from_odom(np.linspace(self.x[:2], np.array(goal), n)):
            ps = PoseStamped()
            ps.header = path.header
            ps.pose.position.x, ps.pose.position.y = float(p[0]), float(p[1])
            ps.pose.orientation.w = 1.0
            path.poses.append(ps)
        self.plan_pub.publish(path)

    # --- the scene -----------------------------------------------------------------------------------
    def test_closed_loop(self) -> None:
        self.static_tf.sendTransform([self.transform(rospy.Time.now(), "map", "odom", *MAP_TO_ODOM),
                                      self.transform(rospy.Time.now(), "base_link", "base_laser", LASER_OFFSET, 0.0,
                                                     0.0)])
        deadline = time.monotonic() + 30.0
        while self.goal_pub.get_num_connections() == 0 or not self.log.diags:
            self.assertLess(time.monotonic(), deadline, "the controller node did not come up within 30 s")
            now = rospy.Time.now()
            self.publish_odometry(now)
            self.publish_people(now)
            time.sleep(SIM_DT)
        self.publish_goal(GOAL_A)
        phase = "to_a"
        events: dict[str, float] = {}
        odom_on = people_on = True
        t_start = time.monotonic()
        self.t0_wall = rospy.Time.now().to_sec()
        k = 0
        intrusion_stamp = None
        first_at_speed_b = None
        next_tick = time.monotonic()
        while phase != "done":
            self.assertLess(time.monotonic() - t_start, 90.0, f"scene not finished in 90 s (phase {phase})")
            next_tick += SIM_DT
            time.sleep(max(0.0, next_tick - time.monotonic()))
            with self.log.lock:
                v_cmd, w_cmd = self.log.last_cmd
            # the base: speed tracked within the acceleration bounds, turn rate as commanded
            a = float(np.clip((v_cmd - self.x[3]) / SIM_DT, self.model.limits.a_min, self.model.limits.a_max))
            self.omega = float(np.clip(w_cmd, self.model.limits.omega_min, self.model.limits.omega_max))
            self.x = robot_step(self.model, self.x, [a, self.omega], SIM_DT)
            now = rospy.Time.now()
            t = time.monotonic() - t_start
            if odom_on:
                self.publish_odometry(now)
            if k % PEOPLE_EVERY == 0:
                self.crowd.step()
                if people_on:
                    self.publish_people(now)
                    if self.intruder is not None and intrusion_stamp is None:
                        intrusion_stamp = now.to_sec()
                self.publish_scan(now)
            k += 1
            pos, speed = self.x[:2], self.x[3]
            if phase == "to_a":
                if "intrusion" not in events and pos[0] > 3.0 and speed > 0.3:
                    th = self.x[2]
                    self.intruder = pos + 0.8 * self.d_h * np.array([-math.sin(th), math.cos(th)])
                    events["intrusion"] = t
                elif "intrusion" in events and "intruder_left" not in events and t > events["intrusion"] + 1.5:
                    self.intruder = None
                    events["intruder_left"] = t
                # reached as a mission executive sees it: at rest there, and the node says so (after its turn
                # in place to the goal's heading)
                if (np.linalg.norm(pos - GOAL_A) < self.goal_tolerance + 0.1 and abs(speed) < 0.05
                        and self.last_outcome() == "goal_reached"):
                    events["goal_a"] = t
                    self.publish_plan(GOAL_B, 300)
                    phase = "to_b"
            elif phase == "to_b":
                if first_at_speed_b is None and speed > 0.4:
                    first_at_speed_b = t
                    odom_on = False
                    events["odom_off"] = t
                elif "odom_off" in events and odom_on is False and t > events["odom_off"] + OUTAGE:
                    odom_on = True
                    events["odom_on"] = t
                elif "odom_on" in events and "people_off" not in events and speed > 0.4:
                    people_on = False
                    events["people_off"] = t
                elif "people_off" in events and not people_on and t > events["people_off"] + OUTAGE:
                    people_on = True
                    events["people_on"] = t
                if ("people_on" in events and np.linalg.norm(pos - GOAL_B) < self.goal_tolerance + 0.1
                        and abs(speed) < 0.05 and self.last_outcome() == "goal_reached"):
                    events["goal_b"] = t
                    phase = "done"
            if phase != "done":
                self.record_speed(t, events)
        rospy.sleep(0.3)
        self.check(events, intrusion_stamp, t_start)

    def record_speed(self, t: float, events: dict[str, float]) -> None:
        """The robot's true speed at the end of each outage (the stale-input stop must have braked it)."""
        for off, on in (("odom_off", "odom_on"), ("people_off", "people_on")):
            if off in events and on not in events and t > events[off] + OUTAGE - 3 * SIM_DT:
                events.setdefault(f"speed_end_{off}", float(self.x[3]))

    def check(self, events: dict[str, float], intrusion_stamp: float | None, t_start: float) -> None:
        with self.log.lock:
            cmds, stops, diags = list(self.log.cmds), list(self.log.stops), list(self.log.diags)
        summary: dict[str, object] = {"events": events, "commands": len(cmds),
                                      "stops": [(s[0] - self.t0_wall, s[1], s[2]) for s in stops]}
        try:
            self.check_run(events, intrusion_stamp, t_start, cmds, stops, diags, summary)
        finally:
            with open(self.summary_path, "w") as f:
                json.dump(summary, f, indent=2)

    def check_run(self, events: dict[str, float], intrusion_stamp: float | None, t_start: float,
                  cmds: list[tuple[float, float, float]], stops: list[tuple[float, bool, str]],
                  diags: list[dict[str, str]], summary: dict[str, object]) -> None:

        # no command is NaN (or infinite)
        bad = [c for c in cmds if not (math.isfinite(c[1]) and math.isfinite(c[2]))]
        self.assertGreater(len(cmds), 100, "too few commands received")
        self.assertEqual(bad, [], "non-finite commands")

        # the goals
        self.assertIn("goal_a", events, "goal A not reached")
        self.assertIn("goal_b", events, "goal B not reached")
        reached = [d for d in diags if d.get("outcome") == "goal_reached"]
        self.assertTrue(reached, "the node never reported goal_reached in its diagnostics")

        # the person within d_h: a stop on the stop topic within one control period
        self.assertIsNotNone(intrusion_stamp, "the person never stepped in")
        assert intrusion_stamp is not None
        human = [s for s in stops if s[1] and s[0] >= intrusion_stamp - 1e-6]
        self.assertTrue(human, "no protective stop after the person stepped within d_h")
        self.assertIn(human[0][2], ("human_too_close", "unsafe_plan", "separation",
                                    "predicted_contact"),
                      f"first stop after the intrusion: {human[0]}")
        latency = human[0][0] - intrusion_stamp
        summary["human_stop_latency_s"] = latency
        self.assertLessEqual(latency, self.period + STOP_ALLOWANCE,
                             f"stop {latency:.3f} s after the person stepped in (period {self.period} s)")

        # stale inputs stop the robot, with the node's reasons
        for off, reason, timeout in (("odom_off", "stale_odometry", self.odom_timeout),
                                     ("people_off", "stale_people", self.people_timeout)):
            self.assertIn(off, events, f"outage {off} did not happen")
            t_off = t_start + events[off]
            on = off.replace("_off", "_on")
            t_on = t_start + events[on]
            got = [s for s in stops if s[2] == reason]
            self.assertTrue(got, f"no {reason} stop")
            speed_end = events.get(f"speed_end_{off}")
            summary[f"speed_end_{off}"] = speed_end
            self.assertIsNotNone(speed_end)
            self.assertLess(float(speed_end or 0.0), 0.02, f"robot still moving at the end of the {off} outage")
            # while stopped for the reason, the commands brake: non-increasing speed, no turning
            window = [c for c in cmds if t_off + timeout + 2 * self.period < c[0] < t_on]
            self.assertTrue(window, f"no commands during the {off} outage")
            self.assertTrue(all(c[2] == 0.0 for c in window), f"turning during the {off} outage")
            speeds = [c[1] for c in window]
            self.assertTrue(all(b <= a + 1e-9 for a, b in itertools.pairwise(speeds)), f"not braking during {off}")
            self.assertEqual(speeds[-1], 0.0, f"command not zero at the end of the {off} outage")

        # the cycle time at 30 tracked people (callback to cmd_vel publish)
        cycles = np.array([float(d["cycle_ms"]) for d in diags if d.get("tracks") == "30"])
        self.assertGreater(len(cycles), 50, "too few periods with 30 tracked people")
        summary["cycle_ms_30_people"] = {"n": len(cycles), "mean": float(cycles.mean()),
                                         "p50": float(np.percentile(cycles, 50)),
                                         "p99": float(np.percentile(cycles, 99)), "max": float(cycles.max())}
        self.assertLess(float(np.percentile(cycles, 99)), 1000 * self.period, "cycle time p99 beyond the period")


if __name__ == "__main__":
    rostest.rosrun("humanmpc_ros_test", "closed_loop", ClosedLoop)
