"""Shipped models: manifests verify, models load and run through the harness."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import EVALUATION_SEED, evaluate
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.models.pretrained import pretrained_models, verify_manifest
from motiongym.agents.models.ship import ship
from motiongym.envs import ENV_IDS

SHIPPED = [(env_id, name) for env_id in ENV_IDS for name in pretrained_models(env_id)]


@pytest.mark.parametrize(("env_id", "name"), SHIPPED)
def test_shipped_model_verifies_loads_and_runs_an_episode(env_id, name):
    verify_manifest(pretrained_models(env_id)[name])
    env = make_env(env_id, {"max_episode_steps": 300})  # a learner may never finish
    predictor = load_predictor(name, env_id, env)
    evaluation = evaluate(env, predictor, [123], env_id, name, progress=False)
    assert evaluation.episodes[0]["length"] > 0


def test_ship_writes_metrics_and_a_manifest_that_detects_tampering(shipped_folder, tmp_path):
    for name in (
        "model.zip",
        "vecnormalize.npz",
        "config.yml",
        "command.txt",
        "metrics.json",
        "learning_curves.csv",
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


def test_ship_keeps_every_seed_learning_curve(shipped_folder):
    rows = (shipped_folder / "learning_curves.csv").read_text().splitlines()
    assert rows[0] == "training_seed,timesteps,mean_return,success_rate"
    assert {row.split(",")[0] for row in rows[1:]} == {"0", "1"}


def test_ship_reports_every_seed_and_pools_their_episodes(shipped_folder):
    metrics = json.loads((shipped_folder / "metrics.json").read_text())
    assert [run["training_seed"] for run in metrics["runs"]] == [0, 1]
    assert metrics["held_out_seeds"] == [EVALUATION_SEED, EVALUATION_SEED + 1]
    assert metrics["shipped_run"] in {run["run"] for run in metrics["runs"]}
    returns = [episode["return"] for run in metrics["runs"] for episode in run["episodes"]]
    assert metrics["pooled"]["return"]["mean"] == pytest.approx(np.mean(returns))
    best = max(metrics["runs"], key=lambda run: run["summary"]["return"]["mean"])
    assert metrics["shipped_run"] == best["run"]  # no success in 64 steps: ranked by return


def test_ship_refuses_runs_of_different_ids(shipped_folder, tmp_path):
    other = tmp_path / "other"
    other.mkdir()
    settings = "algo: ppo\nseed: 0\nn_timesteps: 64\npolicy: MultiInputPolicy\n"
    (other / "config.yml").write_text(f"env_id: motiongym/Sweeper-v0\n{settings}")
    runs = shipped_folder.parent.parent.parent / "runs" / "ExcavatorReach-v0"
    with pytest.raises(UsageError, match="one ID and algorithm"):
        ship([next(runs.iterdir()), other], n_episodes=1, root=tmp_path / "pretrained")
    for bad, expected in [
        ("env_id: [1]\n", "unknown environment ID"),
        ("env_id: motiongym/Sweeper-v0\nseed: x\n", "'seed' must be an integer"),
        ("env_id: motiongym/Sweeper-v0\nbogus: 1\n", "unknown key 'bogus'"),
    ]:
        (other / "config.yml").write_text(bad + settings.replace("seed: 0\n", ""))
        with pytest.raises(UsageError, match=expected):
            ship([other], n_episodes=1, root=tmp_path / "pretrained")


def test_ship_keeps_a_better_shipped_model_unless_forced(shipped_folder, tmp_path, capsys):
    """A temporary copy of a shipped folder stands for agents/models/pretrained: the worse
    training run is refused with both scores, --force replaces, an equal run ships."""
    from motiongym.agents.cli import main

    metrics = json.loads((shipped_folder / "metrics.json").read_text())
    ranked = sorted(metrics["runs"], key=lambda run: run["summary"]["return"]["mean"])
    worse, best = (ranked[0], ranked[-1])
    assert worse["summary"]["return"]["mean"] < best["summary"]["return"]["mean"]
    runs = shipped_folder.parent.parent.parent / "runs" / "ExcavatorReach-v0"
    root = tmp_path / "pretrained"
    shutil.copytree(shipped_folder, root / "ExcavatorReach-v0" / "ppo")
    before = (root / "ExcavatorReach-v0" / "ppo" / "model.zip").read_bytes()
    argv = ["ship", str(runs / worse["run"]), "--episodes", "2", "--into", str(root)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    best_return = f"mean return {best['summary']['return']['mean']:.4g}"
    worse_return = f"mean return {worse['summary']['return']['mean']:.4g}"
    assert "not shipped" in err and best_return in err and worse_return in err
    assert "--force" in err
    assert (root / "ExcavatorReach-v0" / "ppo" / "model.zip").read_bytes() == before
    assert main([*argv, "--force"]) == 0
    replaced = json.loads((root / "ExcavatorReach-v0" / "ppo" / "metrics.json").read_text())
    assert replaced["shipped_run"] == worse["run"]
    argv = ["ship", str(runs / best["run"]), "--episodes", "2", "--into", str(root)]
    assert main(argv) == 0  # better than what is there now: shipped, both scores printed
    out = capsys.readouterr().out
    assert best_return in out and f"replaced a model with success 0 %, {worse_return}" in out
