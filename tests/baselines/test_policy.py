"""The scripted-policy base: SB3's predictor protocol, batching and per-episode memory."""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from motiongym.baselines.policy import ScriptedPolicy


class CountingPolicy(ScriptedPolicy):
    """Acts with the number of steps since its episode began."""

    def new_memory(self) -> dict:
        return {"steps": 0}

    def act(self, observation, memory):
        memory["steps"] += 1
        return np.array([memory["steps"]])


BOX = spaces.Box(-1.0, 1.0, shape=(3,))
DICT = spaces.Dict({"a": spaces.Box(-1.0, 1.0, shape=(2,)), "b": spaces.MultiBinary(4)})
ACTION = spaces.Box(0.0, 1e6, shape=(1,))


def test_unbatched_memory_persists_until_episode_start():
    policy = CountingPolicy(BOX, ACTION)
    observation = BOX.sample()
    counts = [policy.predict(observation)[0][0] for _ in range(3)]
    assert counts == [1, 2, 3]
    action, state = policy.predict(observation, state="s", episode_start=True)
    assert action[0] == 1 and state == "s"
    policy.reset()
    assert policy.predict(observation)[0][0] == 1


def test_batched_observations_keep_one_memory_per_environment():
    policy = CountingPolicy(BOX, ACTION)
    batch = np.stack([BOX.sample() for _ in range(3)])
    policy.predict(batch, episode_start=np.ones(3, bool))
    actions, _ = policy.predict(batch, episode_start=np.array([False, True, False]))
    assert actions.shape == (3, 1)
    np.testing.assert_array_equal(actions[:, 0], [2, 1, 2])


def test_dict_observations_batched_and_not():
    policy = CountingPolicy(DICT, ACTION)
    single = DICT.sample()
    assert policy.predict(single)[0].shape == (1,)
    batch = {key: np.stack([DICT.sample()[key] for _ in range(2)]) for key in DICT.spaces}
    assert policy.predict(batch)[0].shape == (2, 1)


def test_observations_outside_the_space_are_a_value_error_naming_them():
    import pytest

    policy = CountingPolicy(BOX, ACTION)
    for bad, expected in [
        (np.array([0.0, np.nan, 0.0]), "observation must be finite"),
        (np.array([0.0, 0.0]), r"shape \(3,\)"),
        ("abc", r"shape \(3,\)"),
        (np.array([0.0, 5.0, 0.0]), r"observation\[1\] = 5 is outside .* \[-1, 1\]"),
        (np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -3.0]]), r"observation\[1, 2\] = -3"),
    ]:
        with pytest.raises(ValueError, match=expected):
            policy.predict(bad)
    dict_policy = CountingPolicy(DICT, ACTION)
    with pytest.raises(ValueError, match=r"keys \['a', 'b'\]"):
        dict_policy.predict({"a": np.zeros(2)})
    with pytest.raises(ValueError, match=r"observation\['a'\]\[0\] = 2"):
        dict_policy.predict({"a": np.array([2.0, 0.0]), "b": np.zeros(4, np.int8)})
    assert policy.predict(np.array([1.0, -1.0, 0.5]))[0][0] == 1  # the bounds themselves


def test_a_planner_is_never_fed_an_observation_no_environment_makes():
    """Ablation of the bounds check: the dual-arm planner given a path 10**9 times
    too long once allocated without bound (MemoryError); now refused before planning."""
    import gymnasium as gym
    import pytest

    from motiongym.agents.environments import resolved_env_kwargs
    from motiongym.baselines import make_policy

    env_id = "motiongym/DualArmCell-v1"
    env = gym.make(env_id)
    observation, _ = env.reset(seed=0)
    policy = make_policy(
        env_id,
        "min-makespan",
        env.observation_space,
        env.action_space,
        resolved_env_kwargs(env_id, None),
    )
    with pytest.raises(ValueError, match="outside the observation space"):
        policy.predict(observation * 1e9)
    assert env.action_space.contains(policy.predict(observation)[0].astype(np.float32))
