"""The command line: listing, evaluation outputs, training runs, one-line errors."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest
import yaml

from motiongym.agents.cli import main
from motiongym.agents.training.config import default_config_path, load_config
from motiongym.agents.training.train import train
from motiongym.baselines import scripted_policies
from motiongym.envs import ENV_IDS

SWEEPER = "motiongym/Sweeper-v0"


def _error(capsys, argv) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("motiongym: error: ") and "\n" not in err
    return err


def test_list_names_every_id_and_its_policies(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for env_id in ENV_IDS:
        assert env_id in out
        for name in scripted_policies(env_id):
            assert name in out


def test_unknown_id_policy_experiment(capsys, tmp_path):
    err = _error(capsys, ["evaluate", "motiongym/Nope-v0", "--policy", "x"])
    assert "Nope-v0" in err and SWEEPER in err
    err = _error(capsys, ["evaluate", SWEEPER, "--policy", "nope", "--out", str(tmp_path)])
    assert "'nope'" in err
    for name in scripted_policies(SWEEPER):
        assert name in err
    err = _error(capsys, ["evaluate", SWEEPER, "--policy", "psa-cwa", "--env-kwargs", "bogus=1"])
    assert "bogus" in err


def test_config_errors_name_the_key(capsys, tmp_path):
    bad_key = tmp_path / "bad.yml"
    bad_key.write_text("ppo:\n  n_timesteps: 10\n  policy: MultiInputPolicy\n  n_step: 4\n")
    err = _error(capsys, ["train", SWEEPER, "--config", str(bad_key), "--out", str(tmp_path)])
    assert "'n_step'" in err and "n_steps" in err
    malformed = tmp_path / "malformed.yml"
    malformed.write_text("ppo:\n  n_steps: [3\n")
    assert "malformed YAML" in _error(capsys, ["train", SWEEPER, "--config", str(malformed)])
    bad_activation = tmp_path / "activation.yml"
    bad_activation.write_text(
        "ppo:\n  n_timesteps: 10\n  policy: MultiInputPolicy\n"
        "  policy_kwargs: {activation_fn: swish}\n"
    )
    err = _error(capsys, ["train", SWEEPER, "--config", str(bad_activation)])
    assert "'swish'" in err and "leaky_relu" in err
    missing = tmp_path / "missing.yml"
    assert "no configuration file" in _error(capsys, ["train", SWEEPER, "--config", str(missing)])
    no_block = tmp_path / "sac_only.yml"
    no_block.write_text("sac:\n  n_timesteps: 10\n  policy: MlpPolicy\n")
    assert "no block for algorithm 'ppo'" in _error(
        capsys, ["train", SWEEPER, "--algo", "ppo", "--config", str(no_block)]
    )
    err = _error(capsys, ["train", SWEEPER, "--config", str(no_block), "--out", str(tmp_path)])
    assert "sac cannot train on motiongym/Sweeper-v0" in err and "Discrete(3)" in err


def test_evaluate_writes_json_and_csv_with_the_env_measures(capsys, tmp_path):
    argv = [
        "evaluate",
        SWEEPER,
        "--policy",
        "psa-cwa",
        "--episodes",
        "2",
        "--out",
        str(tmp_path),
        "--no-progress",
        "--env-kwargs",
        "map_name=room",
    ]
    assert main(argv) == 0
    data = json.loads(next(tmp_path.glob("*.json")).read_text())
    assert data["seeds"] == [100_000, 100_001]
    assert {"coverage", "is_success", "cost", "return", "length"} <= set(data["summary"])
    assert len(next(tmp_path.glob("*.csv")).read_text().splitlines()) == 3


def test_every_shipped_config_block_is_valid():
    files = sorted(Path(str(resources.files("motiongym.configs"))).glob("*.yml"))
    assert files
    for path in files:  # <Name>-vN.yml, or <Name>-vN-<variant>.yml
        name = re.match(r".+?-v\d+", path.stem)
        assert name and f"motiongym/{name.group(0)}" in ENV_IDS, f"{path.name}: no registered ID"
        for algo in yaml.safe_load(path.read_text()):
            config = load_config(path, algo)
            # 0 steps of RL only where the block learns from a teacher (imitate).
            assert config["n_timesteps"] > 0 or config["imitate"], f"{path.name} [{algo}]"


def test_train_smoke_run_writes_a_loadable_run_folder(capsys, tmp_path):
    config = tmp_path / "tiny.yml"
    config.write_text(
        "ppo:\n  n_envs: 2\n  n_timesteps: 128\n  policy: MultiInputPolicy\n  n_steps: 64\n"
        "  batch_size: 64\n  eval_freq: 64\n  n_eval_episodes: 1\n  checkpoint_freq: 64\n"
        "  normalize: true\n  env_kwargs: {map_name: room, max_episode_steps: 100}\n"
    )
    argv = ["train", SWEEPER, "--config", str(config), "--out", str(tmp_path), "--no-progress"]
    assert main(argv) == 0
    (run_dir,) = (tmp_path / "Sweeper-v0").iterdir()
    for name in (
        "model.zip",
        "config.yml",
        "command.txt",
        "eval/evaluations.npz",
        "eval/learning_curve.png",
        "tb",
        "checkpoints",
        "monitor",
    ):
        assert (run_dir / name).exists(), name
    assert yaml.safe_load((run_dir / "config.yml").read_text())["n_steps"] == 64
    assert (run_dir / "vecnormalize.npz").is_file()  # statistics as plain arrays, never pickled
    assert {p.suffix for p in (run_dir / "checkpoints").iterdir()} == {".npz", ".zip"}
    assert not list(run_dir.rglob("*.pkl"))
    out = tmp_path / "eval"
    argv = [
        "evaluate",
        SWEEPER,
        "--policy",
        str(run_dir),
        "--episodes",
        "1",
        "--out",
        str(out),
        "--no-progress",
        "--env-kwargs",
        "map_name=room",
        "max_episode_steps=100",
    ]
    assert main(argv) == 0
    assert json.loads(next(out.glob("*.json")).read_text())["summary"]["length"]["mean"] > 0


def test_model_for_another_space_is_refused(capsys, tmp_path):
    from stable_baselines3 import PPO

    model_file = tmp_path / "cartpole.zip"
    PPO("MlpPolicy", "CartPole-v1", n_steps=32, batch_size=32, device="cpu").save(model_file)
    err = _error(capsys, ["evaluate", SWEEPER, "--policy", str(model_file)])
    assert "no manifest.json" in err and "--trust" in err
    assert main(["evaluate", SWEEPER, "--policy", str(model_file), "--trust"]) == 2
    warning, err = capsys.readouterr().err.strip().split("\n")
    assert warning.startswith("warning: ") and "without a manifest" in warning
    assert err.startswith("motiongym: error: ") and "another observation space" in err


def test_no_traceback_from_the_installed_command(tmp_path):
    result = subprocess.run(
        [
            str(Path(sys.executable).parent / "motiongym"),
            "evaluate",
            "motiongym/Nope-v0",
            "--policy",
            "x",
        ],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    "argv",
    [
        ["list"],
        ["evaluate"],
        ["compare"],
        ["train"],
        ["reproduce"],
        ["ship"],
        ["bench"],
        ["record"],
    ],
)
def test_every_subcommand_has_help(argv, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main([*argv, "--help"])
    assert exit_info.value.code == 0
    assert "usage: motiongym" in capsys.readouterr().out


def test_train_defaults_to_the_config_files_first_block(tmp_path):
    from motiongym.agents.training.config import first_block

    config = tmp_path / "two.yml"
    config.write_text(
        "a2c:\n  n_timesteps: 16\n  policy: MlpPolicy\n  n_steps: 8\n"
        "ppo:\n  n_timesteps: 16\n  policy: MlpPolicy\n"
    )
    assert first_block(config) == "a2c"
    run_dir = train("motiongym/ExcavatorReach-v0", config_path=config, out_root=tmp_path)
    assert run_dir.name.startswith("a2c_seed0_")
    assert first_block(default_config_path("motiongym/Sweeper-v0")) == "maskableppo"


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--seed", "-5"], "--seed: must be in [0, 4294967295], got -5"),
        (["--seed", str(2**80)], "--seed: must be in [0, 4294967295]"),
        (["--seed", "x"], "--seed: must be a whole number"),
        (["--episodes", "0"], "--episodes: must be a whole number >= 1, got 0"),
        (["--seed", str(2**32 - 1), "--episodes", "2"], "passes 4294967295"),
        (["--env-kwargs", "map_name=bogus"], "map_name must be one of"),
        (["--env-kwargs", "robot_width=2.5"], "robot_width must be an integer"),
        (["--env-kwargs", "map_name=[room"], "'map_name=[room': the value is not YAML"),
        (["--env-kwargs", "max_episode_steps=-3"], "max_episode_steps must be an integer"),
        (["--env-kwargs", "max_episode_steps=abc"], "max_episode_steps must be an integer"),
        (["--env-kwargs", "render_mode=bogus"], "render_mode must be one of None"),
        (["--env-kwargs", "map_file=/nonexistent.txt"], "map_file must be an existing"),
    ],
)
def test_bad_evaluation_arguments_are_one_line_and_exit_2(capsys, argv, expected):
    err = _error(capsys, ["evaluate", SWEEPER, "--policy", "psa-cwa", *argv])
    assert expected in err


def test_out_on_a_file_is_refused_and_writes_nothing(capsys, tmp_path):
    target = tmp_path / "a_file"
    target.write_text("keep me")
    err = _error(capsys, ["evaluate", SWEEPER, "--policy", "psa-cwa", "--out", str(target)])
    assert "is a file, not a folder" in err and target.read_text() == "keep me"
    below = str(target / "sub")
    err = _error(capsys, ["evaluate", SWEEPER, "--policy", "psa-cwa", "--out", below])
    assert f"lies under {str(target)!r}, a file" in err
    err = _error(capsys, ["benchmarks", "--out", str(target / "BENCHMARKS.md")])
    assert "a file" in err


@pytest.mark.parametrize(
    ("setting", "expected"),
    [
        ("n_envs: 0", "n_envs must be an integer in [1, 1024], got 0"),
        ("n_timesteps: -5", "n_timesteps must be an integer"),
        ("policy: 123", "policy must be one of"),
        ("learning_rate: .nan", "learning_rate must be a finite number"),
        ("gamma: 2", "gamma must be a finite number in (0.0, 1.0]"),
        ("eval_freq: -1", "eval_freq must be an integer in [1, "),
        ("checkpoint_freq: 0", "checkpoint_freq must be an integer in [1, "),
        ("policy_kwargs: {net_arch: [-5]}", "net_arch layer size must be an integer"),
        ("policy: CnnPolicy", "ppo cannot train on motiongym/Sweeper-v0"),  # SB3's ValueError
        ("policy_kwargs: {bogus: 1}", "unknown policy_kwargs key 'bogus'; valid: activation_fn"),
        ("policy_kwargs: {ortho_init: x}", "policy_kwargs.ortho_init must be True or False"),
        ("policy_kwargs: {net_arch: {pi: [8], bogus: [8]}}", "net_arch keys must be among"),
        ("normalize_advantage: 3", "normalize_advantage must be True or False, got 3"),
        ("ent_coef: auto", "ent_coef must be a finite number"),  # "auto" is SAC's, not PPO's
        ("n_epochs: 100000000000", "n_epochs must be an integer in [1, 10000]"),
        ("normalize: {gamma: .nan}", "normalize.gamma must be a finite number"),
        ("normalize: {clip_obs: -1}", "normalize.clip_obs must be a finite number"),
        ("normalize: {norm_obs: 5}", "normalize.norm_obs must be True or False"),
        ("normalize: {bogus: 1}", "unknown normalize key(s) ['bogus']"),
        ("env_kwargs: {max_episode_steps: -1}", "max_episode_steps must be an integer >= 1"),
        ("env_kwargs: {coarse: 100000}", "coarse must be an integer in [1, 64]"),
        (
            "policy_kwargs: {features_extractor_class: sweeper_egocentric, "
            "features_extractor_kwargs: {bogus: 1}}",
            "unexpected keyword argument 'bogus'",
        ),
    ],
)
def test_bad_config_values_are_named_and_leave_no_run_folder(capsys, tmp_path, setting, expected):
    config = tmp_path / "bad.yml"
    block = {"n_timesteps": "64", "policy": "MultiInputPolicy", "n_steps": "32", "batch_size": "32"}
    key = setting.split(":")[0]
    block.pop(key, None)
    lines = [f"  {k}: {v}" for k, v in block.items()] + [f"  {setting}"]
    config.write_text("ppo:\n" + "\n".join(lines) + "\n")
    out = tmp_path / "runs"
    err = _error(capsys, ["train", SWEEPER, "--config", str(config), "--out", str(out)])
    assert expected in err
    assert not out.exists()  # nor the folders above the run's


def test_benchmarks_out_on_a_folder_is_refused(capsys, tmp_path):
    err = _error(capsys, ["benchmarks", "--out", str(tmp_path)])
    assert "is a folder, not a file" in err


def test_training_that_diverges_is_one_line_and_says_what_is_left(capsys, tmp_path, monkeypatch):
    from stable_baselines3 import PPO

    def diverge(self, **kwargs):
        raise ValueError("Expected parameter logits (Tensor of shape (32, 3)) ... nan")

    monkeypatch.setattr(PPO, "learn", diverge)
    config = tmp_path / "tiny.yml"
    config.write_text(
        "ppo:\n  n_timesteps: 64\n  policy: MultiInputPolicy\n  n_steps: 32\n  batch_size: 32\n"
    )
    out = tmp_path / "runs"
    err = _error(capsys, ["train", SWEEPER, "--config", str(config), "--out", str(out)])
    assert "training stopped at step 0 (Expected parameter logits" in err
    (run_dir,) = (out / "Sweeper-v0").iterdir()
    assert not (run_dir / "manifest.json").exists() and not (run_dir / "model.zip").exists()
