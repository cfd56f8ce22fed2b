"""The exact minimum delay of DualArmCell-v1 by boundary following (``bracket``).

Independent truths: the v1 environment itself (a pure delay run step by step),
and the brute force over every delay on the environment's step check, which
uses neither map nor boundary following.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.agents.evaluation.episodes import run_episode
from motiongym.agents.reproduce.dual_arm_truth import at_rest_pair
from motiongym.baselines import make_policy
from motiongym.baselines.dual_arm import bracket, exact_delay, schedules
from motiongym.baselines.dual_arm.boundary_following import boundary_following
from motiongym.baselines.dual_arm.collision_map import CollisionMap
from motiongym.baselines.dual_arm.exact_delay import free_delays, step_table
from motiongym.baselines.dual_arm.step_check import StepCheck
from motiongym.envs.dual_arm import motion, task

V1 = "motiongym/DualArmCell-v1"
KW = {**gym.spec(V1).kwargs, "control": "robot_2"}  # what the policy is told of the env


def _pair(seed):
    return task.sample_pair(np.random.default_rng(seed), "colliding")


def _env_collides(traj1, traj2, delay):
    """Run the pure delay in DualArmCell-v1: does any step collide?"""
    env = gym.make(V1).unwrapped
    env.reset(seed=0)
    env.world.load(traj1, traj2)
    for step in range(traj1.n_samples + traj2.n_samples + delay + 2):
        _, _, terminated, _, info = env.step(np.array([1.0, 1.0 if step >= delay else 0.0]))
        if info["collision"]:
            return True
        if terminated:
            return False
    raise AssertionError("the episode did not end")


@pytest.fixture(scope="module")
def truths():
    out = {}
    for seed in (20_000, 20_001):
        t1, t2 = _pair(seed)
        free = free_delays(step_table(t1, t2), t1.n_samples, t2.n_samples)
        out[seed] = (t1, t2, free)
    return out


def test_the_step_check_is_the_environments(truths):
    t1, t2, free = truths[20_000]
    best = int(np.flatnonzero(free)[0])
    for delay in (0, best - 2, best - 1, best, best + 1, t1.n_samples):
        assert _env_collides(t1, t2, delay) == (not free[delay])
        assert StepCheck(t1, t2).delay_collides(delay) == (not free[delay])


def test_many_steps_at_once_give_the_same_verdicts():
    t1, t2 = _pair(20_002)
    q1, q2 = t1.samples(), t2.samples()
    rng = np.random.default_rng(0)
    s1 = rng.integers(0, t1.n_samples, 60)
    s2 = rng.integers(0, t2.n_samples, 60)
    spans1, spans2 = np.stack([s1, s1 + 1], 1), np.stack([s2, s2 + 1], 1)
    many = motion.simultaneous_collide_many(q1, spans1, q2, spans2, 0.0)
    pairs = zip(spans1, spans2, strict=True)
    one = [motion.simultaneous_collide(q1, a, q2, b, 0.0) for a, b in pairs]
    assert many.tolist() == one
    assert 0 < many.sum() < 60


def test_the_maps_bracket_every_delay(truths):
    # lower map: every delay free on the environment's check is free on it;
    # upper map: every delay free on it is free on the environment's check.
    t1, t2, free = truths[20_001]
    check = StepCheck(t1, t2)
    check.table()  # every verdict at once (the maps then read them)
    lower = CollisionMap.from_steps(check, t2, 100, "lower")
    upper = CollisionMap.from_steps(check, t2, 100, "upper")
    for delay in range(t1.n_samples + 1):
        if free[delay]:
            assert schedules.curve_is_free(lower, delay)
        if schedules.curve_is_free(upper, delay):
            assert free[delay]
    d_lo = schedules.exhaustive_min_delay(lower)
    d_hi = schedules.exhaustive_min_delay(upper)
    assert d_lo <= int(np.flatnonzero(free)[0]) <= d_hi


@pytest.mark.parametrize("seed", [20_000, 20_001])
def test_equal_to_the_brute_force(truths, seed):
    t1, t2, free = truths[seed]
    plan = bracket.exact_delay_search(t1, t2)
    assert plan.delay == int(np.flatnonzero(free)[0])
    assert plan.lower <= plan.delay and plan.checked == plan.delay - plan.lower + 1


def test_ablations_each_part_earns_its_place():
    # Seed 20_001: boundary following on the lower map alone is early (its delay
    # collides), on the upper map alone late; the exact checks from the lower
    # map's delay need two checks where a scan from 0 needs the delay + 1.
    t1, t2 = _pair(20_001)
    check = StepCheck(t1, t2)
    plan = bracket.exact_delay_search(t1, t2)
    assert plan.delay == 22 and plan.lower == 21 and plan.checked == 2
    assert check.delay_collides(plan.lower)
    upper = boundary_following(CollisionMap.from_steps(check, t2, 100, "upper")).delay
    assert upper == 26 and not check.delay_collides(upper)


@pytest.mark.parametrize("where", ["start", "end"])
def test_arms_that_collide_at_rest_are_reported_not_delayed(where):
    t1, t2 = at_rest_pair(where)
    plan = bracket.exact_delay_search(t1, t2)
    assert plan.delay is None
    assert plan.reason == f"the arms collide at rest ({where} configurations)"
    env = gym.make(V1, control="robot_2")
    policy = make_policy(V1, "boundary-following", env.observation_space, env.action_space, KW)
    env.reset(seed=0)
    base = env.unwrapped
    base.world.reset((t1, t2), base.np_random)  # this pair in place of the sampled one
    base.task.begin(base.world)
    policy.reset()
    policy.predict(base.task.observe(base.world))
    diagnostics = policy.diagnostics()
    assert diagnostics["fallback"] and diagnostics["reason"] == plan.reason


@pytest.mark.parametrize("seed", [20_000, 20_001])
def test_the_v1_policy_takes_the_exact_delay(truths, seed):
    t1, t2, free = truths[seed]
    env = gym.make(V1, control="robot_2")
    policy = make_policy(V1, "boundary-following", env.observation_space, env.action_space, KW)
    info = run_episode(env, policy, seed)  # reset(seed) samples the same pair
    np.testing.assert_array_equal(env.unwrapped.world.tasks[1].vias, t2.vias)
    d = policy.diagnostics()
    assert d["delay"] == int(np.flatnonzero(free)[0])
    assert d["replans"] == 0 and not d["fallback"]
    assert info["is_success"]
    assert info["makespan"] == pytest.approx(max(t1.n_samples, d["delay"] + t2.n_samples) * 0.02)


@pytest.mark.slow
def test_equal_to_the_brute_force_on_many_pairs():
    for seed in range(30_000, 30_030):
        t1, t2 = _pair(seed)
        free = free_delays(step_table(t1, t2), t1.n_samples, t2.n_samples)
        assert bracket.exact_delay_search(t1, t2).delay == int(np.flatnonzero(free)[0]), seed


@pytest.mark.parametrize(
    ("kwargs", "name"), [({"n_levels": 0}, "n_levels"), ({"margin": -1.0}, "margin")]
)
def test_bad_input_names_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=name):
        bracket.exact_delay_search(*task.paper_case(), **kwargs)


def test_a_policy_told_only_the_control_plans_on_its_ids_check():
    # Told {"control": "both"} alone, the policy used to plan on the parameters' defaults
    # (v0's samples): on this pair it chose 82, one step before v1's minimum 83, with no
    # re-plan, and collided between samples (sampled distance 0.43 mm).
    env = gym.make(V1)
    policy = make_policy(V1, "boundary-following", env.observation_space, env.action_space,
                         {"control": "both"})  # fmt: skip
    assert (policy.check, policy.safety_margin) == ("swept", 0.0)
    info = run_episode(env, policy, 610_030)
    t1, t2 = env.unwrapped.world.tasks
    assert policy.diagnostics()["delay"] == exact_delay.true_min_delay(t1, t2) == 83
    assert info["is_success"]
    v0 = make_policy(V1, "boundary-following", env.observation_space, env.action_space,
                     {"collision_check": "samples"})  # fmt: skip
    assert v0.check == "samples"  # what the caller says wins over the ID's registration
