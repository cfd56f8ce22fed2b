"""The shared-parameter policy over the dual-arm PettingZoo env: VecEnv, training, evaluation."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import evaluate
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.training.multiagent import (
    SharedPolicyPredictor,
    SharedPolicyVecEnv,
    parallel_factory,
    slot_observations,
)
from motiongym.agents.training.train import train

DUAL_ARM = "motiongym/DualArmCell-v0"
OBS = 94  # the cell's observation

SHARED_CONFIG = """
ppo:
  n_envs: 2
  n_timesteps: 256
  policy: MlpPolicy
  policy_kwargs: {net_arch: [16]}
  vec_env: pettingzoo
  n_steps: 32
  batch_size: 64
  n_epochs: 1
  normalize: true
  eval_freq: 128
  n_eval_episodes: 1
  env_kwargs: {max_steps: 40}
"""


def _venv(n_copies: int, **kwargs) -> SharedPolicyVecEnv:
    factory = parallel_factory(DUAL_ARM)
    return SharedPolicyVecEnv(lambda: factory(**kwargs), n_copies)


def test_slots_are_copy_major_with_the_agents_one_hot_index():
    venv = _venv(3)
    assert venv.num_envs == 6 and venv.agents == ["robot_1", "robot_2"]
    assert venv.observation_space.shape == (OBS + 2,)
    assert venv.action_space.shape == (1,)
    venv.seed(0)
    observations = venv.reset()
    assert observations.shape == (6, OBS + 2) and observations.dtype == np.float32
    np.testing.assert_array_equal(observations[:, OBS:], np.tile(np.eye(2), (3, 1)))
    # Both agents of a copy see the cell's observation; copies differ (seeds 0, 1, 2).
    np.testing.assert_array_equal(observations[0, :OBS], observations[1, :OBS])
    assert not np.array_equal(observations[0, :OBS], observations[2, :OBS])
    assert all(venv.observation_space.contains(row) for row in observations)


def test_copy_k_is_reset_with_seed_plus_k():
    venv = _venv(2)
    venv.seed(7)
    observations = venv.reset()
    env = parallel_factory(DUAL_ARM)()
    for k in range(2):
        expected, _ = env.reset(seed=7 + k)
        np.testing.assert_array_equal(observations[2 * k, :OBS], expected["robot_1"])


def test_same_seed_same_steps():
    def rollout() -> list[np.ndarray]:
        venv = _venv(2, max_steps=30)
        venv.seed(3)
        trace = [venv.reset()]
        actions = np.random.default_rng(0).uniform(0, 1, (60, 4, 1)).astype(np.float32)
        for action in actions:
            observation, reward, done, _ = venv.step(action)
            trace += [observation, reward, done]
        return trace

    for first, second in zip(rollout(), rollout(), strict=True):
        np.testing.assert_array_equal(first, second)


def test_each_slot_acts_for_its_own_arm():
    venv = _venv(1)
    venv.seed(0)
    venv.reset()
    observations, rewards, _, infos = venv.step(np.array([[1.0], [0.0]], dtype=np.float32))
    assert infos[0]["progress_1"] == pytest.approx(1.0)
    assert infos[0]["progress_2"] == pytest.approx(0.0)
    assert rewards[0] == rewards[1]  # the shared reward, once per agent


def test_one_copy_steps_as_the_single_agent_view():
    venv = _venv(1)
    env = make_env(DUAL_ARM)
    venv.seed(11)
    slots = venv.reset()
    observation, _ = env.reset(seed=11)
    actions = np.random.default_rng(1).uniform(0, 1, (400, 2)).astype(np.float32)
    for action in actions:
        np.testing.assert_array_equal(slots[:, :OBS], [observation, observation])
        slots, rewards, dones, infos = venv.step(action.reshape(2, 1))
        observation, reward, terminated, truncated, info = env.step(action)
        np.testing.assert_allclose(rewards, [reward, reward], rtol=1e-6)
        assert dones.all() == (terminated or truncated)
        if dones.all():
            np.testing.assert_array_equal(infos[0]["terminal_observation"][:OBS], observation)
            break
    assert dones.all()  # the colliding tasks end well within 400 random steps


def test_a_truncated_copy_ends_every_slot_reports_its_terminal_observation_and_resets():
    venv = _venv(2, max_steps=5)
    venv.seed(0)
    venv.reset()
    waiting = np.zeros((4, 1), dtype=np.float32)  # never collide, never finish
    for _ in range(4):
        _, _, dones, infos = venv.step(waiting)
        assert not dones.any() and not any(info["TimeLimit.truncated"] for info in infos)
    observations, _, dones, infos = venv.step(waiting)
    assert dones.all()
    for slot, info in enumerate(infos):
        assert info["TimeLimit.truncated"]
        terminal = info["terminal_observation"]
        np.testing.assert_array_equal(terminal[OBS:], np.eye(2)[slot % 2])
        assert terminal[14] == pytest.approx(5 * 0.02)  # elapsed time at the end
    assert np.all(observations[:, 14] == 0.0)  # the next episodes' first observations


def test_a_terminated_copy_is_not_a_truncation():
    venv = _venv(1)
    venv.seed(0)
    venv.reset()
    full_speed = np.ones((2, 1), dtype=np.float32)  # colliding tasks: they meet or finish
    for _ in range(1000):
        _, _, dones, infos = venv.step(full_speed)
        if dones.any():
            break
    assert dones.all()
    assert not infos[0]["TimeLimit.truncated"] and "terminal_observation" in infos[1]


def test_slot_observations_of_a_batch():
    per_agent = np.arange(12, dtype=np.float32).reshape(2, 2, 3)  # (B, n, d)
    slots = slot_observations(per_agent)
    np.testing.assert_array_equal(slots[3], [9, 10, 11, 0, 1])  # batch 1, agent 1


class _SlotEcho:
    """Acts with the first observation entry plus the agent's index (slot's one-hot)."""

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        index = observation[:, -2:].argmax(axis=1)
        return (observation[:, :1] + index[:, None]).astype(np.float32), state


def test_predictor_assembles_the_joint_action_in_agent_order():
    predictor = SharedPolicyPredictor(_SlotEcho(), n_agents=2)
    action, _ = predictor.predict(np.full(OBS, 0.25))
    np.testing.assert_allclose(action, [0.25, 1.25])
    batch, _ = predictor.predict(np.array([np.zeros(OBS), np.ones(OBS)]))
    np.testing.assert_allclose(batch, [[0.0, 1.0], [1.0, 2.0]])


def test_an_id_without_a_parallel_version_is_refused(tmp_path):
    with pytest.raises(UsageError, match="no PettingZoo parallel version.*DualArmCell-v0"):
        parallel_factory("motiongym/Sweeper-v0")
    config = tmp_path / "shared.yml"
    config.write_text(SHARED_CONFIG.replace("  env_kwargs: {max_steps: 40}\n", ""))
    with pytest.raises(UsageError, match="no PettingZoo parallel version"):
        train("motiongym/ExcavatorReach-v0", "ppo", config_path=config, out_root=tmp_path)


def test_tiny_shared_run_loads_as_a_predictor_of_the_single_agent_view(tmp_path):
    config = tmp_path / "shared.yml"
    config.write_text(SHARED_CONFIG)
    run_dir = train(DUAL_ARM, "ppo", config_path=config, out_root=tmp_path, progress=False)
    assert yaml.safe_load((run_dir / "config.yml").read_text())["vec_env"] == "pettingzoo"
    assert (run_dir / "vecnormalize.npz").is_file()
    assert (run_dir / "eval" / "evaluations.npz").is_file()
    monitor = (run_dir / "monitor" / "pettingzoo.monitor.csv").read_text().splitlines()
    assert len(monitor) > 2  # episodes of at most 40 steps, one row per slot

    env = make_env(DUAL_ARM, max_episode_steps=60)
    predictor = load_predictor(str(run_dir), DUAL_ARM, env)
    assert isinstance(predictor, SharedPolicyPredictor)
    action, _ = predictor.predict(env.reset(seed=0)[0])
    assert action.shape == (2,) and env.action_space.contains(action)
    evaluation = evaluate(env, predictor, [100_000], DUAL_ARM, "shared", progress=False)
    assert 0 < evaluation.episodes[0]["length"] <= 60


def test_a_shared_run_needs_the_joint_action_of_both_arms(tmp_path):
    config = tmp_path / "shared.yml"
    config.write_text(SHARED_CONFIG.replace("n_timesteps: 256", "n_timesteps: 64"))
    run_dir = train(DUAL_ARM, "ppo", config_path=config, out_root=tmp_path, progress=False)
    env = make_env(DUAL_ARM, {"control": "robot_2"})
    with pytest.raises(UsageError, match="joint action of shape"):
        load_predictor(str(run_dir), DUAL_ARM, env)
