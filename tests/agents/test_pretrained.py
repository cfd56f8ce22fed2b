"""Shipped models: manifests verify, models load and run through the harness."""

from __future__ import annotations

import shutil

import pytest

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluate import evaluate
from motiongym.agents.predictors import load_predictor
from motiongym.agents.pretrained import pretrained_models, ship, verify_manifest
from motiongym.agents.train import train
from motiongym.envs import ENV_IDS

SHIPPED = [(env_id, name) for env_id in ENV_IDS for name in pretrained_models(env_id)]


@pytest.mark.parametrize(("env_id", "name"), SHIPPED)
def test_shipped_model_verifies_loads_and_runs_an_episode(env_id, name):
    verify_manifest(pretrained_models(env_id)[name])
    env = make_env(env_id)
    predictor = load_predictor(name, env_id, env)
    evaluation = evaluate(env, predictor, [123], env_id, name, progress=False)
    assert evaluation.episodes[0]["length"] > 0


TINY_CONFIG = """
ppo:
  n_envs: 1
  n_timesteps: 64
  policy: MlpPolicy
  n_steps: 64
  batch_size: 32
  normalize: true
"""


@pytest.fixture(scope="module")
def shipped_folder(tmp_path_factory):
    root = tmp_path_factory.mktemp("ship")
    config = root / "tiny.yml"
    config.write_text(TINY_CONFIG)
    run_dir = train(
        "motiongym/ExcavatorReach-v0",
        "ppo",
        config_path=config,
        out_root=root / "runs",
        progress=False,
    )
    return ship(run_dir, n_episodes=1, root=root / "pretrained")


def test_ship_writes_metrics_and_a_manifest_that_detects_tampering(shipped_folder, tmp_path):
    for name in (
        "model.zip",
        "vecnormalize.pkl",
        "config.yml",
        "command.txt",
        "metrics.json",
        "manifest.json",
    ):
        assert (shipped_folder / name).is_file(), name
    verify_manifest(shipped_folder)
    tampered = tmp_path / "tampered"
    shutil.copytree(shipped_folder, tampered)
    with (tampered / "model.zip").open("ab") as handle:
        handle.write(b"\0")
    with pytest.raises(UsageError, match="SHA-256"):
        verify_manifest(tampered)
    (tampered / "config.yml").unlink()
    with pytest.raises(UsageError, match="missing"):
        verify_manifest(tampered)
