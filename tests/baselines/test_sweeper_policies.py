"""The sweeper's scripted policies: PSA + CWA sweeps everything; the weak baseline does not."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.agents.reproduce.sweeper_runs import run_sweep, sweep
from motiongym.baselines.registry import make_policy, scripted_policies
from motiongym.envs.sweeper.generator import empty_room

ENV_ID = "motiongym/Sweeper-v0"


def test_policies_declared() -> None:
    assert set(scripted_policies(ENV_ID)) == {"psa-cwa", "psa-cwa-nearest", "wall-follow"}


@pytest.mark.parametrize("map_name", ["room", "apartment", "maze"])
def test_psa_cwa_sweeps_every_reachable_cell_of_the_paper_maps(map_name: str) -> None:
    for seed in range(2):
        info = sweep(map_name, seed=seed)
        assert info["is_success"] and info["coverage"] == 1.0
        assert info["bumps"] == 0  # it senses what is ahead
        assert 1.0 <= info["travel_ratio"] < 2.5
        assert info["psa_coverage"] > 0.9  # PSA does most of it, CWA the corners


def _procedural(n: int, first_seed: int) -> None:
    env = gym.make(ENV_ID, map_name="random")
    kwargs = {**gym.spec(ENV_ID).kwargs, "map_name": "random"}
    policy = make_policy(ENV_ID, "psa-cwa", env.observation_space, env.action_space, kwargs)
    for seed in range(first_seed, first_seed + n):
        info = run_sweep(env, policy, seed)
        assert info["is_success"], (seed, info["coverage"])


def test_psa_cwa_sweeps_procedural_maps() -> None:
    _procedural(8, 0)


@pytest.mark.slow
def test_psa_cwa_sweeps_fifty_procedural_maps() -> None:
    _procedural(50, 1000)


def test_psa_cwa_through_sb3_predict_and_episode_start() -> None:
    env = gym.make(ENV_ID, map_name="room")
    policy = make_policy(ENV_ID, "psa-cwa", env.observation_space, env.action_space, {})
    for seed in (0, 1):  # two episodes: memory must be reset by episode_start
        obs, _ = env.reset(seed=seed)
        start = True
        while True:
            action, _ = policy.predict(obs, episode_start=np.array([start]))
            start = False
            obs, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                break
        assert info["is_success"]


def test_psa_cwa_same_seed_same_trajectory() -> None:
    a, b = sweep("maze", seed=5), sweep("maze", seed=5)
    assert (a["travel"], a["turns"], a["steps"]) == (b["travel"], b["turns"], b["steps"])


def test_psa_cwa_other_robot_widths_and_sensor_range() -> None:
    for kwargs in ({"robot_width": 2}, {"robot_width": 4}, {"robot_width": 3, "sensor_range": 1}):
        info = sweep("apartment", seed=0, **kwargs)
        assert info["is_success"], kwargs


def test_psa_cwa_user_map_from_grid() -> None:
    grid = empty_room(20, 26)
    grid[5:9, 6:20] = True
    info = sweep("room", seed=0, grid=grid)
    assert info["is_success"] and info["travel_ratio"] < 1.6


def test_wall_follow_is_weaker_than_psa_on_the_empty_room() -> None:
    room = empty_room(30, 40)
    psa = sweep("room", seed=0, grid=room)
    weak = sweep("room", seed=0, grid=room, policy="wall-follow", max_steps=psa["steps"])
    assert psa["coverage"] == 1.0
    assert 0.5 < weak["coverage"] < 1.0
    assert weak["overlap"] > psa["overlap"]


def test_psa_cwa_under_odometry_noise_keeps_sweeping() -> None:
    info = sweep("room", seed=0, slip_noise=0.05, max_steps=3000)
    assert info["coverage"] > 0.8
    assert np.isfinite(info["travel"])


def test_nearest_first_ablation_also_sweeps_everything() -> None:
    for map_name in ("apartment", "maze"):
        info = sweep(map_name, seed=0, policy="psa-cwa-nearest")
        assert info["is_success"]


def _popping(entries: list[tuple[tuple[int, int], int]], retry: bool = False) -> tuple[int, int]:
    """Where PSA + CWA transfers to from (8, 10) in an empty room, given stack entries
    ``(segment start, run)`` (segments heading east, 3 long, bottom to top)."""
    from motiongym.baselines.sweeper import psa
    from motiongym.baselines.sweeper.psa_cwa import PsaCwaPolicy

    env = gym.make(ENV_ID, grid=empty_room(20, 26))
    policy = PsaCwaPolicy(env.observation_space, env.action_space, {})
    obs, _ = env.reset(seed=0, options={"start": (8, 10), "heading": 0})
    memory = policy.new_memory()
    policy.act(obs, memory)  # writes the first window into the robot's maps
    memory.stack = psa.PsaStack()
    for start, run in entries:
        memory.stack.push(psa.Segment(start, 0, 3, 3), run)
    memory.retry = retry
    policy._pop(memory, 8, 10, 0)
    assert memory.mode == "transfer"
    return memory.goal


def test_pop_takes_the_nearest_entry_of_the_latest_run() -> None:
    near, far = ((8, 14), 1), ((13, 4), 1)
    assert _popping([near, far]) == (8, 14)  # the top entry is farther: LIFO by runs
    assert _popping([(near[0], 0), (far[0], 1)]) == (13, 6)  # an older run waits (nearer end)


def test_pop_after_an_aborted_transfer_retries_the_top_entry() -> None:
    near, far = ((8, 14), 1), ((13, 4), 1)
    assert _popping([near, far], retry=True) == (13, 6)


def test_region_behind_the_last_lane_is_pushed_and_swept_by_psa() -> None:
    # a cupboard along the north wall leaves a strip one robot width wide beside
    # it; the fifth lane (cols 13-15, heading south) starts at the cupboard's
    # corner with that strip behind it, beside no lane, so only the segment in
    # line behind the lane holds it
    grid = empty_room(16, 17)
    grid[1:7, 1:13] = True
    options = {"start": (7, 1), "heading": 3}
    env = gym.make(ENV_ID, grid=grid)
    policy = make_policy(ENV_ID, "psa-cwa", env.observation_space, env.action_space, {})
    info = run_sweep(env, policy, 0, options)
    assert info["is_success"]
    assert info["transfers"] == [("transfer", (12, 13), (6, 13))]  # popped from the stack
    policy.push_behind = False
    info = run_sweep(env, policy, 0, options)
    assert info["transfers"] == [("restart", (12, 13), (4, 13))]  # found by CWA's scan
