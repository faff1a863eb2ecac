"""Geometry of the static world: distances and the nearest obstacle point."""

from __future__ import annotations

import numpy as np
import pytest

from humanmpc.sim.world import Circle, Polygon, World

BOUNDS = (-10.0, 10.0, -10.0, 10.0)


def test_nearest_point_of_a_circle_lies_on_the_ray_from_its_centre() -> None:
    world = World((Circle((1.0, 2.0), 0.5),), BOUNDS)
    np.testing.assert_allclose(world.nearest_point([4.0, 6.0]), [1.0 + 0.3, 2.0 + 0.4])
    assert world.signed_distance([4.0, 6.0]) == pytest.approx(4.5)
    assert world.signed_distance([1.0, 2.2]) == pytest.approx(-0.3)  # inside: negative depth


def test_circle_centre_query_is_finite_and_on_the_boundary() -> None:
    world = World((Circle((0.0, 0.0), 1.0),), BOUNDS)
    p = world.nearest_point([0.0, 0.0])
    assert np.all(np.isfinite(p)) and np.linalg.norm(p) == pytest.approx(1.0)


def test_nearest_point_of_a_polygon_edge_is_the_perpendicular_foot() -> None:
    world = World((Polygon.rectangle((0.0, 0.0), 2.0, 1.0),), BOUNDS)
    np.testing.assert_allclose(world.nearest_point([0.3, 2.0]), [0.3, 0.5])
    assert world.signed_distance([0.3, 2.0]) == pytest.approx(1.5)


def test_nearest_point_of_a_polygon_beyond_a_corner_is_the_vertex() -> None:
    world = World((Polygon.rectangle((0.0, 0.0), 2.0, 1.0),), BOUNDS)
    np.testing.assert_allclose(world.nearest_point([4.0, 4.5]), [1.0, 0.5])
    assert world.signed_distance([4.0, 4.5]) == pytest.approx(5.0)


def test_point_inside_a_non_convex_polygon_has_negative_distance_and_notch_is_outside() -> None:
    l_shape = Polygon(((0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)))
    world = World((l_shape,), BOUNDS)
    assert world.signed_distance([0.5, 0.5]) == pytest.approx(-0.5)
    assert world.signed_distance([2.0, 1.5]) == pytest.approx(0.5)  # in the notch, outside
    np.testing.assert_allclose(world.nearest_point([2.0, 1.5]), [2.0, 1.0])


def test_nearest_point_comes_from_the_closest_of_several_obstacles() -> None:
    world = World((Circle((5.0, 0.0), 1.0), Polygon.rectangle((-3.0, 0.0), 1.0, 1.0), Circle((0.0, 6.0), 0.5)), BOUNDS)
    np.testing.assert_allclose(world.nearest_point([-1.0, 0.2]), [-2.5, 0.2])
    np.testing.assert_allclose(world.nearest_point([3.0, 0.0]), [4.0, 0.0])
    np.testing.assert_allclose(world.nearest_point([0.0, 4.0]), [0.0, 5.5])


def test_queries_are_vectorised_over_any_batch_shape() -> None:
    world = World((Circle((0.0, 0.0), 1.0), Polygon.rectangle((4.0, 0.0), 1.0, 1.0)), BOUNDS)
    pts = np.random.default_rng(0).uniform(-6, 6, (3, 5, 2))
    d = world.signed_distance(pts)
    near = world.nearest_point(pts)
    assert d.shape == (3, 5) and near.shape == (3, 5, 2)
    for idx in np.ndindex(3, 5):
        assert d[idx] == pytest.approx(float(world.signed_distance(pts[idx])))
        np.testing.assert_allclose(near[idx], world.nearest_point(pts[idx]))
    # |signed distance| equals the distance to the returned boundary point
    np.testing.assert_allclose(np.abs(d), np.linalg.norm(near - pts, axis=-1), atol=1e-12)


def test_empty_world_has_infinite_distance_and_a_far_obstacle_parameter() -> None:
    world = World((), BOUNDS)
    assert np.isinf(world.signed_distance([0.0, 0.0]))
    with pytest.raises(ValueError, match="no obstacles"):
        world.nearest_point([0.0, 0.0])
    assert np.linalg.norm(world.obstacle_parameter([1.0, 1.0]) - [1.0, 1.0]) >= 100.0


def test_invalid_obstacles_are_rejected_with_a_reason() -> None:
    with pytest.raises(ValueError, match="radius"):
        Circle((0.0, 0.0), -1.0)
    with pytest.raises(ValueError, match="zero area"):
        Polygon(((0, 0), (1, 1), (2, 2)))
    with pytest.raises(ValueError, match="bounds"):
        World((), (1.0, 0.0, 0.0, 1.0))
