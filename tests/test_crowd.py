"""Social force crowd: behaviour, robustness and agreement with pysocialforce."""

from __future__ import annotations

import importlib
import logging
import os
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from humanmpc.sim.crowd import Crowd, CrowdSpec
from humanmpc.sim.social_force import (
    SocialForceParams,
    group_forces,
    obstacle_force,
    obstacle_force_samples,
    social_force,
)
from humanmpc.sim.world import Polygon, World

CONTACT = 0.5  # two human radii of 0.25 m


def _run(crowd: Crowd, steps: int, **robot: np.ndarray) -> np.ndarray:
    track = [crowd.positions]
    for _ in range(steps):
        crowd.step(**robot)
        track.append(crowd.positions)
    return np.array(track)


def test_lone_human_reaches_its_goal_and_stops() -> None:
    crowd = Crowd(CrowdSpec.build([[0.0, 0.0]], [[[6.0, 3.0]]], 1.2))
    track = _run(crowd, 120)
    final = np.linalg.norm(track[-1, 0] - [6.0, 3.0])
    assert final < 0.5  # pysocialforce's arrival radius
    np.testing.assert_allclose(track[-1], track[-10])  # standing still once arrived
    speed = np.linalg.norm(np.diff(track[:40, 0], axis=0), axis=1) / 0.1
    assert speed.max() <= 1.3 * 1.2 + 1e-9  # never faster than the cap


@pytest.mark.parametrize("angle", [0.0, np.pi / 2, 3 * np.pi / 4, np.pi])
def test_two_humans_facing_each_other_pass_without_contact(angle: float) -> None:
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    pos = np.array([[-5.0, 0.05], [5.0, -0.05]]) @ rot.T
    goals = -pos
    crowd = Crowd(CrowdSpec.build(pos, [g[None] for g in goals], 1.2))
    track = _run(crowd, 150)
    gap = np.linalg.norm(track[:, 0] - track[:, 1], axis=1)
    assert gap.min() > CONTACT
    assert np.all(np.linalg.norm(track[-1] - goals, axis=1) < 0.5)


def test_head_on_encounter_is_rotation_invariant_unlike_pysocialforce() -> None:
    """pysocialforce's unwrapped angle weakens the repulsion for encounters along the x axis."""

    def min_gap(angle: float, compat: bool) -> float:
        rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        pos = np.array([[-5.0, 0.1], [5.0, -0.1]]) @ rot.T
        spec = CrowdSpec.build(pos, [g[None] for g in -pos], 1.2)
        track = _run(Crowd(spec, params=SocialForceParams(pysocialforce_compat=compat)), 150)
        return float(np.linalg.norm(track[:, 0] - track[:, 1], axis=1).min())

    fixed = [min_gap(a, False) for a in (0.0, 0.7, np.pi / 2)]
    assert max(fixed) - min(fixed) < 1e-6
    assert min_gap(0.0, True) < fixed[0] - 0.1


def test_forces_are_finite_for_coincident_and_motionless_agents() -> None:
    p = SocialForceParams()
    pos = np.array([[1.0, 1.0], [1.0, 1.0], [1.0, 1.0]])
    for vel in (np.zeros((3, 2)), np.array([[1.0, 0.0], [0.0, 0.0], [-1.0, 0.5]])):
        f = social_force(pos, vel, pos, vel, np.arange(3), p)
        assert np.all(np.isfinite(f))
    goal = pos.copy()  # standing on their goals
    assert np.all(np.isfinite(group_forces(pos, goal, np.array([0, 0, 0]), p)))
    assert np.all(np.isfinite(obstacle_force_samples(pos, pos[:1], p)))
    assert np.all(np.isfinite(obstacle_force(pos, np.zeros((3, 1)), pos[:, None, :], p)))
    crowd = Crowd(CrowdSpec.build(pos, [[g] for g in goal], 1.0, groups=[(0, 1, 2)]))
    crowd.step(robot_position=[1.0, 1.0], robot_velocity=[0.0, 0.0])
    assert np.all(np.isfinite(crowd.positions))


def test_the_robot_repels_a_human_walking_at_it() -> None:
    spec = CrowdSpec.build([[-4.0, 0.0]], [[[4.0, 0.0]]], 1.0)
    free = _run(Crowd(spec), 80)
    robot = {"robot_position": np.array([0.0, 0.05]), "robot_velocity": np.zeros(2)}
    dodged = _run(Crowd(spec), 80, **robot)
    assert np.abs(free[:, 0, 1]).max() < 1e-9
    assert np.linalg.norm(dodged[:, 0] - [0.0, 0.05], axis=1).min() > 0.4
    assert np.abs(dodged[:, 0, 1]).max() > 0.2


def test_two_humans_pass_each_other_in_a_3m_corridor_without_touching_walls() -> None:
    walls = (Polygon.rectangle((0.0, 1.6), 20.0, 0.2), Polygon.rectangle((0.0, -1.6), 20.0, 0.2))
    world = World(walls, (-11.0, 11.0, -3.0, 3.0))
    spec = CrowdSpec.build([[-8.0, 1.2], [8.0, 1.2]], [[[8.0, 1.2]], [[-8.0, 1.2]]], 1.2)
    track = _run(Crowd(spec, world), 200)
    assert np.abs(track[..., 1]).max() < 1.5 - 0.25  # no body touches a wall face
    assert np.linalg.norm(track[:, 0] - track[:, 1], axis=1).min() > CONTACT
    assert np.all(np.linalg.norm(track[-1] - [[8.0, 1.2], [-8.0, 1.2]], axis=1) < 0.5)


def test_looping_humans_walk_back_and_forth_between_waypoints() -> None:
    spec = CrowdSpec.build([[0.0, 0.0]], [[[4.0, 0.0], [0.0, 0.0]]], 1.0, loop=True)
    track = _run(Crowd(spec), 400)
    x = track[:, 0, 0]
    turns = np.count_nonzero(np.diff(np.sign(np.diff(x[x != x[0]]))) != 0)
    assert x.max() > 3.4 and turns >= 3  # out, back, out again, ...


def test_group_coherence_pulls_a_straggler_back_to_the_group() -> None:
    pos = np.array([[0.0, 0.0], [0.0, 0.6], [0.0, -0.6], [0.0, 4.0]])
    goals = pos + np.array([10.0, 0.0])
    spec = CrowdSpec.build(pos, [g[None] for g in goals], 1.0, groups=[(0, 1, 2, 3)])
    alone = CrowdSpec.build(pos, [g[None] for g in goals], 1.0)
    y_group = _run(Crowd(spec), 50)[-1, 3, 1]
    y_alone = _run(Crowd(alone), 50)[-1, 3, 1]
    assert y_group < y_alone - 0.5


@pytest.fixture(scope="module")
def pysocialforce(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ModuleType]:
    """pysocialforce, imported without letting it touch logging or the CWD.

    At import it sets the root logger to DEBUG, adds handlers and writes file.log in the CWD.
    """
    pytest.importorskip("numba")
    root = logging.getLogger()
    level, handlers = root.level, list(root.handlers)
    cwd = Path.cwd()
    os.chdir(tmp_path_factory.mktemp("psf"))
    try:
        module = importlib.import_module("pysocialforce")
    except ImportError:
        pytest.skip("pysocialforce is not installed (pip install pysocialforce)")
    finally:
        os.chdir(cwd)
        for h in list(root.handlers):
            if h not in handlers:
                root.removeHandler(h)
        root.setLevel(level)
    yield module


def test_vectorised_model_matches_pysocialforce_with_groups_and_walls(
    pysocialforce: ModuleType, tmp_path: Path
) -> None:
    """Same state, same parameters, 20 s at dt = 0.1 s: trajectories agree to 1e-9 m.

    Both compute the same floating-point formulas in a different order (vectorised sums), so
    only rounding differs; 1e-9 m leaves room for its growth over 200 steps while any change
    of a force term (even a factor 1.01) shows up at the millimetre level within a few steps.
    pysocialforce derives the desired and the maximum speed from the initial speed (1.3 |v0|),
    hence ``max_speed_factor = 1`` and ``desired_speeds = 1.3 |v0|`` here.
    """
    rng = np.random.default_rng(3)
    k = 7
    pos = rng.uniform(-4, 4, (k, 2))
    heading = rng.uniform(-np.pi, np.pi, k)
    speed = rng.uniform(0.6, 1.0, k)
    vel = np.stack([np.cos(heading), np.sin(heading)], 1) * speed[:, None]
    goals = -pos + rng.normal(0, 0.5, (k, 2))
    groups = [[0, 1, 2], [3, 4]]
    wall = Polygon.rectangle((0.0, 5.0), 8.0, 0.4, 0.2)
    world = World((wall,), (-10.0, 10.0, -10.0, 10.0))
    v = wall.array
    lines = [[a[0], b[0], a[1], b[1]] for a, b in zip(v, np.roll(v, -1, axis=0), strict=True)]
    config = tmp_path / "sf.toml"
    config.write_text("step_width = 0.1\n[scene]\nenable_group = true\n")
    state = np.hstack([pos, vel, goals])
    sim = pysocialforce.Simulator(state, groups=groups, obstacles=lines, config_file=str(config))
    assert sim.peds.step_width == 0.1
    params = SocialForceParams(max_speed_factor=1.0, pysocialforce_compat=True)
    spec = CrowdSpec.build(pos, [g[None] for g in goals], 1.3 * speed, velocities=vel, groups=groups)
    crowd = Crowd(spec, world, params)
    worst = 0.0
    for _ in range(200):
        sim.step()
        crowd.step()
        worst = max(worst, float(np.abs(sim.peds.pos() - crowd.positions).max()))
    assert worst < 1e-9
    moved = np.linalg.norm(crowd.positions - pos, axis=1)
    assert moved.min() > 1.0  # everybody actually walked
