"""The goal-conditioned variants (motiongym.envs.goal): HER's contract, checked by number."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from motiongym.baselines import make_policy
from motiongym.envs.core import ArgumentError

GOALS = {
    "motiongym/HarvestArmGoal-v1": "motiongym/HarvestArm-v1",
    "motiongym/HarvestArmPlanarGoal-v1": "motiongym/HarvestArmPlanar-v1",
    "motiongym/ExcavatorReachGoal-v1": "motiongym/ExcavatorReach-v1",
}
POLICY = {
    "motiongym/HarvestArmGoal-v1": "potential-field",
    "motiongym/HarvestArmPlanarGoal-v1": "potential-field",
    "motiongym/ExcavatorReachGoal-v1": "newton-raphson-reach",
}


def _episode(env_id: str, policy: str, seed: int, steps: int = 400):
    env = gym.make(env_id)
    pol = make_policy(env_id, policy, env.observation_space, env.action_space, env.spec.kwargs)
    obs, info = env.reset(seed=seed)
    trace = []
    for _ in range(steps):
        action, _ = pol.predict(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        trace.append((obs, action, reward, terminated, info))
        if terminated or truncated:
            break
    return env, trace


@pytest.mark.parametrize("goal_id", GOALS)
def test_scripted_policy_acts_the_same_on_the_goal_id_as_on_its_base(goal_id):
    """The adapter rebuilds the base observation: same actions, same success, step by step."""
    _, goal = _episode(goal_id, POLICY[goal_id], seed=5)
    _, base = _episode(GOALS[goal_id], POLICY[goal_id], seed=5)
    assert len(goal) == len(base)
    np.testing.assert_array_equal([s[1] for s in goal], [s[1] for s in base])
    assert goal[-1][4]["is_success"] == base[-1][4]["is_success"]


@pytest.mark.parametrize("goal_id", GOALS)
def test_compute_reward_and_terminated_agree_with_the_steps(goal_id):
    """Over a scripted episode (it ends in success) and random steps: the reward is
    compute_reward's, success is the base's ``is_success``, termination compute_terminated's."""
    env, trace = _episode(goal_id, POLICY[goal_id], seed=1)
    env.reset(seed=2)
    env.action_space.seed(2)
    for _ in range(60):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        trace.append((obs, None, reward, terminated, info))
        if terminated or truncated:
            break
    u = env.unwrapped
    assert trace[len(trace) - 1][4]["is_success"] or any(s[4]["is_success"] for s in trace)
    for obs, _, reward, terminated, info in trace:
        a, d = obs["achieved_goal"], obs["desired_goal"]
        assert reward == u.compute_reward(a, d, info)
        assert bool(u.fields.success(a, d)) == bool(info["is_success"])
        assert u.compute_terminated(a, d, info) == terminated
        assert u.compute_truncated(a, d, info) is False
        assert sum(v for k, v in info.items() if k.startswith("reward_")) == reward


@pytest.mark.parametrize("goal_id", GOALS)
def test_compute_reward_is_vectorised_and_relabels(goal_id):
    """A batch (as HerReplayBuffer passes it) gives the per-pair rewards; a goal set to
    the achieved one (HER's relabelling) is a success, 0 without collision."""
    env = gym.make(goal_id)
    u = env.unwrapped
    obs, info = env.reset(seed=0)
    a = np.stack([obs["achieved_goal"]] * 4)
    d = np.stack([obs["desired_goal"], obs["achieved_goal"], obs["desired_goal"], a[0]])
    hit = {**info, "cost": 1.0, **{k: 1.0 for k in u.fields.collision_keys}}
    infos = np.array([info, info, hit, hit], dtype=object)
    rewards = u.compute_reward(a, d, infos)
    assert rewards.shape == (4,)
    np.testing.assert_array_equal(rewards, [-1.0, 0.0, -51.0, -50.0])
    assert [u.compute_reward(a[i], d[i], infos[i]) for i in range(4)] == list(rewards)
    np.testing.assert_array_equal(u.compute_terminated(a, d, infos), [False, True, True, True])


def test_collision_penalty_and_cost_weights():
    """Ablation: collision=0 and cost=0 leave the sparse -1/0 alone and need no info
    (HerReplayBuffer's default passes empty dicts); cost=2 charges 2 per unit of cost."""
    env = gym.make("motiongym/HarvestArmGoal-v1", collision=0.0)
    obs, info = env.reset(seed=0)
    a, d = obs["achieved_goal"], obs["desired_goal"]
    assert env.unwrapped.compute_reward(a, d, {}) == -1.0
    charged = gym.make("motiongym/HarvestArmGoal-v1", collision=0.0, cost=2.0).unwrapped
    assert charged.compute_reward(a, d, {**info, "cost": 1.0}) == -3.0
    with pytest.raises(ValueError, match="copy_info_dict=True"):
        gym.make("motiongym/HarvestArmGoal-v1").unwrapped.compute_reward(a, d, {})


def test_excavator_bucket_angle_is_wrapped():
    """A target angle 2 pi away from the bucket's is the same angle (the base's remainder)."""
    env = gym.make("motiongym/ExcavatorReachGoal-v1").unwrapped
    a = np.array([5.0, 0.0, 1.0, 3.1])
    d = a + np.array([0.0, 0.0, 0.0, 2 * np.pi - 0.01])
    assert env.fields.success(a, d)
    assert not env.fields.success(a, a + np.array([0.0, 0.0, 0.0, 0.1]))
    assert not env.fields.success(a, a + np.array([0.06, 0.0, 0.0, 0.0]))


@pytest.mark.parametrize("goal_id", GOALS)
def test_split_and_join_are_inverse(goal_id):
    """The goal Dict and the base observation carry the same numbers."""
    base = gym.make(GOALS[goal_id])
    goal = gym.make(goal_id)
    flat, _ = base.reset(seed=7)
    obs, _ = goal.reset(seed=7)
    fields = goal.unwrapped.fields
    for key, value in fields.split(flat).items():
        np.testing.assert_array_equal(value, obs[key])
    np.testing.assert_allclose(fields.join(obs), flat, atol=1e-6)
    assert obs["observation"].size == flat.size - 2 * fields.size  # goal and error gone


def test_wrong_goal_shape_and_bad_arguments_are_clear_errors():
    env = gym.make("motiongym/HarvestArmPlanarGoal-v1").unwrapped
    with pytest.raises(ValueError, match=r"achieved_goal must have shape \(\.\.\., 2\)"):
        env.compute_reward(np.zeros(3), np.zeros(2), {})
    with pytest.raises(ValueError, match="must match"):
        env.compute_reward(np.zeros((4, 2)), np.zeros((3, 2)), {})
    with pytest.raises(ArgumentError, match="base must be a registered"):
        gym.make("motiongym/HarvestArmGoal-v1", base="motiongym/Nope-v0")
    with pytest.raises(ArgumentError, match="fields must be one of the registered goal fields"):
        gym.make("motiongym/HarvestArmGoal-v1", fields="nowhere")
    with pytest.raises(ArgumentError, match="collision"):
        gym.make("motiongym/HarvestArmGoal-v1", collision=-1.0)
    with pytest.raises(ValueError, match="goal Dict"):
        make_policy(
            "motiongym/HarvestArmGoal-v1",
            "potential-field",
            gym.spaces.Box(-1, 1, (3,)),
            env.action_space,
            gym.spec("motiongym/HarvestArmGoal-v1").kwargs,
        )
