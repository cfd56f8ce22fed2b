"""Fixtures of the agents tests: a shipped model made from two tiny training runs."""

from __future__ import annotations

import pytest

from motiongym.agents.models.ship import ship
from motiongym.agents.training.train import train

TINY_CONFIG = """
ppo:
  n_envs: 1
  n_timesteps: 64
  policy: MlpPolicy
  n_steps: 64
  batch_size: 32
  normalize: true
  eval_freq: 32
  n_eval_episodes: 1
"""


@pytest.fixture
def tiny_config(tmp_path):
    """``TINY_CONFIG`` in a file: one PPO update of 64 steps."""
    path = tmp_path / "tiny.yml"
    path.write_text(TINY_CONFIG)
    return path


@pytest.fixture(scope="session")
def shipped_folder(tmp_path_factory):
    root = tmp_path_factory.mktemp("ship")
    config = root / "tiny.yml"
    config.write_text(TINY_CONFIG)
    run_dirs = [
        train(
            "motiongym/ExcavatorReach-v0",
            "ppo",
            config_path=config,
            seed=seed,
            out_root=root / "runs",
            progress=False,
        )
        for seed in (0, 1)
    ]
    return ship(run_dirs, n_episodes=2, root=root / "pretrained").folder
