"""The lag map (baselines/dual_arm/lag_map.py) and the re-planning boundary-following
teacher, checked against the environment itself: pure delays run in the environment."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from dual_arm_runs import run_policy, run_pure_delay

from motiongym.baselines import make_policy
from motiongym.baselines.dual_arm import exact_delay
from motiongym.baselines.dual_arm.lag_map import LagMap
from motiongym.envs.dual_arm.task import DT, LAYOUT, tasks_from_observation

V0, V1 = "motiongym/DualArmCell-v0", "motiongym/DualArmCell-v1"


@pytest.mark.parametrize("env_id", [V0, V1])
def test_first_clear_go_is_the_environments_minimum_delay(env_id):
    """Waiting at the start, the first step whose "go now" row is clear is a delay the
    environment runs without collision, and one step earlier collides (scenes 100000-100002,
    v0's check at the samples and v1's over the motion)."""
    env = gym.make(env_id)
    params = env.unwrapped.params
    for seed in (100000, 100001, 100002):
        obs, _ = env.reset(seed=seed)
        lag_map = LagMap(*tasks_from_observation(obs), params.safety_margin, params.collision_check)
        first = next(x for x in range(lag_map.n1 + 1) if lag_map.clear_now(x, 0.0))
        assert first > 0  # "colliding" pairs: starting together collides
        assert run_pure_delay(env, seed, first), (env_id, seed, first)
        assert not run_pure_delay(env, seed, first - 1), (env_id, seed, first)


def test_window_rows_are_the_further_waits():
    """Row ``j`` of the window is "wait lags[j], then go": at the start, row 0 of the window
    at step ``x`` equals row ``w`` at step ``x - w`` (the same pure delay), bin by bin; each
    row's last entry is its first colliding step over the horizon."""
    env = gym.make(V1)
    obs, _ = env.reset(seed=100003)
    lag_map = LagMap(*tasks_from_observation(obs), 0.0, "swept")
    lags = [0, 5, 12]
    later = lag_map.window(12, 0.0, [0], 1, 300)
    earlier = lag_map.window(0, 0.0, lags, 1, 312)
    assert earlier.shape == (3, 313)
    assert np.array_equal(earlier[2, 12:312], later[0, :300])
    assert earlier[2, :12].sum() == lag_map.table[:12, 0].sum()  # waiting at the start
    for row in earlier:
        hits = np.flatnonzero(row[:312])
        assert row[312] == np.float32(hits[0] / 312 if len(hits) else 1.0)


@pytest.mark.parametrize("seed", [100000, 100065])
def test_replanning_teacher_acts_as_the_planned_delay_on_v1(seed):
    """On v1, where boundary following's delay is exact, the re-planning teacher's actions
    along its own episode are the planned schedule's, step for step until robot 2 is done
    (after that the advance moves nothing)."""
    env = gym.make(V1)
    kwargs = dict(env.spec.kwargs)
    plain = make_policy(V1, "boundary-following", env.observation_space, env.action_space, kwargs)
    replan = make_policy(
        V1, "boundary-following", env.observation_space, env.action_space, kwargs, replan=True
    )
    obs, _ = env.reset(seed=seed)
    start, done = np.array([True]), False
    while not done:
        a, _ = plain.predict(obs, episode_start=start)
        b, _ = replan.predict(obs, episode_start=start)
        if obs[LAYOUT["progress"]][1] < 1.0:
            assert np.array_equal(a, b)
        obs, _, terminated, truncated, info = env.step(a)
        start, done = np.array([False]), terminated or truncated
    assert info["is_success"]


@pytest.mark.parametrize("bad", ["yes", 1, None])
def test_replan_must_be_a_bool(bad):
    env = gym.make(V1)
    with pytest.raises(ValueError, match="replan"):
        make_policy(
            V1,
            "boundary-following",
            env.observation_space,
            env.action_space,
            dict(env.spec.kwargs),
            replan=bad,
        )


@pytest.mark.parametrize("env_id", [V0, V1])
def test_robot_1_waiting_is_read_off_the_swapped_table(env_id):
    """``LagMap(traj2, traj1)`` is the map with robot 1 waiting: its first clear "go now"
    at the start is a delay of robot 1 that the environment runs without collision, and one
    step earlier collides (scenes 100000-100002); its moving entries are the transpose of
    the usual table's (each trajectory on its own robot's base)."""
    env = gym.make(env_id)
    params = env.unwrapped.params
    check = params.collision_check
    for seed in (100000, 100001, 100002):
        obs, _ = env.reset(seed=seed)
        traj1, traj2 = tasks_from_observation(obs)
        usual = LagMap(traj1, traj2, params.safety_margin, check)
        swapped = LagMap(traj2, traj1, params.safety_margin, check)
        assert (swapped.lead, swapped.wait) == (1, 0)
        n1, n2 = usual.n1, usual.n2
        moving = usual.table[:n1, 1 : n2 + 1]  # robot 1 on move s1, robot 2 on move k
        assert np.array_equal(swapped.table[:n2, 1 : n1 + 1], moving.T)
        first = swapped.min_wait(0, 0.0)
        assert first is not None and first > 0
        assert run_pure_delay(env, seed, first, waiting=0), (env_id, seed, first)
        assert not run_pure_delay(env, seed, first - 1, waiting=0), (env_id, seed, first)


def test_free_lags_are_the_rows_that_stay_clear():
    """``free_lags`` (all waits at once) agrees with ``blocked`` row by row, and
    ``min_wait`` with its first free row whatever its chunk, from the start and from
    states part-way (scene 100004, v1)."""
    env = gym.make(V1)
    obs, _ = env.reset(seed=100004)
    lag_map = LagMap(*tasks_from_observation(obs), 0.0, "swept")
    for x, p2 in ((0, 0.0), (30, 12.0), (50, 7.5)):
        free = lag_map.free_lags(x, p2)
        horizon = 2 * (lag_map.n1 - x) + lag_map.n2 + 2
        one_by_one = [not lag_map.blocked(x, p2, w, horizon).any() for w in range(len(free))]
        assert free.tolist() == one_by_one
        smallest = int(np.argmax(free)) if free.any() else None
        for chunk in (1, 7, 32, 1000):  # the waits tried a chunk at a time: the same answer
            assert lag_map.min_wait(x, p2, chunk) == smallest


# v1 (its swept check makes the brute force about 4x longer) in the slow tier.
@pytest.mark.parametrize("env_id", [V0, pytest.param(V1, marks=pytest.mark.slow)])
def test_either_waits_is_the_shorter_order_of_the_brute_force(env_id):
    """``either-waits`` runs clear in ``min(max(N1, D2 + N2), max(N2, D1 + N1))`` steps, the
    shorter of both orders' minimum pure delays found by running every delay in the
    environment itself (scenes 100000-100004); the ablation, robot 2 always the one that
    waits (the paper's boundary following), is longer on 3 of these 5 scenes and never
    shorter."""
    env = gym.make(env_id)
    kwargs = dict(env.spec.kwargs)
    either = make_policy(env_id, "either-waits", env.observation_space, env.action_space, kwargs)
    paper = make_policy(
        env_id, "boundary-following", env.observation_space, env.action_space, kwargs
    )
    longer = 0
    for seed in range(100000, 100005):
        obs, _ = env.reset(seed=seed)
        traj1, traj2 = tasks_from_observation(obs)
        n1, n2 = traj1.n_samples, traj2.n_samples
        d2 = next(d for d in range(n1 + 1) if run_pure_delay(env, seed, d, waiting=1))
        d1 = next(d for d in range(n2 + 1) if run_pure_delay(env, seed, d, waiting=0))
        steps = min(max(n1, d2 + n2), max(n2, d1 + n1))
        spans = []
        for policy in (either, paper):
            info = run_policy(env, policy, seed)
            assert info["is_success"], (env_id, seed)
            spans.append(info["makespan"])
        assert spans[0] == pytest.approx(steps * DT), (env_id, seed)
        assert spans[0] <= spans[1] + 1e-9
        longer += spans[1] > spans[0] + 1e-9
    assert longer == 3


def test_either_waits_switching_order_finishes_before_the_closed_form():
    # Scene 100023 (v1): robot 2 waits first (36 steps), then robot 1 yields: robot 1
    # waiting from the start has no free pure delay, but after robot 2's wait it does,
    # and finishes sooner. Both robots wait; the makespan (228 steps) is below the pure
    # delays' bound min(max(N1, D2 + N2), max(N2, D1 + N1)) = 264 (D1 none: 72 + 192).
    env = gym.make(V1)
    kwargs = dict(env.spec.kwargs)
    either = make_policy(V1, "either-waits", env.observation_space, env.action_space, kwargs)
    obs, _ = env.reset(seed=100023)
    traj1, traj2 = env.unwrapped.world.tasks
    actions, done = [], False
    while not done:
        action, _ = either.predict(obs)
        actions.append(action)
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    waits = (np.array(actions) == 0).any(axis=0)
    assert info["is_success"] and waits.all()  # both robots waited
    d2 = exact_delay.true_min_delay(traj1, traj2)
    assert exact_delay.true_min_delay(traj2, traj1) is None
    bound = max(traj1.n_samples, d2 + traj2.n_samples)
    assert (len(actions), bound) == (228, 264)
    assert info["makespan"] == pytest.approx(len(actions) * DT)
