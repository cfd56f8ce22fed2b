"""The greedy coverage teacher (nearest-unswept) of Sweeper-v1: its distances and its sweeps."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.agents.reproduce.sweeper_runs import run_sweep
from motiongym.baselines.registry import make_policy
from motiongym.envs.sweeper.occupancy import bfs_distance, box_sum

ENV_ID = "motiongym/Sweeper-v1"


def test_distance_to_the_nearest_goal_counts_moves_around_a_wall() -> None:
    """The teacher's distances (``bfs_distance`` from a mask of goals): a 5 x 5 grid, a
    wall across rows 0-3 of column 2: from (0, 0) to the goal (0, 4) is 4 moves down and
    back up around the wall plus 4 across, 12; a closed cell is unreached (-1)."""
    open_ = np.ones((5, 5), bool)
    open_[0:4, 2] = False
    goal = np.zeros((5, 5), bool)
    goal[0, 4] = True
    dist = bfs_distance(open_, goal)
    assert dist[0, 4] == 0 and dist[0, 0] == 12 and dist[4, 2] == 6
    assert dist[0, 2] == -1
    shut = open_.copy()
    shut[4, 2] = False  # the wall now splits the grid
    assert bfs_distance(shut, goal)[0, 0] == -1
    two = goal.copy()
    two[4, 0] = True  # a second goal: the distance is to the nearer one
    assert bfs_distance(open_, two)[0, 0] == 4


def test_goal_blocks_are_every_top_left_cell_whose_block_holds_one() -> None:
    """The teacher's goal test (``box_sum > 0``) over the configurations whose 3 x 3
    footprint lies inside the 5 x 6 grid."""
    cells = np.zeros((5, 6), bool)
    cells[2, 3] = True
    blocks = (box_sum(cells.astype(np.int64), 3) > 0)[:3, :4]
    assert blocks.shape == (3, 4)
    assert sorted(zip(*np.nonzero(blocks), strict=True)) == [
        (r, c) for r in range(3) for c in range(1, 4)
    ]


@pytest.mark.parametrize("map_name", ["room", "apartment", "maze"])
def test_nearest_unswept_sweeps_every_reachable_cell_with_few_detours(map_name: str) -> None:
    """Line-of-sight sensing, two starts per map: full coverage, no bump, and a travel
    ratio (travel over area / w) below 1.8 (PSA + CWA: 1.36-1.53 on these maps)."""
    env = gym.make(ENV_ID, map_name=map_name)
    kwargs = {**gym.spec(ENV_ID).kwargs, "map_name": map_name}
    policy = make_policy(ENV_ID, "nearest-unswept", env.observation_space, env.action_space, kwargs)
    for seed in range(2):
        info = run_sweep(env, policy, seed)
        assert info["is_success"] and info["coverage"] == 1.0, (seed, info["coverage"])
        assert info["bumps"] == 0
        assert 1.0 <= info["travel_ratio"] < 1.8, (seed, info["travel_ratio"])
