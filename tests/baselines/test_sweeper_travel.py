"""Travel of the sweeper's PSA + CWA against the lower bound and SmartDFS's bound.

The issue asks for travel / (area / W) below SmartDFS's ratio
``W (C + E/2 - 3) / (area / W)`` on every map from random starts. The room
meets it from each of seeds 0-9 (38 of seeds 0-39), the maze from 2 of
seeds 0-9, the apartment from none (the ``xfail(strict=True)`` tests say so,
and fail the day they pass). The other tests pin what the PSA choices
documented in ``baselines/sweeper/psa.py`` and ``quadtree.py`` do, with
numbers.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.baselines.sweeper.run import sweep
from motiongym.envs.sweeper import world
from motiongym.envs.sweeper.generator import empty_room

ENV_ID = "motiongym/Sweeper-v0"


def _ratios(map_name: str, seeds: range) -> tuple[np.ndarray, np.ndarray]:
    """Travel ratio and SmartDFS ratio per seeded random start."""
    ours, bound = [], []
    env = gym.make(ENV_ID, map_name=map_name)
    for seed in seeds:
        info = sweep(map_name, seed=seed)
        assert info["is_success"]
        env.reset(seed=seed)
        sc = env.unwrapped.scenario
        ours.append(info["travel_ratio"])
        bound.append(world.smartdfs_bound(sc.reachable, 3, sc.start)[2])
    return np.array(ours), np.array(bound)


def test_smartdfs_ratio_on_a_block_aligned_room() -> None:
    # a 12 x 12 free square, W = 3: 4 x 4 blocks, C = 16, E = 16 boundary edges
    reachable = np.zeros((14, 14), bool)
    reachable[1:13, 1:13] = True
    c_count, edges, ratio = world.smartdfs_bound(reachable, 3, (1, 1))
    assert (c_count, edges) == (16, 16)
    # C + E/2 - 3 = 21 steps of 3 cells = 63 cells, lower bound 144 / 3 = 48 cells
    assert ratio == pytest.approx(63 / 48)


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
    assert info["memory"].log == []
    assert info["travel_by_mode"]["transfer"] == 0.0
    assert info["travel_ratio"] < 1.0  # shifts sweep too


def test_popped_segments_leave_no_wide_region_to_corner_work() -> None:
    # popped segments go back on the stack: PSA itself finds every piece of
    # them, so the maze needs no restart from CWA's scan
    for seed in range(4):
        info = sweep("maze", seed=seed)
        assert info["psa_coverage"] == 1.0
        assert not [e for e in info["memory"].log if e[0] == "restart"]


@pytest.mark.parametrize(
    ("map_name", "ceiling"), [("room", 1.42), ("apartment", 1.66), ("maze", 1.50)]
)
def test_travel_ratio_regression(map_name: str, ceiling: float) -> None:
    # measured (seeds 0-3): room 1.370, apartment 1.617, maze 1.463; before
    # LIFO by runs, the restart heading and transfers that sweep: 1.51, 1.67,
    # 1.51; before the first-shift and re-push choices: 1.52, 1.91, 1.60
    ours, _ = _ratios(map_name, range(4))
    assert ours.mean() < ceiling


def test_room_travel_below_smartdfs() -> None:
    # measured 1.21-1.52 against 1.43-1.55, below at each of these starts (and
    # at 38 of seeds 0-39); 5 of 10 before LIFO by runs and sweeping transfers
    ours, bound = _ratios("room", range(10))
    assert (ours < bound).all()


@pytest.mark.xfail(
    strict=True,
    reason="open: over seeds 0-9 PSA's travel ratio is below SmartDFS's at 2 maze starts "
    "(1.42-1.58 vs 1.453) and no apartment start (1.46-1.72 vs 1.35-1.45); transfers "
    "are 29-34 % of the travel",
)
@pytest.mark.parametrize("map_name", ["apartment", "maze"])
def test_travel_below_smartdfs_on_the_paper_maps(map_name: str) -> None:
    ours, bound = _ratios(map_name, range(4))
    assert (ours < bound).all()


@pytest.fixture(scope="module")
def procedural() -> tuple[np.ndarray, np.ndarray]:
    """Travel and SmartDFS ratios on the reproduction's 50 procedural maps (seeds 1000-1049)."""
    from motiongym.baselines.registry import make_policy
    from motiongym.baselines.sweeper.run import run_episode

    env = gym.make(ENV_ID, map_name="random")
    kwargs = {**gym.spec(ENV_ID).kwargs, "map_name": "random"}
    policy = make_policy(ENV_ID, "psa-cwa", env.observation_space, env.action_space, kwargs)
    ours, bound = [], []
    for seed in range(1000, 1050):
        info = run_episode(env, policy, seed)
        assert info["is_success"], seed
        sc = env.unwrapped.scenario
        ours.append(info["travel_ratio"])
        bound.append(world.smartdfs_bound(sc.reachable, 3, sc.start)[2])
    return np.array(ours), np.array(bound)


def test_procedural_travel(procedural) -> None:
    ours, bound = procedural
    # measured 1.389 and 36 of 50 (1.445 and 25 before LIFO by runs, the restart
    # heading and sweeping transfers; 1.499 before the first-shift choices)
    assert ours.mean() < 1.42
    assert (ours < bound).sum() >= 32


@pytest.mark.xfail(strict=True, reason="open: 36 of the 50 procedural maps are below SmartDFS")
def test_procedural_travel_below_smartdfs_everywhere(procedural) -> None:
    ours, bound = procedural
    assert (ours < bound).all()
