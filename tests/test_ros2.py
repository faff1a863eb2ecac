"""The ROS 2 node (humanmpc-gen ros2): generated, started as its own process, and driven over real DDS
on the loopback by a simulated robot and crowd in another process (tests/ros2/sim_node.py).

Both processes get the wheels' environment from humanmpc.ros2.env (nothing set by hand), discovery
kept on this machine and a random domain, so parallel runs do not hear each other. Bounded in time;
both processes are always killed.
"""

from __future__ import annotations

import itertools
import json
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from humanmpc.codegen.generate import GenerateError
from humanmpc.codegen.ros2 import ROS2_MARKER, write_ros2

from .conftest import make_solver

pytest.importorskip("rclpy", reason="the ROS 2 wheels: pip install 'humanmpc[ros2]' (make test installs them)")

from humanmpc.ros2.env import localhost_environment, ros_environment

SIM = Path(__file__).parent / "ros2" / "sim_node.py"


@pytest.fixture(scope="module")
def solver_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_solver(tmp_path_factory.mktemp("ros2_solver"))


@pytest.fixture(scope="module")
def node_dir(solver_dir: Path) -> Path:
    return write_ros2(solver_dir)


def test_ros2_command_writes_the_launcher_parameters_and_a_copy_of_the_built_solver(node_dir: Path,
                                                                                     solver_dir: Path) -> None:
    name = solver_dir.name
    assert (node_dir / ROS2_MARKER).is_file()
    assert os.access(node_dir / f"{name}_node.py", os.X_OK)
    params = (node_dir / "config" / f"{name}.yaml").read_text()
    assert "ros__parameters:" in params and "    d_h: 0.5" in params and "must be a number with 0 <= d_h" in params
    assert (node_dir / "solver" / "build" / f"lib{name}.so").is_file()
    with pytest.raises(GenerateError, match="already exists"):
        write_ros2(solver_dir)


def test_ros2_command_refuses_a_solver_that_is_not_built(tmp_path: Path) -> None:
    unbuilt = make_solver(tmp_path, built=False)
    with pytest.raises(GenerateError, match="build it first"):
        write_ros2(unbuilt, tmp_path / "out")


def _kill(proc: subprocess.Popen[bytes]) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


@pytest.fixture(scope="module")
def closed_loop(node_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    """The generated node and the simulation, each its own process, over Fast DDS on the loopback."""
    out = tmp_path_factory.mktemp("ros2_loop")
    env = localhost_environment(ros_environment())
    name = node_dir.name.removesuffix("_ros2")
    with open(out / "node.log", "wb") as log:
        node = subprocess.Popen([sys.executable, str(node_dir / f"{name}_node.py")], env=env, stdout=log,
                                stderr=subprocess.STDOUT, start_new_session=True)
        try:
            sim = subprocess.run([sys.executable, str(SIM), f"{name}_controller", str(out / "summary.json")], env=env,
                                 capture_output=True, text=True, timeout=240, start_new_session=True)
        finally:
            _kill(node)
    assert sim.returncode == 0, sim.stdout + sim.stderr + (out / "node.log").read_text()
    summary = json.loads((out / "summary.json").read_text())
    summary["node_log"] = (out / "node.log").read_text()
    cycle = np.array([float(d["cycle_ms"]) for d in summary["diags"] if d.get("people_used") is not None])
    print(f"\nROS 2 node cycle time, 30 people at 10 Hz: {len(cycle)} periods, mean {cycle.mean():.2f} ms, "
          f"p50 {np.percentile(cycle, 50):.2f} ms, p99 {np.percentile(cycle, 99):.2f} ms, max {cycle.max():.2f} ms")
    Path("out").mkdir(exist_ok=True)
    Path("out/ros2_closed_loop.json").write_text(json.dumps(
        {"periods": len(cycle), "cycle_ms_mean": cycle.mean(), "cycle_ms_p99": float(np.percentile(cycle, 99)),
         **{k: v for k, v in summary.items() if k not in ("cmds", "diags", "stops", "node_log")}}, indent=1))
    yield summary


@pytest.mark.slow
def test_robot_reaches_its_goals_among_walking_people(closed_loop: dict[str, Any]) -> None:
    assert closed_loop["goal_a_reached"] and closed_loop["goal_b_reached"]
    assert all(np.isfinite(v) and np.isfinite(w) for _, v, w in closed_loop["cmds"])


@pytest.mark.slow
def test_person_within_d_h_gives_a_latched_protective_stop_and_a_braking_command(closed_loop: dict[str, Any]) -> None:
    t_in = closed_loop["intruder_time"]
    assert t_in is not None
    stops = [(t, reason) for t, stop, reason in closed_loop["stops"] if stop and t_in <= t <= t_in + 1.0]
    people_stops = ("human_too_close", "unsafe_plan", "separation", "predicted_contact")
    assert stops and stops[0][1] in people_stops, closed_loop["stops"]
    t_stop = stops[0][0]
    t_end = min([t for t, stop, _ in closed_loop["stops"] if not stop and t > t_stop] + [t_in + 1.0])
    after = [v for t, v, _ in closed_loop["cmds"] if t_stop <= t < t_end]
    assert after and min(after) < closed_loop["v_at_intruder"] - 0.1, "the commands did not brake"


@pytest.mark.slow
def test_stale_odometry_stops_the_robot(closed_loop: dict[str, Any]) -> None:
    off, on = closed_loop["odom_off"], closed_loop["odom_on"]
    assert any(stop and reason == "stale_odometry" and off < t < on for t, stop, reason in closed_loop["stops"])
    during = [v for t, v, _ in closed_loop["cmds"] if off + 0.6 < t < on]
    assert during and during[-1] == 0.0 and all(b <= a for a, b in itertools.pairwise(during))
    assert closed_loop["v_true_after_outage"] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.slow
def test_parameter_service_changes_behaviour_and_refuses_a_broken_rule_with_the_rule(
        closed_loop: dict[str, Any]) -> None:
    assert closed_loop["d_h_refused"]
    assert "d_h must be a number with 0 <= d_h <= 100" in closed_loop["d_h_reason"]
    assert closed_loop["speed_limit_set"], closed_loop["speed_limit_reason"]
    assert closed_loop["max_v_a"] > 0.5            # before: the spec's speed limit
    assert closed_loop["max_v_b"] <= 0.3 + 1e-6    # after: the one set through the service
