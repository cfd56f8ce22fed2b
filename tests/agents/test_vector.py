"""motiongym train on the natively vectorised sweeper through the SB3 adapter."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from motiongym.agents.errors import UsageError
from motiongym.agents.training.train import train
from motiongym.agents.training.vector import VectorEnvAdapter

NATIVE_CONFIG = """
ppo:
  n_envs: 4
  n_timesteps: 256
  policy: MultiInputPolicy
  n_steps: 64
  batch_size: 64
  vec_env: native
  eval_freq: 128
  n_eval_episodes: 1
  env_kwargs: {map_name: room, max_episode_steps: 50}
"""


def test_train_runs_on_the_native_vector_env(tmp_path):
    config = tmp_path / "native.yml"
    config.write_text(NATIVE_CONFIG)
    run_dir = train(
        "motiongym/Sweeper-v0", "ppo", config_path=config, out_root=tmp_path, progress=False
    )
    assert (run_dir / "model.zip").is_file()
    monitor = (run_dir / "monitor" / "native.monitor.csv").read_text().splitlines()
    assert len(monitor) > 2  # episodes of 50 steps were recorded by VecMonitor


def test_native_requires_a_vector_entry_point(tmp_path):
    config = tmp_path / "native.yml"
    config.write_text(NATIVE_CONFIG.replace("MultiInputPolicy", "MlpPolicy"))
    with pytest.raises(UsageError, match="no native vector environment"):
        train(
            "motiongym/ExcavatorReach-v0",
            "ppo",
            config_path=config,
            out_root=tmp_path,
            progress=False,
        )


def test_adapter_refuses_next_step_autoreset():
    with pytest.raises(ValueError, match="SAME_STEP"):
        VectorEnvAdapter(
            gym.make_vec("CartPole-v1", num_envs=2, vectorization_mode="vector_entry_point")
        )


def test_adapter_reports_terminal_observations_and_truncation():
    native = gym.make_vec(
        "motiongym/Sweeper-v0",
        num_envs=3,
        vectorization_mode="vector_entry_point",
        max_episode_steps=5,
    )
    venv = VectorEnvAdapter(native)
    venv.seed(0)
    venv.reset()
    for _ in range(5):
        _, _, dones, infos = venv.step(np.zeros(3, dtype=np.int64))
    assert dones.all()
    for info in infos:
        assert "terminal_observation" in info and info["TimeLimit.truncated"]
