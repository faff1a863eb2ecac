"""Candidate plans share their controller's solver: each is solved in the main solver's memory while the main
plan's warm start is kept aside (c_runtime/ocp_nlp_iterate.h), and of their outputs only those that may still
be applied are kept. An extra candidate therefore costs a few bytes, not a solver (about 240 KB in double at
the default sizes); the sizes come from the package's own report (<name>_controller_memsize)."""

from __future__ import annotations

from pathlib import Path

import pytest

import humanmpc
from tests.conftest import make_solver


@pytest.fixture(scope="module")
def sizes(tmp_path_factory: pytest.TempPathFactory, default_dir: Path) -> dict[int, int]:
    """controller_memsize by number of candidates (the default spec's three, and 1, 2, 4 and 8)."""
    root = tmp_path_factory.mktemp("candidates_memory")
    dirs = {3: default_dir}
    for n in (1, 2, 4, 8):
        dirs[n] = make_solver(root, {"name": f"cand{n}", "controller": {"candidates": n}})
    return {n: humanmpc.load(d).controller().memsize for n, d in dirs.items()}


def test_a_second_plan_costs_the_kept_warm_start_and_one_output_not_a_solver(sizes: dict[int, int]) -> None:
    """The main plan's warm start (its iterate, two of its multipliers, flags: 9 KB in double) and one output."""
    assert sizes[2] - sizes[1] <= 16 * 1024, sizes
    assert sizes[2] - sizes[1] <= sizes[1] // 16, sizes  # a solver is most of a one-plan controller


def test_beyond_three_plans_each_costs_a_few_bytes(sizes: dict[int, int]) -> None:
    """Three output buffers at most (the cheapest plan so far, last period's decision, the one being solved):
    from the fourth plan on, a candidate adds nothing to the controller (a few ints on the step's stack)."""
    assert sizes[4] - sizes[2] <= 8 * 1024, sizes
    assert sizes[8] - sizes[4] <= 4 * 256, sizes
