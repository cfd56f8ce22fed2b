"""The first hour's long waits, said or avoided: episodes capped by --max-steps (and an ID
with long episodes announced before it is evaluated), a training progress bar whose total
is the steps that run, and compare --all's closing summary of what it wrote where."""

from __future__ import annotations

import warnings

import gymnasium as gym
import pytest
from sb3_contrib import MaskablePPO
from stable_baselines3 import PPO, SAC

from motiongym.agents import cli
from motiongym.agents.cli import main
from motiongym.agents.environments import long_episodes_note
from motiongym.agents.evaluation import report
from motiongym.agents.training.train import StepsProgressBar, steps_to_run

SWEEPER = "motiongym/Sweeper-v0"
REACH = "motiongym/ExcavatorReach-v0"


def test_an_id_with_long_episodes_is_announced_and_others_are_not():
    note = long_episodes_note(SWEEPER, {}, 10)
    assert note == (
        "Sweeper-v0's episodes end at success or at 20,000 steps: a policy that does not "
        "finish runs 10 x 20,000 steps"
    )
    assert long_episodes_note(SWEEPER, {"max_episode_steps": 1000}, 10) is None
    assert long_episodes_note(REACH, {}, 10) is None


def test_evaluate_announces_the_sweepers_limit_before_it_starts(capsys, tmp_path):
    argv = ["evaluate", SWEEPER, "--policy", "psa-cwa", "--episodes", "1", "--no-progress"]
    assert main([*argv, "--env-kwargs", "map_name=room", "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "20,000 steps: a policy that does not finish runs 1 x 20,000 steps" in err
    assert "(--max-steps N caps them)" in err


def test_max_steps_caps_every_episode_and_says_nothing(capsys, tmp_path):
    argv = ["evaluate", SWEEPER, "--policy", "random", "--episodes", "2", "--max-steps", "7"]
    assert main([*argv, "--no-progress", "--out", str(tmp_path)]) == 0
    assert "20,000" not in capsys.readouterr().err
    (written,) = tmp_path.glob("*_evaluation.csv")
    lengths = [line.split(",")[2] for line in written.read_text().splitlines()[1:]]
    assert lengths == ["7", "7"]
    clash = ["--max-steps", "7", "--env-kwargs", "max_episode_steps=9"]
    assert main(["evaluate", SWEEPER, "--policy", "random", *clash]) == 2
    assert "--max-steps 7 and --env-kwargs max_episode_steps=9 disagree" in capsys.readouterr().err


def test_steps_to_run_counts_whole_collections():
    env = gym.make(REACH)
    ppo = PPO("MlpPolicy", env, n_steps=64, batch_size=64, device="cpu")
    assert [steps_to_run(ppo, n) for n in (1, 64, 65, 5000)] == [64, 64, 128, 5056]
    sac = SAC("MlpPolicy", env, train_freq=4, device="cpu")
    assert steps_to_run(sac, 10) == 12
    assert steps_to_run(SAC("MlpPolicy", env, train_freq=(1, "episode"), device="cpu"), 10) == 10


def test_the_progress_bar_ends_full_at_the_steps_that_ran():
    env = gym.make(SWEEPER, map_name="room", max_episode_steps=50)
    model = MaskablePPO("MultiInputPolicy", env, n_steps=32, batch_size=32, device="cpu")
    bar = StepsProgressBar()
    model.learn(total_timesteps=40, callback=bar)
    assert model.num_timesteps == 64
    assert (bar.pbar.total, bar.pbar.n) == (64, 64)


def test_compare_all_ends_with_what_it_wrote_and_where(capsys, monkeypatch, tmp_path):
    ids = ["motiongym/ExcavatorReach-v0", "motiongym/Excavator-v0"]
    monkeypatch.setattr(cli, "ENV_IDS", ids)
    # The piped width wherever the tests run (pytest-xdist's workers set COLUMNS=80).
    monkeypatch.delenv("COLUMNS", raising=False)
    monkeypatch.setattr(report, "console", report.make_console())
    argv = ["compare", "--all", "--policies", "random", "--episodes", "1", "--max-steps", "3"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main([*argv, "--no-progress", "--out", str(tmp_path)]) == 0
    assert not [w for w in caught if "out of date" in str(w.message)]  # v0 IDs on purpose
    out = capsys.readouterr().out
    summary = out[out.index("compared 2 IDs on 1 episodes each") :]
    n_files = len(list(tmp_path.iterdir()))
    assert f"{n_files} files in {tmp_path}/" in " ".join(summary.split())
    for env_id in ids:
        name = env_id.split("/")[1]
        assert env_id in summary
        for suffix in ("md", "png", "json", "csv"):
            assert f"{name}_comparison.{suffix}" in summary
            assert (tmp_path / f"{name}_comparison.{suffix}").is_file()


@pytest.mark.parametrize("command", ["evaluate", "compare"])
def test_max_steps_help_states_its_default(command, capsys):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    assert "--max-steps" in capsys.readouterr().out
