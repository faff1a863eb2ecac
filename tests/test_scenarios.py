"""Seeded scenarios: reproducible, valid, and named."""

from __future__ import annotations

import numpy as np
import pytest

from humanmpc.sim.scenarios import CROWDNAV_SCENARIOS, SCENARIOS, SIMULATED_SCENARIOS, make_scenario


@pytest.mark.parametrize("name", [*SIMULATED_SCENARIOS, *CROWDNAV_SCENARIOS])
def test_scenario_is_reproducible_per_seed_and_varies_across_seeds(name: str) -> None:
    a, b, c = make_scenario(name, 7), make_scenario(name, 7), make_scenario(name, 8)
    np.testing.assert_array_equal(a.crowd.positions, b.crowd.positions)
    np.testing.assert_array_equal(a.goal, b.goal)
    assert a.world == b.world
    assert not np.array_equal(a.crowd.positions, c.crowd.positions)


@pytest.mark.parametrize("name", [*SIMULATED_SCENARIOS, *CROWDNAV_SCENARIOS])
def test_scenario_starts_everyone_in_free_space(name: str) -> None:
    for seed in range(5):
        s = make_scenario(name, seed)
        r = 0.2
        assert s.world.contains_free_disc(s.robot_start[:2], r) and s.world.contains_free_disc(s.goal[:2], r)
        assert np.all(s.world.signed_distance(s.crowd.positions) > 0.25)
        gaps = np.linalg.norm(s.crowd.positions - s.robot_start[:2], axis=1)
        assert gaps.min() > 1.0
        assert np.linalg.norm(s.goal[:2] - s.robot_start[:2]) > 5.0


def test_paper_scenarios_have_the_papers_crowds() -> None:
    rcc = make_scenario("random_crowded_cluttered", 0)
    assert rcc.crowd.size == 10 and len(rcc.world.obstacles) == 5
    group = make_scenario("crossing_group", 0)
    assert group.crowd.size == 9 and group.crowd.groups == (tuple(range(9)),)
    assert np.all(group.crowd.loop)


def test_unknown_scenario_names_the_valid_ones() -> None:
    with pytest.raises(ValueError, match=r"valid scenarios: .*corridor.*crossing_group"):
        make_scenario("mall", 0)


def test_the_simulated_crowdnav_and_recorded_scenarios_are_all_registered() -> None:
    assert set(SCENARIOS) == {*SIMULATED_SCENARIOS, *CROWDNAV_SCENARIOS, "biwi_eth", "biwi_hotel", "crowds_zara01"}


@pytest.mark.parametrize("kind", ["circle", "square"])
def test_crowdnav_crossings_have_their_people_apart_walking_to_their_own_goals(kind: str) -> None:
    for n in (5, 10, 20):
        for seed in range(20):
            s = make_scenario(f"crowdnav_{kind}_{n}", seed)
            start, goal = s.crowd.positions, np.array([w[-1] for w in s.crowd.waypoints])
            assert s.crowd.size == n and not np.any(s.crowd.loop) and np.all(s.crowd.desired_speeds == 1.0)
            for points in (start, goal):
                gaps = np.linalg.norm(points[:, None] - points[None], axis=-1) + 10 * np.eye(n)
                assert gaps.min() >= 0.7
                for robot in (s.robot_start[:2], s.goal[:2]):
                    assert np.linalg.norm(points - robot, axis=1).min() >= 1.2
            if kind == "circle":  # on the circle of 4 m give or take 0.5 m per coordinate, going to the antipode
                np.testing.assert_allclose(goal, -start)
                assert np.all(np.abs(np.linalg.norm(start, axis=1) - 4.0) <= 0.5 * np.sqrt(2) + 1e-9)
            else:  # from one half of the 10 m square to the other
                assert np.all(np.sign(start[:, 0]) == -np.sign(goal[:, 0])) and np.all(np.abs(start) <= 5.0)
            np.testing.assert_array_equal(s.robot_start[:2], [0.0, -4.0])
            np.testing.assert_array_equal(s.goal[:2], [0.0, 4.0])
