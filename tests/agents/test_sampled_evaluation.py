"""A run with ``deterministic: false`` samples its actions, the same ones on the same seed."""

from __future__ import annotations

import json
import shutil

import pytest
import torch
import yaml

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation import benchmarks
from motiongym.agents.evaluation.episodes import evaluate
from motiongym.agents.models.predictors import SampledModel, load_predictor
from motiongym.agents.models.pretrained import write_manifest
from motiongym.agents.training.train import train

SWEEPER = "motiongym/Sweeper-v0"
TINY = (
    "maskableppo:\n  n_timesteps: 64\n  policy: MultiInputPolicy\n  n_steps: 32\n"
    "  batch_size: 32\n  eval_freq: 64\n  n_eval_episodes: 1\n  deterministic: {}\n"
    "  env_kwargs: {{max_episode_steps: 60}}\n"
)


def test_a_sampling_run_acts_the_same_on_the_same_seed(tmp_path):
    config = tmp_path / "tiny.yml"
    config.write_text(TINY.format("false"))
    run_dir = train(SWEEPER, config_path=config, out_root=tmp_path, progress=False)
    env = make_env(SWEEPER, {"max_episode_steps": 60})
    predictor = load_predictor(str(run_dir), SWEEPER, env)
    assert isinstance(predictor, SampledModel)
    caller_state = torch.random.get_rng_state()
    sampled = evaluate(env, predictor, [7, 8], SWEEPER, "sampled", progress=False).episodes
    assert torch.equal(torch.random.get_rng_state(), caller_state)  # restored after each episode
    torch.rand(3)  # the caller's own draws change nothing
    again = evaluate(env, predictor, [7, 8], SWEEPER, "sampled", progress=False).episodes
    assert again == sampled
    # The same model on its most likely actions is another policy.
    resolved = yaml.safe_load((run_dir / "config.yml").read_text())
    (run_dir / "config.yml").write_text(yaml.safe_dump({**resolved, "deterministic": True}))
    with pytest.raises(UsageError, match="SHA-256"):  # the run's manifest sees the edit
        load_predictor(str(run_dir), SWEEPER, env)
    write_manifest(run_dir)  # the user vouches for the edited run
    greedy = load_predictor(str(run_dir), SWEEPER, env)
    assert not isinstance(greedy, SampledModel)
    assert evaluate(env, greedy, [7, 8], SWEEPER, "greedy", progress=False).episodes != sampled


def test_deterministic_must_be_a_boolean(tmp_path):
    config = tmp_path / "bad.yml"
    config.write_text(TINY.format("sometimes"))
    with pytest.raises(UsageError, match="'deterministic' must be true or false"):
        train(SWEEPER, config_path=config, out_root=tmp_path, progress=False)


def test_shipped_metrics_and_benchmark_labels_say_how_the_runs_acted(shipped_folder, tmp_path):
    metrics = json.loads((shipped_folder / "metrics.json").read_text())
    assert [run["deterministic"] for run in metrics["runs"]] == [True, True]
    folder = tmp_path / "sampled"
    shutil.copytree(shipped_folder, folder)
    for run in metrics["runs"]:
        run["deterministic"] = False
    (folder / "metrics.json").write_text(json.dumps(metrics))
    evaluation, _ = benchmarks.pooled_evaluation(folder)
    assert evaluation.policy == "ppo (from scratch, 2 seeds, sampled)"
