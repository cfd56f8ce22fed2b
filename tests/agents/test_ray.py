"""Ray (the optional extra motiongym[ray]): ``motiongym sweep`` (Tune trials of whole train
runs) and ``motiongym rllib`` (RLlib PPO, the dual-arm cell's PettingZoo env multi-agent).

Without Ray the commands say how to install it (tested here by hiding Ray); the trial grid,
the grouping for ``ship`` and the RLlib settings file are checked without Ray. With Ray
installed (``make test-ray``), a local Ray head on 127.0.0.1 runs one tiny sweep and one
tiny RLlib iteration of each route (slow tests), then stops.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from motiongym.agents.cli import main
from motiongym.agents.errors import UsageError
from motiongym.agents.integrations.rllib_runs import (
    SECTIONS,
    default_rllib_config,
    load_rllib_settings,
)
from motiongym.agents.integrations.sweep import final_evaluation, ship_groups, trial_specs
from motiongym.envs import ENV_IDS

try:
    import ray
except ImportError:
    ray = None
needs_ray = pytest.mark.skipif(
    ray is None, reason="Ray is the optional extra motiongym[ray] (make test-ray installs it)"
)

TINY_RLLIB = {
    "training": {"train_batch_size_per_learner": 200, "minibatch_size": 100, "num_epochs": 1},
    "env_runners": {"num_env_runners": 0},
    "model": {"fcnet_hiddens": [16]},
}


@pytest.mark.parametrize("command", [["sweep", "motiongym/Sweeper-v0"], ["rllib", "x"]])
def test_without_ray_the_commands_say_how_to_install_it(monkeypatch, capsys, command):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray raises ImportError
    assert main(command) == 2
    assert "needs Ray, an optional extra: pip install 'motiongym[ray]'" in capsys.readouterr().err


def test_the_trial_grid_is_ids_by_configs_by_seeds_with_absolute_paths(tmp_path):
    a, b = tmp_path / "a.yml", tmp_path / "b.yml"
    a.write_text("ppo: {}\n"), b.write_text("ppo: {}\n")  # files that exist
    ids = ["motiongym/Sweeper-v0", "motiongym/HarvestArm-v0"]
    specs = trial_specs(ids, [a, b, None], [0, 5], Path("rel"), timesteps=100)
    assert len(specs) == 2 * 3 * 2
    assert {(s["env_id"], s["config_name"], s["seed"]) for s in specs} == {
        (i, c, s) for i in ids for c in ("a", "b", "default") for s in (0, 5)
    }
    assert all(Path(s["out"]).is_absolute() and s["timesteps"] == 100 for s in specs)
    assert {s["out"] for s in specs} == {str(Path("rel", c).resolve()) for c in "ab"} | {
        str(Path("rel", "default").resolve())
    }  # one folder per config: two configs of one ID never share a run folder


def test_bad_sweeps_are_refused_by_name(tmp_path):
    (tmp_path / "x").mkdir()
    (tmp_path / "a.yml").write_text("ppo: {}\n"), (tmp_path / "x" / "a.yml").write_text("ppo: {}\n")
    with pytest.raises(UsageError, match="unknown environment ID 'Nope-v0'"):
        trial_specs(["Nope-v0"], [None], [0], tmp_path)
    with pytest.raises(UsageError, match="two files share a name"):
        trial_specs(["motiongym/Sweeper-v0"], [tmp_path / "a.yml", tmp_path / "x/a.yml"], [0],
                    tmp_path)  # fmt: skip
    with pytest.raises(UsageError, match="no configuration file at .*missing.yml"):
        trial_specs(["motiongym/Sweeper-v0"], [tmp_path / "missing.yml"], [0], tmp_path)
    with pytest.raises(UsageError, match="a seed is given twice"):
        trial_specs(["motiongym/Sweeper-v0"], [None], [1, 1], tmp_path)


def test_runs_are_grouped_by_id_and_config_with_their_ship_command():
    results = [
        {"env_id": "motiongym/A-v0", "config_name": "c", "seed": s, "run_dir": f"/r/c{s}"}
        for s in (2, 0)
    ] + [{"env_id": "motiongym/A-v0", "config_name": "d", "seed": 0, "run_dir": "/r/d0"}]
    groups = ship_groups(results)
    assert list(groups) == ["motiongym/A-v0 [c]", "motiongym/A-v0 [d]"]
    assert groups["motiongym/A-v0 [c]"] == {
        "run_dirs": ["/r/c0", "/r/c2"], "seeds": [0, 2], "ship": "motiongym ship /r/c0 /r/c2"
    }  # fmt: skip


def test_the_final_evaluation_is_the_callbacks_last(tmp_path):
    assert np.isnan(final_evaluation(tmp_path)["eval_return"])  # no evaluation ran
    (tmp_path / "eval").mkdir()
    results, successes = np.array([[1.0, 3.0], [4.0, 6.0]]), np.array([[0.0, 0.0], [1.0, 0.0]])
    np.savez(tmp_path / "eval" / "evaluations.npz", results=results, successes=successes,
             timesteps=np.array([10, 20]))  # fmt: skip
    assert final_evaluation(tmp_path) == {"eval_return": 5.0, "eval_success": 0.5}


def test_the_rllib_settings_file_covers_known_ids_and_sections():
    document = yaml.safe_load(default_rllib_config().read_text())
    assert set(document) - {"default"} <= set(ENV_IDS)
    for block in document.values():
        assert set(block) <= set(SECTIONS)
    dual = load_rllib_settings("motiongym/DualArmCell-v0")
    assert dual["model"] == {"fcnet_hiddens": [64, 64]}  # the ID's, over the default
    assert dual["training"]["num_epochs"] == 10  # the default's
    assert dual["env_config"] == {"collision": 20.0, "advance": 10.0}
    assert load_rllib_settings("motiongym/Sweeper-v0")["env_config"] == {}


def test_bad_rllib_settings_are_refused_by_name(tmp_path):
    path = tmp_path / "r.yml"
    path.write_text("default:\n  learning: {}\n")
    with pytest.raises(UsageError, match=r"\[default\]: unknown section\(s\) \['learning'\]"):
        load_rllib_settings("motiongym/Sweeper-v0", path)
    path.write_text("Sweeper-v0: {}\n")
    with pytest.raises(UsageError, match="'Sweeper-v0' is neither 'default' nor an ID"):
        load_rllib_settings("motiongym/Sweeper-v0", path)


@needs_ray
def test_every_id_gets_an_rllib_ppo_config_and_an_unknown_keyword_is_named():
    from motiongym.agents.integrations.rllib_runs import ppo_config

    for env_id in ENV_IDS:
        config = ppo_config(env_id, load_rllib_settings(env_id))
        assert config.env == env_id and config.minibatch_size == 256
    settings = load_rllib_settings("motiongym/Sweeper-v0")
    settings["training"]["learning_rate"] = 0.1
    with pytest.raises(UsageError, match="learning_rate"):
        ppo_config("motiongym/Sweeper-v0", settings)


@pytest.fixture(scope="module")
def local_ray():
    ray.init(address="local", num_cpus=2, include_dashboard=False, configure_logging=False,
             log_to_driver=False, _node_ip_address="127.0.0.1")  # fmt: skip
    yield
    ray.shutdown()


@needs_ray
@pytest.mark.slow
def test_a_tiny_sweep_on_a_local_ray_writes_run_folders_and_ship_commands(
    tmp_path, local_ray, tiny_config
):
    from motiongym.agents.integrations.sweep import SWEEP_FILE, sweep

    specs = trial_specs(["motiongym/ExcavatorReach-v0"], [tiny_config], [0, 1], tmp_path / "out")
    groups = sweep(specs, tmp_path / "out")
    (group,) = groups.values()
    assert group["seeds"] == [0, 1]
    for run_dir in group["run_dirs"]:
        assert (Path(run_dir) / "model.zip").is_file() and (
            Path(run_dir) / "manifest.json"
        ).is_file()
        assert Path(run_dir).parent == tmp_path / "out" / "tiny" / "ExcavatorReach-v0"
    assert json.loads((tmp_path / "out" / SWEEP_FILE).read_text())["groups"] == groups


@needs_ray
@pytest.mark.slow
@pytest.mark.parametrize(
    ("env_id", "multi_agent"),
    [(env_id, False) for env_id in ENV_IDS] + [("motiongym/DualArmCell-v0", True)],
)  # every ID with RLlib's PPO, the dual-arm cell also as RLlib multi-agent
def test_one_tiny_rllib_iteration(tmp_path, local_ray, env_id, multi_agent):
    from motiongym.agents.integrations.rllib_runs import train_rllib

    run_dir = train_rllib(env_id, 1, tmp_path, overrides=TINY_RLLIB, multi_agent=multi_agent)
    (progress,) = json.loads((run_dir / "progress.json").read_text())
    assert progress["env_steps"] == 200  # one batch of train_batch_size_per_learner
    assert (run_dir / "checkpoint").is_dir()
    assert yaml.safe_load((run_dir / "config.yml").read_text())["multi_agent"] is multi_agent
