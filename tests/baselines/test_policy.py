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
