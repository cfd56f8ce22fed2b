"""The dual-arm learner-side lag map (motiongym.agents.learners.dual_arm): what the learner is
shown, checked against pure delays run in the environment; the predictor that rebuilds it
at evaluation; its settings' errors; and its ablation at a small DAgger budget."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch
from dual_arm_runs import run_pure_delay
from stable_baselines3 import SAC

from motiongym.agents.learners.dual_arm import DualArmMapWrapper, check_dual_arm_map_kwargs
from motiongym.agents.learners.memory import MapMemoryPredictor
from motiongym.agents.training.dagger import dagger, on_policy_error
from motiongym.baselines import make_policy
from motiongym.envs.core import ArgumentError
from motiongym.envs.dual_arm.world import tasks_from_observation

V1 = "motiongym/DualArmCell-v1"


def test_the_view_shows_which_delays_the_environment_runs_clear():
    """Waiting at the start of scene 100001, the view's "go now" row (entries 2 ..
    2 + bins) is all clear at step ``x`` exactly when the pure delay ``x`` runs without
    collision in the environment (checked at the first clear step and the one before)."""
    env = DualArmMapWrapper(gym.make(V1), lags=[0, 4], bin_steps=8, bins=64)
    assert env.observation_space.shape == (2 + 2 * 65,)
    obs, _ = env.reset(seed=100001)
    x = 0
    while obs[2 : 2 + 64].any():
        assert set(np.unique(obs[2:66])) <= {0.0, 1.0}
        assert 0.0 <= obs[66] < 1.0  # a collision ahead on "go now"
        obs, *_ = env.step(np.array([1.0, 0.0], np.float32))
        x += 1
    assert obs[66] == 1.0
    bare = gym.make(V1)
    assert run_pure_delay(bare, 100001, x)
    assert not run_pure_delay(bare, 100001, x - 1)


def test_the_either_view_shows_both_orders():
    """``yielding: either``: progress, remaining samples, then per order (robot 2 waiting,
    then robot 1 waiting) its smallest free wait, when both are done after it, and its
    rows. At the start of scene 100001 each order's smallest free wait is the pure delay of
    that robot that the environment runs clear (and one step less collides), and its
    finishing step the run's length; the robot-2 rows are the default view's."""
    lags, bins = [0, 4], 64
    env = DualArmMapWrapper(gym.make(V1), lags=lags, bins=bins, yielding="either")
    plain = DualArmMapWrapper(gym.make(V1), lags=lags, bins=bins)
    rows = len(lags) * (bins + 1)
    assert env.observation_space.shape == (2 + 2 + 2 * (2 + rows) + 1,)
    obs, _ = env.reset(seed=100001)
    shown, _ = plain.reset(seed=100001)
    assert np.array_equal(obs[6 : 6 + rows], shown[2:])
    bare = gym.make(V1)
    horizon = 8 * bins
    n1, n2 = (t.n_samples for t in tasks_from_observation(bare.reset(seed=100001)[0]))
    assert obs[2:4] == pytest.approx([n1 / horizon, n2 / horizon])
    finish = []
    for waiting, start, runs, waits in ((1, 4, n1, n2), (0, 6 + rows, n2, n1)):
        wait = int(round(float(obs[start]) * horizon))
        assert run_pure_delay(bare, 100001, wait, waiting=waiting), waiting
        assert not run_pure_delay(bare, 100001, wait - 1, waiting=waiting), waiting
        finish.append(max(runs, wait + waits))
        assert round(float(obs[start + 1]) * 2 * horizon) == finish[-1]
    assert obs[-1] == pytest.approx(0.5 + 0.5 * np.tanh((finish[1] - finish[0]) / 8))


class _Echo:
    def __init__(self) -> None:
        self.seen: list[np.ndarray] = []

    def predict(self, observation, state=None, episode_start=None, deterministic=True, **kw):
        self.seen.append(np.array(observation, copy=True))
        return np.zeros((len(observation), 2) if np.ndim(observation) > 1 else 2), state


def test_the_predictor_builds_what_the_wrapper_showed_in_training():
    """Single and batched (two sub-environments) observations through MapMemoryPredictor
    give the wrapper's view, step for step, across an episode boundary."""
    bare = [gym.make(V1), gym.make(V1)]
    wrapped = [DualArmMapWrapper(gym.make(V1)), DualArmMapWrapper(gym.make(V1))]
    echo = _Echo()
    predictor = MapMemoryPredictor(echo, bare[0], "dual_arm_map")
    action = np.array([1.0, 0.0], np.float32)
    for seeds in ((100000, 100004), (100005, 100006)):
        obs = np.stack([b.reset(seed=s)[0] for b, s in zip(bare, seeds, strict=True)])
        shown = np.stack([w.reset(seed=s)[0] for w, s in zip(wrapped, seeds, strict=True)])
        for k in range(40):
            predictor.predict(obs, episode_start=np.array([k == 0, k == 0]))
            assert np.array_equal(echo.seen[-1], shown)
            obs = np.stack([b.step(action)[0] for b in bare])
            shown = np.stack([w.step(action)[0] for w in wrapped])
    single = MapMemoryPredictor(echo, bare[0], "dual_arm_map")
    obs, _ = bare[0].reset(seed=100002)
    single.predict(obs, episode_start=np.array([True]))
    assert np.array_equal(echo.seen[-1], wrapped[0].reset(seed=100002)[0])


def test_settings_and_environment_are_checked():
    assert check_dual_arm_map_kwargs({})["bins"] == 64
    with pytest.raises(ArgumentError, match="memory_kwargs must be a mapping"):
        check_dual_arm_map_kwargs([("bins", 8)])
    with pytest.raises(ArgumentError, match="unknown memory_kwargs key 'crop'"):
        check_dual_arm_map_kwargs({"crop": 3})
    for lags in ([4, 0], [0, 0], [], [0, -1], [0, 1.5], "0"):
        with pytest.raises(ArgumentError, match="memory_kwargs.lags"):
            check_dual_arm_map_kwargs({"lags": lags})
    with pytest.raises(ArgumentError, match="memory_kwargs.bins"):
        check_dual_arm_map_kwargs({"bins": 0})
    with pytest.raises(ArgumentError, match="memory_kwargs.first_hit"):
        check_dual_arm_map_kwargs({"first_hit": "no"})
    with pytest.raises(ArgumentError, match="memory_kwargs.sooner"):
        check_dual_arm_map_kwargs({"sooner": 1})
    wrapped = DualArmMapWrapper(gym.make(V1), yielding="either", sooner=False)
    assert wrapped.observation_space.shape == (2 + 2 + 2 * (2 + 8 * 65),)
    for bad in ("robot_1", 1, None):
        with pytest.raises(ArgumentError, match="memory_kwargs.yielding must be one of"):
            check_dual_arm_map_kwargs({"yielding": bad})
    assert DualArmMapWrapper(gym.make(V1), first_hit=False).observation_space.shape == (514,)
    with pytest.raises(ValueError, match="needs a dual-arm environment"):
        DualArmMapWrapper(gym.make("CartPole-v1"))


def _taught(env: gym.Env, teacher, seed: int) -> float:
    torch.manual_seed(seed)
    model = SAC("MlpPolicy", env, policy_kwargs={"net_arch": [128, 128]}, seed=seed)
    dagger(model, env, teacher, 1, 10, 20, training_seed=seed)
    return on_policy_error(model, env, teacher, range(100_000, 100_020))[1]


@pytest.mark.study
def test_the_learner_needs_the_map():
    """The ablation of configs/DualArmCell-v1-dagger.yml's memory at a small budget (10
    teacher and 10 learner episodes, seed 0): with the lag map the learner succeeds on
    held-out scenes 100000-100019 far more often than on the raw observation (measured at
    the full budget in docs/experiments/DualArmCell-v1.md)."""
    bare = gym.make(V1)
    teacher = make_policy(
        V1,
        "boundary-following",
        bare.observation_space,
        bare.action_space,
        dict(bare.spec.kwargs),
        replan=True,
    )
    with_map = _taught(DualArmMapWrapper(gym.make(V1)), teacher, 0)
    without = _taught(gym.make(V1), teacher, 0)
    assert with_map >= 0.9, with_map
    assert with_map >= without + 0.3, (with_map, without)
