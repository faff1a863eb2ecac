"""The process environment the ROS 2 wheels from PyPI need, set before rclpy is imported.

The wheels (``ros-jazzy-*``) install their libraries into ``<prefix>/lib`` and, auditwheel-renamed,
into ``site-packages/ros_*.libs``, and their ament index into ``<prefix>/share``. rclpy's C extension
finds those libraries only through ``LD_LIBRARY_PATH``, which the dynamic loader reads at process
start, so a process that lacks it is started again with it (``reexec_with_ros_env``). The wheels'
own ``ros_wheels_bootstrapper.pth`` does the same for every interpreter of the environment, unless
``_ROS_WHEELS_BOOTSTRAP_COMPLETE`` is set: set here, so a process is started once, not twice.

With a system's ROS 2 (``source /opt/ros/jazzy/setup.bash``), ``AMENT_PREFIX_PATH`` already names it,
and nothing is changed.
"""

from __future__ import annotations

import importlib.util
import os
import random
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

BOOTSTRAP_GUARD = "_ROS_WHEELS_BOOTSTRAP_COMPLETE"
DEFAULT_RMW = "rmw_fastrtps_cpp"


def _site_packages_of_rclpy() -> Path | None:
    spec = importlib.util.find_spec("rclpy")
    if spec is None or spec.origin is None:
        return None
    return Path(spec.origin).resolve().parent.parent


def wheel_library_dirs(prefix: str | Path = sys.prefix) -> list[str]:
    """The folders holding the wheels' shared libraries (empty when rclpy is not installed as wheels)."""
    site = _site_packages_of_rclpy()
    if site is None or not (Path(prefix) / "share" / "ament_index").is_dir():
        return []
    dirs = [str(Path(prefix) / "lib")]
    dirs += sorted(str(d) for d in site.glob("ros_*.libs") if d.is_dir())
    return dirs


def system_ros(base: Mapping[str, str]) -> bool:
    """True when a sourced ROS 2 installation provides rclpy (its setup script sets ROS_DISTRO)."""
    return bool(base.get("ROS_DISTRO")) and bool(base.get("AMENT_PREFIX_PATH"))


def ros_environment(base: Mapping[str, str] | None = None, prefix: str | Path = sys.prefix) -> dict[str, str]:
    """``base`` (default: this process's environment) with what the wheels need added."""
    env = dict(os.environ if base is None else base)
    if system_ros(env):
        return env
    dirs = wheel_library_dirs(prefix)
    if not dirs:
        raise RuntimeError("rclpy is not installed: install the ROS 2 wheels with pip install 'humanmpc[ros2]', "
                           "or source a ROS 2 Jazzy installation (source /opt/ros/jazzy/setup.bash)")
    have = [d for d in env.get("LD_LIBRARY_PATH", "").split(os.pathsep) if d]
    env["LD_LIBRARY_PATH"] = os.pathsep.join(dirs + [d for d in have if d not in dirs])
    ament = [d for d in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if d]
    if str(prefix) not in ament:
        env["AMENT_PREFIX_PATH"] = os.pathsep.join([str(prefix), *ament])
    env.setdefault("RMW_IMPLEMENTATION", DEFAULT_RMW)
    env[BOOTSTRAP_GUARD] = "1"
    return env


def localhost_environment(base: Mapping[str, str], domain_id: int | None = None) -> dict[str, str]:
    """``base`` with DDS discovery kept on this machine, in a domain of its own (default: a random one,
    so parallel runs do not hear each other)."""
    env = dict(base)
    env["ROS_DOMAIN_ID"] = str(random.randint(1, 101) if domain_id is None else domain_id)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env.pop("ROS_LOCALHOST_ONLY", None)  # deprecated since Jazzy, in favour of the line above
    env.pop("ROS_STATIC_PEERS", None)
    return env


def ready(env: Mapping[str, str] | None = None) -> bool:
    """True when this process was started with the environment rclpy needs."""
    current = os.environ if env is None else env
    if system_ros(current):
        return True
    want = ros_environment(current)
    return all(current.get(k) == want[k] for k in ("LD_LIBRARY_PATH", "AMENT_PREFIX_PATH", "RMW_IMPLEMENTATION"))


def reexec_with_ros_env(argv: Sequence[str] | None = None) -> None:
    """Start this process again with the wheels' environment when it lacks it (returns when it has it)."""
    if ready():
        return
    args = list(sys.orig_argv if argv is None else argv)
    os.execve(sys.executable, [sys.executable, *args[1:]], ros_environment())
