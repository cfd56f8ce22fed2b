"""Property-based hostile input (Hypothesis): the parallel env and the policies' ``predict``.

PettingZoo's dual-arm env: its keywords and each agent's action give a clear
error naming the argument, or finite observations and rewards. Every scripted
policy's ``predict``: a damaged observation (an entry NaN, inf, huge or
negative; the wrong shape or type) gives a ``ValueError`` naming the
observation, or an action inside the action space.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from fuzzing import OUTCOMES, PROFILE
from hypothesis import given
from hypothesis import strategies as st

import motiongym  # noqa: F401
from motiongym.agents.environments import resolved_env_kwargs
from motiongym.baselines import make_policy, scripted_policies
from motiongym.envs import ENV_IDS
from motiongym.envs.dual_arm.parallel import DualArmParallelEnv

WEIRD = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, 1, -1, 0.5, 1e300, 10**5, "", "both", "swept", "samples"]),
    st.text(max_size=4),
    st.lists(st.floats(allow_nan=True), max_size=3),
    st.complex_numbers(max_magnitude=1e3),
)
PARALLEL_KEYWORDS = [
    "max_steps",
    "pairs",
    "task",
    "safety_margin",
    "clearance_distance",
    "time",
    "control",
]


@given(name=st.sampled_from(PARALLEL_KEYWORDS), value=WEIRD, seed=st.integers(0, 2**31))
def test_parallel_env_keywords_give_a_clear_error_or_a_valid_world(name, value, seed):
    try:
        env = DualArmParallelEnv(**{name: value})
    except ValueError as error:
        assert name in str(error), f"{name}={value!r}: {error}"
        OUTCOMES["parallel env kwargs: clear error"] += 1
        return
    observations, _ = env.reset(seed=seed)
    for _ in range(3):
        actions = {agent: env.action_space(agent).sample() for agent in env.agents}
        observations, rewards, *_ = env.step(actions)
        assert all(np.isfinite(o).all() for o in observations.values())
        assert all(math.isfinite(r) for r in rewards.values())
        if not env.agents:
            break
    env.close()
    OUTCOMES["parallel env kwargs: valid"] += 1


@given(
    agent=st.sampled_from(["robot_1", "robot_2", "robot_3", 0]),
    action=st.one_of(WEIRD, st.just(np.array([[0.5]])), st.just(np.float32([0.5]))),
)
def test_parallel_env_actions_are_checked_per_agent(agent, action):
    env = DualArmParallelEnv()
    env.reset(seed=0)
    actions = {"robot_1": np.float32([0.5]), "robot_2": np.float32([0.5]), agent: action}
    try:
        observations, rewards, *_ = env.step(actions)
    except ValueError as error:
        assert "action" in str(error), f"{agent}: {action!r}: {error}"
        OUTCOMES["parallel env actions: clear error"] += 1
        return
    assert all(np.isfinite(o).all() for o in observations.values())
    assert all(math.isfinite(r) for r in rewards.values())
    OUTCOMES["parallel env actions: valid"] += 1


def test_parallel_env_step_before_reset_is_a_clear_error():
    with pytest.raises(RuntimeError, match="reset"):
        DualArmParallelEnv().step({"robot_1": [0.5], "robot_2": [0.5]})


# The fast slice: one ID per world (the newest); the full run: every ID.
POLICY_IDS = [
    i
    for i in ENV_IDS
    if scripted_policies(i)
    and (PROFILE == "fuzz" or not any(j > i and j[:-3] == i[:-3] for j in ENV_IDS))
]
CASES = [(env_id, name) for env_id in POLICY_IDS for name in sorted(scripted_policies(env_id))]


def _damaged(observation, data):
    """One entry of ``observation`` replaced, or the whole of it swapped for something wrong."""
    kind = data.draw(st.sampled_from(["entry", "scaled", "shape", "type"]), label="damage")
    if kind == "type":
        return data.draw(WEIRD, label="observation")
    if isinstance(observation, dict):
        key = data.draw(st.sampled_from(sorted(observation)), label="key")
        return {**observation, key: _damaged_array(observation[key], kind, data)}
    return _damaged_array(observation, kind, data)


def _damaged_array(array, kind, data):
    a = np.array(array, dtype=np.float64 if kind != "shape" else None)
    if kind == "shape":
        return a.reshape(-1)[: data.draw(st.integers(0, max(a.size - 1, 0)))]
    if kind == "scaled":
        return a * data.draw(st.sampled_from([-1.0, 1e3, 1e9, -1e9]))
    index = data.draw(st.integers(0, max(a.size - 1, 0)), label="index")
    a.reshape(-1)[index] = data.draw(
        st.sampled_from([np.nan, np.inf, -np.inf, 1e300, -1e300, -1.0, 0.0]), label="value"
    )
    return a


@pytest.mark.parametrize(("env_id", "policy_name"), CASES)
@given(data=st.data())
def test_predict_gives_a_clear_error_or_an_action_in_the_space(env_id, policy_name, data):
    env = gym.make(env_id)
    observation, _ = env.reset(seed=data.draw(st.integers(0, 2**31), label="seed"))
    policy = make_policy(
        env_id,
        policy_name,
        env.observation_space,
        env.action_space,
        resolved_env_kwargs(env_id, None),
    )
    damaged = _damaged(observation, data)
    try:
        action, _ = policy.predict(damaged, episode_start=np.array([True]))
    except ValueError as error:
        assert "observation" in str(error), f"{policy_name}: {error}"
        OUTCOMES["predict: clear error"] += 1
        return
    finally:
        env.close()
    space = env.action_space
    action = np.asarray(action, dtype=space.dtype)
    assert space.contains(action) or space.contains(action.reshape(space.shape)), action
    OUTCOMES["predict: valid"] += 1
