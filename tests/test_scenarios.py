"""Seeded scenarios: reproducible, valid, and named."""

from __future__ import annotations

import numpy as np
import pytest

from humanmpc.sim.scenarios import SCENARIOS, SIMULATED_SCENARIOS, make_scenario


@pytest.mark.parametrize("name", SIMULATED_SCENARIOS)
def test_scenario_is_reproducible_per_seed_and_varies_across_seeds(name: str) -> None:
    a, b, c = make_scenario(name, 7), make_scenario(name, 7), make_scenario(name, 8)
    np.testing.assert_array_equal(a.crowd.positions, b.crowd.positions)
    np.testing.assert_array_equal(a.goal, b.goal)
    assert a.world == b.world
    assert not np.array_equal(a.crowd.positions, c.crowd.positions)


@pytest.mark.parametrize("name", SIMULATED_SCENARIOS)
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


def test_the_simulated_and_recorded_scenarios_are_all_registered() -> None:
    assert set(SCENARIOS) == {*SIMULATED_SCENARIOS, "biwi_eth", "biwi_hotel", "crowds_zara01"}
