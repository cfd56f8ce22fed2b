"""rl-zoo3 trains from ``configs/zoo/<algo>.yml``: every (algorithm, ID) block of the files
runs the zoo's own train script (``python -m rl_zoo3.train``, the README's command with the
header's ``--env-kwargs``) for a few hundred steps, and the model it saves carries the
file's settings (discount, network, learning rate, ...). ``motiongym evaluate`` then runs
a zoo PPO run (with its normalisation converted to plain arrays, as the refusal says).

rl-zoo3 is not a motiongym dependency (through moviepy it downgrades pillow), so these
tests are skipped unless it is importable: ``make test-zoo`` makes a separate virtual
environment (``.venv-zoo``) with it and runs them there. The default suite checks the files
against the zoo's contract without it (``test_zoo.py``: only keys the zoo knows, importable
class names, ``policy_kwargs`` as the expression the zoo evaluates).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

pytest.importorskip("rl_zoo3", reason="rl-zoo3 is not a dependency: make test-zoo installs it")

CONFIGS = Path(__file__).parents[2] / "configs" / "zoo"
TINY = {  # the zoo's --hyperparams: a few hundred steps, whatever the file's budget
    "ppo": ["n_envs:2", "n_steps:64", "batch_size:64"],
    "sac": ["n_envs:1", "learning_starts:64", "batch_size:32", "buffer_size:2000"],
    "tqc": ["n_envs:1", "learning_starts:64", "batch_size:32", "buffer_size:2000"],
}
STEPS = 256


def blocks() -> list[tuple[str, str]]:
    return [
        (path.stem, env_id)
        for path in sorted(CONFIGS.glob("*.yml"))
        for env_id in yaml.safe_load(path.read_text())
    ]


def header_options(algo: str, env_id: str) -> list[str]:
    """The options the file's header gives for ``env_id`` (``--env-kwargs`` and the rest)."""
    text = (CONFIGS / f"{algo}.yml").read_text()
    line = re.search(
        rf"^#   python -m rl_zoo3.train --algo {algo} --env {env_id} (.*)$", text, re.M
    )
    assert line, f"configs/zoo/{algo}.yml gives no command for {env_id}"
    return line.group(1).split()


def zoo_train(algo: str, env_id: str, folder: Path) -> Path:
    options = header_options(algo, env_id)
    if "--eval-freq" in options:  # evaluate once, early, on one episode
        options[options.index("--eval-freq") + 1] = str(STEPS // 2)
        options[options.index("--eval-episodes") + 1] = "1"
    block = yaml.safe_load((CONFIGS / f"{algo}.yml").read_text())[env_id]
    if block.get("replay_buffer_class") == "HerReplayBuffer":  # samples whole episodes only
        short = "max_episode_steps:50"  # a gym.make keyword the zoo passes on
        at = options.index("--env-kwargs") + 1 if "--env-kwargs" in options else None
        options = (
            options + ["--env-kwargs", short]
            if at is None
            else [*options[:at], short, *options[at:]]
        )
    command = [sys.executable, "-m", "rl_zoo3.train", "--algo", algo, "--env", env_id,
               "--gym-packages", "motiongym", "--conf-file", str(CONFIGS / f"{algo}.yml"),
               "-n", str(STEPS), "--seed", "0", "--device", "cpu", "-f", str(folder),
               *options, "--hyperparams", *TINY[algo]]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    (run,) = (folder / algo).iterdir()
    return run


@pytest.mark.slow
@pytest.mark.parametrize(("algo", "env_id"), blocks())
def test_the_zoo_trains_every_block_with_the_files_settings(tmp_path, algo, env_id):
    from motiongym.agents.environments import make_env
    from motiongym.agents.models.files import algorithm_classes

    block = yaml.safe_load((CONFIGS / f"{algo}.yml").read_text())[env_id]
    run = zoo_train(algo, env_id, tmp_path)
    name = env_id.replace("/", "-")
    env = make_env(env_id) if "replay_buffer_class" in block else None  # HER loads with one
    model = algorithm_classes()[algo].load(run / f"{name}.zip", env=env, device="cpu")
    assert model.num_timesteps >= STEPS
    assert model.gamma == block["gamma"]
    assert model.lr_schedule(1.0) == block["learning_rate"]
    net_arch = re.search(r"net_arch=(\[[^]]*\])", block["policy_kwargs"]).group(1)
    assert str(model.policy_kwargs["net_arch"]) == net_arch
    if block.get("normalize"):
        assert (run / name / "vecnormalize.pkl").is_file()


@pytest.mark.slow
def test_motiongym_evaluates_a_zoo_run(tmp_path, capsys):
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from motiongym.agents.cli import main
    from motiongym.agents.environments import make_env
    from motiongym.agents.models.files import NORMALIZATION_FILE, save_normalization

    env_id = "motiongym/HarvestArmPlanar-v0"
    run = zoo_train("ppo", env_id, tmp_path / "logs")
    pickled = run / env_id.replace("/", "-") / "vecnormalize.pkl"  # ours: trusted
    env = make_env(env_id)
    save_normalization(VecNormalize.load(str(pickled), DummyVecEnv([lambda: env])),
                       run / NORMALIZATION_FILE)  # fmt: skip
    argv = ["evaluate", env_id, "--policy", str(run), "--trust", "--episodes", "2",
            "--out", str(tmp_path / "results"), "--no-progress"]  # fmt: skip
    assert main(argv) == 0
    assert "no observation normalisation found" not in capsys.readouterr().err
    assert list((tmp_path / "results").glob("*.json"))
