#!/usr/bin/python3
"""Drives the generated node with hand-made inputs and reports what it answers (tests/test_ros.py).

Run by Debian's python3 (rospy) against a node already running under the same master:

    node_probe.py '<json config>'

The config says what to publish at 20 Hz for ``duration`` seconds, all in the odometry frame ``odom``
(so no tf is involved): odometry of a robot standing at the origin, stamped ``odom_offset`` seconds
from now; tracked people (``tracks``: a list of [x, y, vx, vy, track_id], any of them may be a
string "nan"), stamped ``people_offset`` from now, published until ``people_until`` seconds (None:
to the end); a 36-beam scan with every return at 5 m until ``scan_until`` (None: to the end; absent
with ``scan`` false); a goal at ``goal`` (null: none). It prints one JSON object: the diagnostics'
values with their time since the start (``diags``, up to ``duration``), the protective stops after
the start (``stops``) and the track
ids of the last predictions that held any (``prediction_ids``).
"""

from __future__ import annotations

import json
import math
import sys
import time
from typing import Any

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped
from humanmpc_msgs.msg import ProtectiveStop, TrackedPerson, TrackedPersons
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from visualization_msgs.msg import MarkerArray

RATE = 20.0  # [Hz] every input


def number(x: Any) -> float:
    return math.nan if x == "nan" else float(x)


def main() -> None:
    cfg: dict[str, Any] = {"duration": 3.0, "odom_offset": 0.0, "people_offset": 0.0, "people_until": None,
                           "scan": False, "scan_until": None, "tracks": [], "goal": None, "node": "/paper_controller"}
    cfg.update(json.loads(sys.argv[1]))
    rospy.init_node("node_probe", anonymous=True, disable_signals=True)
    diags: list[dict[str, Any]] = []
    stops: list[tuple[float, bool, str]] = []
    prediction_ids: list[int] = []
    t0 = [math.inf]  # the start of publishing: what comes before it is not recorded

    def on_diag(msg: DiagnosticArray) -> None:
        if not 0.0 <= time.monotonic() - t0[0] <= cfg["duration"]:
            return
        for st in msg.status:
            if st.name.endswith("_node: controller"):
                d: dict[str, Any] = {kv.key: kv.value for kv in st.values}
                d["t"] = time.monotonic() - t0[0]
                diags.append(d)

    def on_stop(msg: ProtectiveStop) -> None:
        if time.monotonic() < t0[0]:
            return
        stops.append((time.monotonic() - t0[0], bool(msg.stop), msg.reason_name))

    def on_predictions(msg: MarkerArray) -> None:
        ids = sorted(m.id for m in msg.markers if m.ns == "predictions")
        if ids:
            prediction_ids[:] = ids

    rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag)
    rospy.Subscriber(f"{cfg['node']}/protective_stop", ProtectiveStop, on_stop)
    rospy.Subscriber(f"{cfg['node']}/predictions", MarkerArray, on_predictions)
    odom_pub = rospy.Publisher("odom", Odometry, queue_size=5)
    people_pub = rospy.Publisher("people", TrackedPersons, queue_size=5)
    scan_pub = rospy.Publisher("scan", LaserScan, queue_size=5)
    goal_pub = rospy.Publisher("goal", PoseStamped, queue_size=1, latch=True)
    deadline = time.monotonic() + 20.0
    pubs = [odom_pub, people_pub] + ([scan_pub] if cfg["scan"] else []) + ([goal_pub] if cfg["goal"] else [])
    while any(p.get_num_connections() == 0 for p in pubs):
        if time.monotonic() > deadline:
            raise SystemExit("the node did not subscribe within 20 s")
        time.sleep(0.05)
    if cfg["goal"]:
        g = PoseStamped()
        g.header.stamp = rospy.Time.now()
        g.header.frame_id = "odom"
        g.pose.position.x, g.pose.position.y = (float(x) for x in cfg["goal"])
        g.pose.orientation.w = 1.0
        goal_pub.publish(g)
    t0[0] = time.monotonic()
    k = 0
    while True:
        t = time.monotonic() - t0[0]
        if t > cfg["duration"]:
            break
        now = rospy.Time.now()
        o = Odometry()
        o.header.stamp = now + rospy.Duration.from_sec(cfg["odom_offset"])
        o.header.frame_id = "odom"
        o.child_frame_id = "base_link"
        o.pose.pose.orientation.w = 1.0
        odom_pub.publish(o)
        if cfg["people_until"] is None or t < cfg["people_until"]:
            msg = TrackedPersons()
            msg.header.stamp = now + rospy.Duration.from_sec(cfg["people_offset"])
            msg.header.frame_id = "odom"
            for x, y, vx, vy, track_id in cfg["tracks"]:
                tp = TrackedPerson()
                tp.track_id = int(track_id)
                tp.pose.pose.position.x, tp.pose.pose.position.y = number(x), number(y)
                tp.pose.pose.orientation.w = 1.0
                tp.twist.twist.linear.x, tp.twist.twist.linear.y = number(vx), number(vy)
                msg.tracks.append(tp)
            people_pub.publish(msg)
        if cfg["scan"] and (cfg["scan_until"] is None or t < cfg["scan_until"]):
            s = LaserScan()
            s.header.stamp = now
            s.header.frame_id = "odom"
            s.angle_min, s.angle_increment = -math.pi, 2 * math.pi / 36
            s.angle_max = s.angle_min + 35 * s.angle_increment
            s.range_min, s.range_max = 0.05, 20.0
            s.ranges = [5.0] * 36
            scan_pub.publish(s)
        k += 1
        time.sleep(max(0.0, t0[0] + k / RATE - time.monotonic()))
    time.sleep(0.2)
    print(json.dumps({"diags": diags, "stops": stops, "prediction_ids": prediction_ids}))
    rospy.signal_shutdown("done")


if __name__ == "__main__":
    main()
