"""Sweeper-v1's line of sight: the stated rule, checked against a brute force, in the env."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.envs.sweeper import sight
from motiongym.envs.sweeper.generator import empty_room


def line(r0: int, c0: int, r1: int, c1: int) -> list[tuple[int, int]]:
    """Bresenham's all-octant line as Wikipedia writes it (x = column, y = row)."""
    x0, y0, x1, y1 = c0, r0, c1, r1
    dx, dy = abs(x1 - x0), -abs(y1 - y0)
    sx, sy = (1 if x0 < x1 else -1), (1 if y0 < y1 else -1)
    err = dx + dy
    cells = []
    while True:
        cells.append((y0, x0))
        if x0 == x1 and y0 == y1:
            return cells
        e2 = 2 * err
        if e2 >= dy:
            err += dy
            x0 += sx
        if e2 <= dx:
            err += dx
            y0 += sy


def brute_visible(obstacles: np.ndarray, w: int, R: int) -> np.ndarray:
    S = w + 2 * R
    out = np.zeros((S, S), bool)
    feet = [(R + a, R + b) for a in range(w) for b in range(w)]
    for tr in range(S):
        for tc in range(S):
            out[tr, tc] = any(
                not any(obstacles[r, c] for r, c in line(fr, fc, tr, tc)[1:-1]) for fr, fc in feet
            )
    return out


def test_textbook_line_matches_the_sight_module_on_every_octant() -> None:
    for r1 in range(-6, 7):
        for c1 in range(-6, 7):
            want = set(line(0, 0, r1, c1)[1:-1])
            k, r, c = sight._lines_between(*(np.array([v]) for v in (0, 0, r1, c1)))
            assert set(zip(r.tolist(), c.tolist(), strict=True)) == want, (r1, c1)


@pytest.mark.parametrize(("w", "R"), [(3, 3), (1, 4), (2, 2), (4, 1)])
def test_visible_equals_brute_force_on_random_windows(w: int, R: int) -> None:
    rng = np.random.default_rng(w * 10 + R)
    S = w + 2 * R
    rays = sight.ray_matrix(w, R)
    batch = []
    for _ in range(30):
        obstacles = rng.random((S, S)) < 0.3
        obstacles[R : R + w, R : R + w] = False
        got = sight.visible(obstacles.ravel(), rays).reshape(S, S)
        np.testing.assert_array_equal(got, brute_visible(obstacles, w, R))
        batch.append(obstacles.ravel())
    batch = np.array(batch)
    np.testing.assert_array_equal(
        sight.visible(batch, rays), [sight.visible(b, rays) for b in batch]
    )


def test_pillar_behind_a_wall_is_not_sensed_in_v1_and_is_in_v0() -> None:
    grid = empty_room(11, 14)
    grid[2:9, 6] = True  # a 1-cell wall right of the robot, one free column away
    grid[5, 7] = True  # a pillar just behind it
    obs = {}
    for env_id in ("motiongym/Sweeper-v0", "motiongym/Sweeper-v1"):
        env = gym.make(env_id, grid=grid)
        obs[env_id], _ = env.reset(seed=0, options={"start": (4, 2), "heading": 0})
    # w = 3, R = 3: map cell (y, x) is window cell (y - 4 + 3, x - 2 + 3) = (y - 1, x + 1)
    pillar, behind, wall, front = (4, 8), (2, 8), (4, 7), (4, 6)
    v0 = obs["motiongym/Sweeper-v0"]["sensed"].reshape(9, 9)
    v1 = obs["motiongym/Sweeper-v1"]["sensed"].reshape(9, 9)
    known = obs["motiongym/Sweeper-v1"]["known"].reshape(9, 9)
    assert "known" not in obs["motiongym/Sweeper-v0"]
    assert v0[pillar] == 1.0 and v1[pillar] == 0.0  # v0 sees through the wall, v1 does not
    assert known[pillar] == 0.0 and known[behind] == 0.0  # behind the wall: unknown
    assert v1[wall] == 1.0 and known[wall] == 1.0  # the wall itself is sensed
    assert known[front] == 1.0 and v1[front] == 0.0  # the floor in front of it: known free
    assert known[3:6, 3:6].all()  # the footprint
    assert (v1 <= known).all() and (v1 <= v0).all()  # sensed obstacles are known, and real


def test_v1_belief_holds_only_sensed_obstacles() -> None:
    """The coarse obstacle map of v1 never counts more than v0's, and less behind walls."""
    totals = {}
    for env_id in ("motiongym/Sweeper-v0", "motiongym/Sweeper-v1"):
        env = gym.make(env_id, map_name="apartment")
        obs, _ = env.reset(seed=2)
        rng = np.random.default_rng(2)
        for _ in range(300):
            obs, *_ = env.step(int(rng.choice(3, p=[0.6, 0.2, 0.2])))
        totals[env_id] = float(obs["obstacle_map"].sum())
    assert totals["motiongym/Sweeper-v1"] < totals["motiongym/Sweeper-v0"]


def test_ray_matrix_size_for_the_default_robot() -> None:
    """The size the docstring states for the default robot (w = 3, R = 3)."""
    assert sight.ray_matrix(3, 3).nnz == 1544
    S, w = 3 + 2 * 3, 3
    assert sight.ray_matrix(3, 3).shape == (S * S * w * w, S * S)
