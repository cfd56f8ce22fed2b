"""SAC / TQC + HER on the goal-conditioned IDs: the shipped blocks train (a tiny run) and load."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import evaluate
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.training.config import default_config_path, load_config
from motiongym.agents.training.train import train

GOAL_IDS = (
    "motiongym/HarvestArmGoal-v1",
    "motiongym/HarvestArmPlanarGoal-v1",
    "motiongym/ExcavatorReachGoal-v1",
)
TINY = {"n_timesteps": 200, "learning_starts": 41, "eval_freq": 200, "n_eval_episodes": 1}


def _tiny_config(env_id: str, algo: str, folder: Path, **changes) -> Path:
    """The shipped block, shortened to a smoke run on 40-step episodes."""
    block = yaml.safe_load(default_config_path(env_id).read_text())[algo]
    block.update(TINY, batch_size=32, buffer_size=2000, **changes)
    block["env_kwargs"] = {**block.get("env_kwargs", {}), "max_episode_steps": 40}
    path = folder / f"{algo}.yml"
    path.write_text(yaml.safe_dump({algo: block}))
    return path


@pytest.mark.parametrize("env_id", GOAL_IDS)
def test_shipped_her_block_trains_and_its_model_evaluates(env_id, tmp_path):
    run_dir = train(
        env_id, "sac", _tiny_config(env_id, "sac", tmp_path), out_root=tmp_path, progress=False
    )
    env = make_env(env_id, {"max_episode_steps": 40})
    predictor = load_predictor(str(run_dir), env_id, env)
    evaluation = evaluate(env, predictor, [3], env_id, "sac", progress=False)
    assert 0 < evaluation.episodes[0]["length"] <= 40


def test_tqc_her_block_trains(tmp_path):
    env_id = "motiongym/HarvestArmPlanarGoal-v1"
    run_dir = train(
        env_id, "tqc", _tiny_config(env_id, "tqc", tmp_path), out_root=tmp_path, progress=False
    )
    assert (run_dir / "model.zip").is_file()


def test_her_needs_learning_to_start_after_the_first_episode(tmp_path):
    env_id = "motiongym/HarvestArmPlanarGoal-v1"
    config = _tiny_config(env_id, "sac", tmp_path, learning_starts=40)
    with pytest.raises(UsageError, match="learning_starts / n_envs must exceed .* 40 steps"):
        train(env_id, "sac", config, out_root=tmp_path, progress=False)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"replay_buffer_class": "per"}, "replay_buffer_class must be one of"),
        ({"replay_buffer_kwargs": {"n_goals": 4}}, "replay_buffer_kwargs must be a mapping"),
        (
            {"replay_buffer_kwargs": {"goal_selection_strategy": "past"}},
            "goal_selection_strategy must be one of",
        ),
        ({"replay_buffer_kwargs": {"copy_info_dict": "yes"}}, "copy_info_dict must be true"),
        ({"residual": 5}, "residual must be a scripted policy's name"),
        ({"residual_scale": 3.0}, "residual_scale"),
    ],
)
def test_bad_her_and_residual_settings_are_named(change, message):
    path = default_config_path("motiongym/HarvestArmGoal-v1")
    block = {**load_config(path, "sac"), **change}
    from motiongym.agents.training.config import validate_block

    with pytest.raises(UsageError, match=message):
        validate_block(block, "sac", "test")
