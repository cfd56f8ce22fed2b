"""rl-zoo3 runs: ``evaluate`` finds the zoo's normalisation in ``<env-name>/vecnormalize.pkl``
and unpickles it only with ``trust``; without any normalisation it says so."""

from __future__ import annotations

import numpy as np
import pytest
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.predictors import NormalizedModel, load_predictor

ENV_ID = "motiongym/HarvestArmPlanar-v0"
ZOO_NAME = "motiongym-HarvestArmPlanar-v0"  # the zoo's EnvironmentName: '/' as '-'


@pytest.fixture
def env():
    env = make_env(ENV_ID)
    yield env
    env.close()


def zoo_run(tmp_path, env, with_statistics: bool):
    """The layout `python -m rl_zoo3.train --algo ppo --env <ID>` leaves (model untrained)."""
    run = tmp_path / "logs" / "ppo" / f"{ZOO_NAME}_1"
    (run / ZOO_NAME).mkdir(parents=True)
    PPO("MlpPolicy", env, n_steps=64, device="cpu").save(run / f"{ZOO_NAME}.zip")
    if with_statistics:
        normalization = VecNormalize(DummyVecEnv([lambda: env]))
        normalization.obs_rms.mean = np.full(env.observation_space.shape, 0.25)
        normalization.save(str(run / ZOO_NAME / "vecnormalize.pkl"))
    return run


def test_the_zoo_pickle_is_found_and_refused_without_trust(tmp_path, env):
    run = zoo_run(tmp_path, env, with_statistics=True)
    with pytest.raises(UsageError, match=r"rl-zoo3 .*vecnormalize\.pkl: a pickle.*--trust"):
        load_predictor(str(run), ENV_ID, env)


def test_the_zoo_pickle_is_applied_with_trust(tmp_path, env, capsys):
    run = zoo_run(tmp_path, env, with_statistics=True)
    predictor = load_predictor(str(run), ENV_ID, env, trust=True)
    assert isinstance(predictor, NormalizedModel)
    assert np.all(predictor.normalization.obs_rms.mean == 0.25)
    assert not predictor.normalization.training and not predictor.normalization.norm_reward
    assert "unpickling" in capsys.readouterr().err


def test_a_zoo_run_without_normalisation_says_it_found_none(tmp_path, env, capsys):
    run = zoo_run(tmp_path, env, with_statistics=False)
    predictor = load_predictor(str(run / f"{ZOO_NAME}.zip"), ENV_ID, env, trust=True)
    assert isinstance(predictor, PPO)
    assert "no observation normalisation found" in capsys.readouterr().err
