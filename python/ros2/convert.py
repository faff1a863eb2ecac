"""ROS 2 messages to the controller's arrays, and its result back to messages (no navigation here).

People come as a ``sensor_msgs/PointCloud2`` (see ``PEOPLE_FIELDS``): one point per tracked person,
named fields, a header with the stamp and frame, and any number of people. No message package for
tracked people can be built from the PyPI wheels (docs/ros.md), and a point cloud carries every field
of one, is published by any tracker in a few lines and is shown by RViz as it is.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..codegen.ros import NODE_MAX_TRACKS, node_stop_reason

try:  # the ros2 extra
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
    from geometry_msgs.msg import PoseStamped, Quaternion
    from nav_msgs.msg import Odometry, Path
    from sensor_msgs.msg import LaserScan, PointCloud2, PointField
    from visualization_msgs.msg import Marker, MarkerArray
except ImportError as err:
    raise ImportError(f"the ROS 2 node needs rclpy and the ROS 2 message packages ({err}): "
                      "pip install 'humanmpc[ros2]', or source ROS 2 Jazzy (docs/ros.md)") from None

# The people cloud: required fields, then optional ones (absent, or NaN for a person: none given).
PEOPLE_REQUIRED = ("x", "y", "vx", "vy")          # [m] position, [m/s] velocity, in header.frame_id
PEOPLE_OPTIONAL = ("id", "cov_xx", "cov_xy", "cov_yy")  # track id (an integer), position covariance [m^2]
PEOPLE_FIELDS = PEOPLE_REQUIRED + PEOPLE_OPTIONAL
_NUMPY_OF = {PointField.INT8: "i1", PointField.UINT8: "u1", PointField.INT16: "i2", PointField.UINT16: "u2",
             PointField.INT32: "i4", PointField.UINT32: "u4", PointField.FLOAT32: "f4", PointField.FLOAT64: "f8"}
STALE_PEOPLE = node_stop_reason("stale_people").name
MAX_PEOPLE = NODE_MAX_TRACKS  # one message's bound, the ROS 1 node's (more is a broken tracker: too_many_tracks)


class MessageError(ValueError):
    """A people message the node cannot use (it names the field and why): no usable people, so the node's
    stop ``reason`` (stale_people, or too_many_tracks)."""

    def __init__(self, message: str, reason: str = STALE_PEOPLE) -> None:
        super().__init__(message)
        self.reason = reason


def yaw_of(q: Quaternion) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def quaternion_of(yaw: float) -> Quaternion:
    q = Quaternion()
    q.z, q.w = math.sin(yaw / 2.0), math.cos(yaw / 2.0)
    return q


def stamp_seconds(stamp: Any) -> float:
    return float(stamp.sec) + 1e-9 * float(stamp.nanosec)


def odometry_state(msg: Odometry) -> tuple[np.ndarray, float, float]:
    """(pose (x, y, yaw), v, omega) of an odometry message."""
    p = msg.pose.pose
    pose = np.array([p.position.x, p.position.y, yaw_of(p.orientation)])
    return pose, float(msg.twist.twist.linear.x), float(msg.twist.twist.angular.z)


def pose_of(msg: PoseStamped) -> np.ndarray:
    p = msg.pose
    return np.array([p.position.x, p.position.y, yaw_of(p.orientation)])


def path_points(msg: Path, capacity: int) -> np.ndarray:
    """The path's (x, y); more than capacity poses are subsampled evenly, the last kept."""
    pts = np.array([[ps.pose.position.x, ps.pose.position.y] for ps in msg.poses], dtype=np.float64).reshape(-1, 2)
    if len(pts) > capacity:
        pts = pts[np.unique(np.linspace(0, len(pts) - 1, capacity).round().astype(int))]
    return pts


def people_arrays(msg: PointCloud2) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """(tracks (k, 4) [x, y, vx, vy], ids (k,) or None, covariances (k, 3) or None) of a people cloud."""
    fields = {f.name: f for f in msg.fields}
    missing = [n for n in PEOPLE_REQUIRED if n not in fields]
    if missing:
        raise MessageError(f"the people cloud lacks the field(s) {', '.join(missing)}: it needs "
                           f"{', '.join(PEOPLE_REQUIRED)} (and optionally {', '.join(PEOPLE_OPTIONAL)})")
    k = int(msg.width) * int(msg.height)
    names, formats, offsets = [], [], []
    order = ">" if msg.is_bigendian else "<"
    for name in PEOPLE_FIELDS:
        f = fields.get(name)
        if f is None:
            continue
        if f.datatype not in _NUMPY_OF or f.count != 1:
            raise MessageError(f"the people cloud's field {name} has datatype {f.datatype} and count {f.count}: "
                               "it must be one number (PointField INT8 ... FLOAT64)")
        names.append(name)
        formats.append(order + _NUMPY_OF[f.datatype])
        offsets.append(int(f.offset))
    dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": int(msg.point_step)})
    widest = max(o + dtype[n].itemsize for n, o in zip(names, offsets, strict=True))
    if k * int(msg.point_step) > len(msg.data) or widest > dtype.itemsize:
        raise MessageError(f"the people cloud's data holds {len(msg.data)} bytes, too few for {k} points of "
                           f"{msg.point_step} bytes with its fields")
    rec = np.frombuffer(bytes(msg.data), dtype=dtype, count=k) if k else np.zeros(0, dtype=dtype)
    tracks = np.column_stack([rec[n].astype(np.float64) for n in PEOPLE_REQUIRED]) if k else np.zeros((0, 4))
    ids = None
    if "id" in names:
        raw = rec["id"]
        if np.issubdtype(raw.dtype, np.floating) and not np.all(np.isfinite(raw) & (raw == np.round(raw))):
            raise MessageError("the people cloud's field id must hold whole numbers")
        ids = (raw.astype(np.int64) & 0x7FFFFFFF).astype(np.int64)
    cov = None
    if all(n in names for n in ("cov_xx", "cov_xy", "cov_yy")):
        cov = np.column_stack([rec[n].astype(np.float64) for n in ("cov_xx", "cov_xy", "cov_yy")]).reshape(k, 3)
        cov[~(cov[:, 0] > 0.0)] = np.nan  # none given: NaN, or a zero or negative xx
    return tracks, ids, cov


def people_cloud(header: Any, tracks: np.ndarray, ids: np.ndarray | None = None,
                 covariances: np.ndarray | None = None) -> PointCloud2:
    """A people cloud (what a tracker publishes): float64 fields, ids as uint32."""
    k = len(tracks)
    names = ["x", "y", "vx", "vy", "id", "cov_xx", "cov_xy", "cov_yy"]
    dtype = np.dtype([(n, "<u4" if n == "id" else "<f8") for n in names])
    rec = np.zeros(k, dtype=dtype)
    for j, n in enumerate(PEOPLE_REQUIRED):
        rec[n] = tracks[:, j]
    rec["id"] = np.arange(k) if ids is None else ids
    cov = np.full((k, 3), np.nan) if covariances is None else covariances
    for j, n in enumerate(("cov_xx", "cov_xy", "cov_yy")):
        rec[n] = cov[:, j]
    msg = PointCloud2()
    msg.header = header
    msg.height, msg.width = 1, k
    msg.fields = [PointField(name=n, offset=int(dtype.fields[n][1]),  # type: ignore[index]
                             datatype=PointField.UINT32 if n == "id" else PointField.FLOAT64, count=1) for n in names]
    msg.is_bigendian = False
    msg.point_step = dtype.itemsize
    msg.row_step = dtype.itemsize * k
    msg.is_dense = True
    msg.data = rec.tobytes()
    return msg


def scan_points(msg: LaserScan) -> np.ndarray:
    """The returns within [range_min, range_max] as (m, 2) points in the scan's frame."""
    r = np.asarray(msg.ranges, dtype=np.float64)
    a = msg.angle_min + msg.angle_increment * np.arange(len(r))
    ok = np.isfinite(r) & (r >= msg.range_min) & (r <= msg.range_max)
    return np.column_stack([r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])])


def to_frame(points: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Points given in the frame at ``pose`` (x, y, yaw) expressed in the pose's parent frame."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return points @ np.array([[c, s], [-s, c]]) + pose[:2]


def nearest(points: np.ndarray, to: np.ndarray, capacity: int) -> np.ndarray:
    if len(points) <= capacity:
        return points
    d = np.hypot(points[:, 0] - to[0], points[:, 1] - to[1])
    return points[np.argsort(d, kind="stable")[:capacity]]


def plan_path(header: Any, plan: np.ndarray) -> Path:
    msg = Path()
    msg.header = header
    for x, y, th, _v in plan:
        ps = PoseStamped()
        ps.header = header
        ps.pose.position.x, ps.pose.position.y = float(x), float(y)
        ps.pose.orientation = quaternion_of(float(th))
        msg.poses.append(ps)
    return msg


def prediction_markers(header: Any, ids: np.ndarray, predictions: np.ndarray, d_h: float) -> MarkerArray:
    """Each person's predicted path (LINE_STRIP, id = track id) and a d_h disc at its start; a
    DELETEALL first, so people no longer used disappear."""
    out = MarkerArray()
    clear = Marker()
    clear.header = header
    clear.action = Marker.DELETEALL
    out.markers.append(clear)
    for j, tid in enumerate(ids):
        line = Marker()
        line.header = header
        line.ns, line.id, line.type, line.action = "prediction", int(tid), Marker.LINE_STRIP, Marker.ADD
        line.scale.x = 0.05
        line.color.r, line.color.g, line.color.a = 1.0, 0.5, 1.0
        line.pose.orientation.w = 1.0
        for x, y in predictions[:, j]:
            pt = _point(float(x), float(y))
            line.points.append(pt)
        disc = Marker()
        disc.header = header
        disc.ns, disc.id, disc.type, disc.action = "d_h", int(tid), Marker.CYLINDER, Marker.ADD
        disc.pose.position = _point(float(predictions[0, j, 0]), float(predictions[0, j, 1]))
        disc.pose.orientation.w = 1.0
        disc.scale.x = disc.scale.y = 2.0 * d_h
        disc.scale.z = 0.05
        disc.color.r, disc.color.a = 1.0, 0.3
        out.markers.append(line)
        out.markers.append(disc)
    return out


def _point(x: float, y: float) -> Any:
    from geometry_msgs.msg import Point

    return Point(x=x, y=y, z=0.0)


def status(header: Any, name: str, level: int, message: str, values: dict[str, Any],
           hardware_id: str = "") -> DiagnosticArray:
    msg = DiagnosticArray()
    msg.header = header
    st = DiagnosticStatus()
    st.level = bytes([level]) if isinstance(st.level, bytes) else level
    st.name, st.message, st.hardware_id = name, message, hardware_id
    st.values = [KeyValue(key=k, value=str(v)) for k, v in values.items()]
    msg.status = [st]
    return msg


def _level(value: Any) -> int:
    return int.from_bytes(value, "little") if isinstance(value, bytes) else int(value)


OK = _level(DiagnosticStatus.OK)
WARN = _level(DiagnosticStatus.WARN)
