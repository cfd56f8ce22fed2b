"""The generated map families (envs/sweeper/families.py) and their keywords on the envs.

The connectivity oracle below shares nothing with the package: its own
footprint test (a sliding window), its own breadth-first flood fill over
configurations, its own union of footprints.
"""

from __future__ import annotations

from collections import deque

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from numpy.lib.stride_tricks import sliding_window_view

import motiongym  # noqa: F401
from motiongym.envs.checks import ArgumentError
from motiongym.envs.sweeper.families import FAMILIES, MAX_MAP_SEED, NARROW, family_map, min_side
from motiongym.envs.sweeper.vector_env import SweeperVectorEnv

ENV_ID = "motiongym/Sweeper-v1"


def free_squares(grid: np.ndarray, k: int) -> np.ndarray:
    """(H-k+1, W-k+1) bool: anchors whose k x k square holds no obstacle."""
    if k > min(grid.shape):
        return np.zeros((0, 0), bool)
    return ~sliding_window_view(grid, (k, k)).any(axis=(2, 3))


def oracle(grid: np.ndarray, w: int) -> tuple[int, np.ndarray]:
    """(number of 4-connected sets of free configurations, cells swept from the first set)."""
    free = free_squares(grid, w)
    seen = np.zeros_like(free)
    sets, covered = 0, np.zeros_like(grid)
    for start in zip(*np.nonzero(free), strict=True):
        if seen[start]:
            continue
        sets += 1
        queue = deque([start])
        seen[start] = True
        while queue:
            r, c = queue.popleft()
            if sets == 1:
                covered[r : r + w, c : c + w] = True
            for rr, cc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
                inside = 0 <= rr < free.shape[0] and 0 <= cc < free.shape[1]
                if inside and free[rr, cc] and not seen[rr, cc]:
                    seen[rr, cc] = True
                    queue.append((rr, cc))
    return sets, covered


CASES = [(w, None) for w in (1, 2, 3, 5)] + [(w, "min") for w in (1, 3, 10)] + [(3, (70, 45))]


@pytest.mark.parametrize("family", FAMILIES)
def test_closed_and_connected_at_robot_scale(family: str) -> None:
    """Border all wall; one set of free configurations; every free cell under a footprint."""
    for w, size in CASES:
        size = (min_side(w), min_side(w) + 3) if size == "min" else size
        for seed in range(6):
            grid = family_map(family, seed, w, size)
            assert grid.shape == (size or (max(40, min_side(w)), max(60, min_side(w))))
            assert grid[0].all() and grid[-1].all() and grid[:, 0].all() and grid[:, -1].all()
            sets, covered = oracle(grid, w)
            assert sets == 1, (family, seed, w, size)
            assert np.array_equal(covered, ~grid), (family, seed, w, size)


@pytest.mark.parametrize("family", FAMILIES)
def test_deterministic_in_family_seed_and_size(family: str) -> None:
    a = family_map(family, 7, 3)
    assert np.array_equal(a, family_map(family, 7, 3))
    assert not all(np.array_equal(a, family_map(family, s, 3)) for s in (8, 9, 10))
    assert family_map(family, 7, 3, (50, 50)).shape == (50, 50)
    assert np.array_equal(family_map(family, MAX_MAP_SEED, 3), family_map(family, MAX_MAP_SEED, 3))


@pytest.mark.parametrize("family", NARROW)
def test_narrow_families_are_exactly_the_robot_wide(family: str) -> None:
    """No (w + 1)-square of free cells anywhere; the w-square fits (and sweeps everything)."""
    for w in (1, 2, 3, 4):
        for seed in range(10):
            grid = family_map(family, seed, w)
            assert free_squares(grid, w).any()
            assert not free_squares(grid, w + 1).any(), (family, seed, w)


def test_wider_corridors_are_one_or_two_cells_wider() -> None:
    widest = set()
    for seed in range(20):
        grid = family_map("corridors", seed, 3)
        k = max(k for k in range(1, 12) if free_squares(grid, k).any())
        widest.add(k)
    assert widest == {4, 5}


def test_families_differ_in_openness() -> None:
    """Pillar fields and halls are open, the narrow families are mostly wall."""
    share = {f: np.mean([(~family_map(f, s, 3)).mean() for s in range(10)]) for f in FAMILIES}
    assert share["hall"] > 0.7 and share["pillars"] > 0.75
    assert share["narrow-corridors"] < 0.7 and share["narrow-serpentine"] < 0.7


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"map_family": "spiral"}, ["map_family", "'spiral'", "'narrow-corridors'", "'mixed'"]),
        ({"map_family": "hall", "map_seed": -1}, ["map_seed", "-1", "[0, 4294967295]"]),
        ({"map_family": "hall", "map_seed": 2**32}, ["map_seed", "4294967296", "[0, 4294967295]"]),
        ({"map_family": "hall", "map_seed": 1.0}, ["map_seed", "1.0", "an integer"]),
        ({"map_family": "hall", "map_size": (17, 40)}, ["map_size", "(17, 40)", "[18, 256]"]),
        ({"map_family": "hall", "map_size": (40, 257)}, ["map_size", "(40, 257)", "[18, 256]"]),
        ({"map_family": "hall", "map_size": 40}, ["map_size", "40", "(rows, columns)"]),
        (
            {"map_family": "hall", "map_size": (40, 40), "robot_width": 10},
            ["map_size", "(40, 40)", "[46, 256]", "robot_width=10"],
        ),
        ({"map_seed": 3}, ["map_seed", "3", "needs map_family", "'hall'"]),
        ({"map_size": (40, 40)}, ["map_size", "needs map_family"]),
        ({"map_family": "hall", "map_file": "x.txt"}, ["map_family", "map_file", "not both"]),
    ],
)
def test_bad_family_keywords_are_one_clear_error(kwargs: dict, words: list[str]) -> None:
    with pytest.raises(ArgumentError) as error:
        gym.make(ENV_ID, **kwargs)
    for word in words:
        assert word in str(error.value)


def test_bad_input_to_the_generator_names_the_keyword() -> None:
    with pytest.raises(ArgumentError, match="map_family"):
        family_map("maze", 0, 3)
    with pytest.raises(ArgumentError, match="map_seed"):
        family_map("hall", -5, 3)
    with pytest.raises(ArgumentError, match="map_size"):
        family_map("hall", 0, 3, (10, 10))


@pytest.mark.parametrize("family", FAMILIES)
def test_a_fixed_family_map_passes_the_env_checker(family: str) -> None:
    env = gym.make(ENV_ID, map_family=family, map_seed=100000)
    check_env(env.unwrapped, skip_render_check=True)
    assert np.array_equal(env.unwrapped.fixed, family_map(family, 100000, 3))
    env.reset(seed=1)
    assert np.array_equal(env.unwrapped.scenario.obstacle, family_map(family, 100000, 3))


def test_the_keywords_work_on_v0_too() -> None:
    env = gym.make("motiongym/Sweeper-v0", map_family="offices", map_seed=3, map_size=(30, 50))
    check_env(env.unwrapped, skip_render_check=True)
    assert env.unwrapped.fixed.shape == (30, 50)


def test_unset_map_seed_draws_a_map_per_reset_from_the_reset_seed() -> None:
    env = gym.make(ENV_ID, map_family="pillars", map_size=(30, 36))
    assert env.unwrapped.fixed is None
    maps = []
    for seed in (0, 1, 0):
        env.reset(seed=seed)
        maps.append(env.unwrapped.scenario.obstacle.copy())
    assert maps[0].shape == (30, 36)
    assert np.array_equal(maps[0], maps[2]) and not np.array_equal(maps[0], maps[1])


def test_the_vector_env_draws_the_single_envs_maps() -> None:
    single = gym.make(ENV_ID, map_family="mixed")
    vec = SweeperVectorEnv(2, map_family="mixed", line_of_sight=True)
    vec.reset(seed=[4, 5])
    for i, seed in enumerate((4, 5)):
        single.reset(seed=seed)
        assert np.array_equal(vec._scenarios[i].obstacle, single.unwrapped.scenario.obstacle)
    vec.close()
