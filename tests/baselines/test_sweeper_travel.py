"""Travel of the sweeper's PSA + CWA against the lower bound and the exploration bound.

The issue asks for travel / (area / W) below the ratio that SmartDFS's
bound gives for each map. :func:`motiongym.envs.sweeper.occupancy.smartdfs_bound`
gives the bound of the online grid exploration that applies to the map
(``C + E/2 - 3`` without holes, ``C + E/2 + 3H - 2`` around H obstacles)
and the no-hole formula on every map. Measured (seeds 0-19 room and maze,
0-29 apartment, the reproduction's 50 procedural maps): below the bound
from 19/20 (seed 13: 0.013 above its bound), 20/20, 28/30 starts and on 48/50
maps with transfers along the quadtree's chain (20/20, 20/20, 27/30, 49/50
with the BFS-transfer ablation); the mean below the
mean bound on every map. The ``xfail(strict=True)`` tests name the rest,
and fail the day they pass. The other tests pin what the PSA choices
documented in ``baselines/sweeper/psa.py`` and ``quadtree.py`` do, with
numbers.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.agents.reproduce.sweeper_runs import run_sweep, sweep
from motiongym.baselines.registry import make_policy
from motiongym.envs.sweeper import occupancy
from motiongym.envs.sweeper.generator import empty_room

ENV_ID = "motiongym/Sweeper-v0"


def _ratios(map_name: str, seeds: range) -> tuple[np.ndarray, np.ndarray]:
    """Travel ratio and exploration-bound ratio of PSA + CWA per seeded random start."""
    env = gym.make(ENV_ID, map_name=map_name)
    kwargs = {**gym.spec(ENV_ID).kwargs, "map_name": map_name}
    policy = make_policy(ENV_ID, "psa-cwa", env.observation_space, env.action_space, kwargs)
    ours, bound = [], []
    for seed in seeds:
        info = run_sweep(env, policy, seed)
        assert info["is_success"], (map_name, seed)
        sc = env.unwrapped.scenario
        ours.append(info["travel_ratio"])
        bound.append(occupancy.smartdfs_bound(sc.reachable, 3, sc.start).ratio)
    return np.array(ours), np.array(bound)


def test_smartdfs_ratio_on_a_block_aligned_room() -> None:
    # a 12 x 12 free square, W = 3: 4 x 4 blocks, C = 16, E = 16 boundary edges
    reachable = np.zeros((14, 14), bool)
    reachable[1:13, 1:13] = True
    bound = occupancy.smartdfs_bound(reachable, 3, (1, 1))
    assert (bound.cells, bound.edges) == (16, 16)
    # C + E/2 - 3 = 21 steps of 3 cells = 63 cells, lower bound 144 / 3 = 48 cells
    assert bound.ratio == pytest.approx(63 / 48)


def test_travel_by_mode_adds_up_to_the_travel() -> None:
    info = sweep("maze", seed=0)
    parts = info["travel_by_mode"]
    assert sum(parts.values()) == pytest.approx(info["travel"])
    assert parts["other"] == 0.0
    assert parts["lane"] > parts["transfer"] > 0.0  # lanes do most of the travel


def test_first_shift_takes_the_open_side() -> None:
    # started in the north-east corner heading west: the run's side (right of
    # west = north) is the wall; the first shift goes south and one run sweeps
    # the whole room (18 rows = 6 lanes), with no transfer at all
    info = sweep("room", grid=empty_room(20, 26), options={"start": (1, 22), "heading": 2})
    assert info["is_success"]
    assert info["transfers"] == []
    assert info["travel_by_mode"]["transfer"] == 0.0
    assert info["travel_ratio"] < 1.0  # shifts sweep too


def test_popped_segments_leave_no_wide_region_to_corner_work() -> None:
    # popped segments go back on the stack: PSA itself finds every piece of
    # them, so the maze needs no restart from CWA's scan
    for seed in range(4):
        info = sweep("maze", seed=seed)
        assert info["psa_coverage"] == 1.0
        assert not [e for e in info["transfers"] if e[0] == "restart"]


@pytest.mark.parametrize(
    ("map_name", "ceiling"), [("room", 1.40), ("apartment", 1.60), ("maze", 1.55)]
)
def test_travel_ratio_regression(map_name: str, ceiling: float) -> None:
    # measured (seeds 0-3): room 1.347, apartment 1.555, maze 1.501; before the
    # segment behind a lane: 1.370, 1.617, 1.463; before LIFO by runs, the restart
    # heading and transfers that sweep: 1.51, 1.67, 1.51
    ours, _ = _ratios(map_name, range(4))
    assert ours.mean() < ceiling


@pytest.mark.parametrize("map_name", ["room", "maze"])
def test_travel_below_the_exploration_bound_from_every_start(map_name: str) -> None:
    # room 1.23-1.49 against 1.50-1.62; maze 1.42-1.58 against 1.73
    ours, bound = _ratios(map_name, range(10))
    assert (ours < bound).all()


def test_apartment_travel_below_the_exploration_bound_on_average() -> None:
    # measured 1.533 against 1.674 on average, below from all 10 of these starts
    # (28 of seeds 0-29); the no-hole formula's mean is 1.608
    ours, bound = _ratios("apartment", range(10))
    assert ours.mean() < bound.mean()
    assert (ours < bound).sum() >= 9


def test_apartment_travel_below_the_exploration_bound_from_every_start() -> None:
    # below from seeds 0-9 since transfers follow the quadtree's chain (28 of seeds 0-29;
    # the BFS-transfer ablation: 9 of 0-9, 27 of 0-29, seed 6 at 1.639 against 1.624)
    ours, bound = _ratios("apartment", range(10))
    assert (ours < bound).all()


@pytest.fixture(scope="module")
def procedural() -> tuple[np.ndarray, np.ndarray]:
    """Travel and bound ratios on the reproduction's 50 procedural maps (seeds 1000-1049)."""
    return _ratios("random", range(1000, 1050))


def test_procedural_travel(procedural) -> None:
    ours, bound = procedural
    # measured 1.393 against 1.656 on average, below on 48 of 50 maps (quadtree
    # transfers; 1.381 and 49 of 50 with the BFS-transfer ablation)
    assert ours.mean() < 1.42
    assert ours.mean() < bound.mean()
    assert (ours < bound).sum() >= 48


@pytest.mark.xfail(
    strict=True,
    reason="open: map 1000 is at 1.595 against 1.499 (quadtree transfers; below "
    "with the BFS-transfer ablation), map 1013 at 1.417 against 1.412; the other 48 are below",
)
def test_procedural_travel_below_the_exploration_bound_everywhere(procedural) -> None:
    ours, bound = procedural
    assert (ours < bound).all()
