"""A tiny training run of each algorithm family writes a model the harness loads and runs."""

from __future__ import annotations

import pytest

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import evaluate
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.training.train import train

# algorithm -> (ID, the block's algorithm-specific keys): on-policy, off-policy
# (continuous and discrete actions) and recurrent families. The off-policy blocks set a
# small replay buffer: SB3's default (a million transitions) takes most of a run this short
# to allocate.
FAMILIES = {
    "ppo": ("motiongym/ExcavatorReach-v0", "  n_steps: 32\n  batch_size: 32\n"),
    "a2c": ("motiongym/Sweeper-v0", "  n_steps: 8\n"),
    "sac": (
        "motiongym/HarvestArmPlanar-v0",
        "  learning_starts: 16\n  batch_size: 16\n  buffer_size: 256\n",
    ),
    "td3": (
        "motiongym/DualArmCell-v0",
        "  learning_starts: 16\n  batch_size: 16\n  buffer_size: 256\n",
    ),
    "dqn": (
        "motiongym/Sweeper-v0",
        "  learning_starts: 16\n  batch_size: 16\n  buffer_size: 256\n",
    ),
    "recurrentppo": ("motiongym/ExcavatorReach-v0", "  n_steps: 32\n  batch_size: 32\n"),
    "maskableppo": ("motiongym/Sweeper-v0", "  n_steps: 32\n  batch_size: 32\n"),
}


@pytest.mark.parametrize("algo", FAMILIES)
def test_tiny_run_writes_a_model_that_evaluates(algo, tmp_path):
    env_id, keys = FAMILIES[algo]
    policy = "MultiInputPolicy" if env_id.endswith("Sweeper-v0") else "MlpPolicy"
    if algo == "recurrentppo":
        policy = "MlpLstmPolicy"
    config = tmp_path / "tiny.yml"
    config.write_text(
        f"{algo}:\n  n_timesteps: 64\n  policy: {policy}\n  eval_freq: 64\n"
        f"  n_eval_episodes: 1\n  env_kwargs:\n    max_episode_steps: 40\n{keys}"
    )
    run_dir = train(env_id, algo, config_path=config, out_root=tmp_path, progress=False)
    assert (run_dir / "model.zip").is_file()
    assert (run_dir / "eval" / "evaluations.npz").is_file()
    env = make_env(env_id, {"max_episode_steps": 40})
    predictor = load_predictor(str(run_dir), env_id, env)
    evaluation = evaluate(env, predictor, [7], env_id, algo, progress=False)
    assert 0 < evaluation.episodes[0]["length"] <= 40


def test_maskableppo_needs_an_environment_with_action_masks(tmp_path):
    config = tmp_path / "tiny.yml"
    config.write_text("maskableppo:\n  n_timesteps: 64\n  policy: MlpPolicy\n  n_steps: 32\n")
    with pytest.raises(UsageError, match="no action masks"):
        train("motiongym/ExcavatorReach-v0", "maskableppo", config, out_root=tmp_path)
