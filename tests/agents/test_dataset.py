"""``motiongym dataset``: scripted episodes as Minari datasets, and their checks on loading."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("minari")

from motiongym.agents.cli import main  # noqa: E402
from motiongym.agents.integrations.dataset import (  # noqa: E402
    DATASET_SEED,
    load_demonstrations,
    record_dataset,
    transitions,
)

ENV_ID = "motiongym/HarvestArmPlanarGoal-v1"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    root = tmp_path_factory.mktemp("datasets")
    return record_dataset(ENV_ID, "potential-field", 2, root)


def test_metadata_names_the_teacher_and_the_episodes_replay(recorded):
    """The metadata name the policy and its version; replaying the recorded actions
    from the recorded seeds gives the recorded observations (an independent truth)."""
    from motiongym import __version__

    path, rate = recorded
    env = gym.make(ENV_ID)
    dataset = load_demonstrations(path, env)
    meta = dataset.storage.metadata
    assert (meta["env_id"], meta["policy_name"], meta["policy_version"]) == (
        ENV_ID,
        "potential-field",
        __version__,
    )
    assert meta["algorithm_name"] == f"potential-field (motiongym {__version__})"
    assert meta["first_seed"] == DATASET_SEED
    assert dataset.total_episodes == 2
    successes = []
    for episode in dataset.iterate_episodes():
        obs, _ = env.reset(seed=DATASET_SEED + int(episode.id))
        np.testing.assert_array_equal(obs["desired_goal"], episode.observations["desired_goal"][0])
        for t, action in enumerate(episode.actions):
            obs, *_, info = env.step(action)
            np.testing.assert_array_equal(
                obs["observation"], episode.observations["observation"][t + 1]
            )
        successes.append(info["is_success"])
    assert rate == np.mean(successes)
    observations, actions = transitions(dataset)
    assert len(actions) == len(observations["observation"]) == dataset.total_steps


def test_a_dataset_of_another_id_or_space_is_refused(recorded, tmp_path):
    path, _ = recorded
    with pytest.raises(ValueError, match="recorded on 'motiongym/HarvestArmPlanarGoal-v1'"):
        load_demonstrations(path, gym.make("motiongym/HarvestArmGoal-v1"))
    with pytest.raises(ValueError, match="observation_space"):
        load_demonstrations(path, gym.make(ENV_ID, n_obstacles=6))
    with pytest.raises(ValueError, match="must be a Minari dataset folder"):
        load_demonstrations(tmp_path, gym.make(ENV_ID))


def test_cli_writes_a_dataset_and_refuses_to_overwrite(tmp_path, capsys):
    args = ["dataset", "motiongym/ExcavatorReachGoal-v1", "--policy", "newton-raphson-reach"]
    args += ["--episodes", "1", "--out", str(tmp_path)]
    assert main(args) == 0
    assert "success 100%" in capsys.readouterr().out
    assert main(args) == 2
    assert "exists already" in capsys.readouterr().err
    assert main([*args[:3], "nope", *args[4:]]) == 2
    assert "scripted policies: newton-raphson-reach" in capsys.readouterr().err


def test_a_dataset_records_the_spaces_of_the_keywords_it_was_made_with(tmp_path, capsys):
    """Recorded with ``dof=5`` on the 7-DOF ID: the metadata hold the 5-DOF spaces,
    so loading it for the registered ID is refused; a bad keyword is refused first."""
    env_id = "motiongym/HarvestArm-v0"
    args = ["dataset", env_id, "--policy", "potential-field", "--episodes", "1"]
    args += ["--out", str(tmp_path)]
    assert main([*args, "--env-kwargs", "bogus=1"]) == 2
    assert "unknown keyword argument(s) bogus" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
    path, _ = record_dataset(env_id, "potential-field", 1, tmp_path, env_kwargs={"dof": 5})
    dataset = load_demonstrations(path, gym.make(env_id, dof=5))
    assert dataset.action_space.shape == (5,)
    with pytest.raises(
        ValueError, match=r"observation_space Box\(166,\), the environment Box\(185,\)"
    ):
        load_demonstrations(path, gym.make(env_id))
