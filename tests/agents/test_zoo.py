"""rl-zoo3 runs: ``evaluate`` finds the zoo's normalisation in ``<env-name>/vecnormalize.pkl``
and never unpickles it (with or without ``trust``); converted to plain arrays beside the model,
it is applied; without any normalisation it says so."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.models.predictors import NormalizedModel, load_predictor

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
        space = env.observation_space  # statistics observations in its bounds can give
        normalization.obs_rms.mean = np.clip(np.full(space.shape, 0.25), space.low, space.high)
        normalization.obs_rms.var = np.full(space.shape, 1e-4)
        normalization.save(str(run / ZOO_NAME / "vecnormalize.pkl"))
    return run


@pytest.mark.parametrize("trust", [False, True])
def test_the_zoo_pickle_is_found_and_never_unpickled(tmp_path, env, monkeypatch, trust):
    import pickle

    run = zoo_run(tmp_path, env, with_statistics=True)

    def refuse(*args, **kwargs):
        raise AssertionError("unpickled")

    monkeypatch.setattr(pickle, "load", refuse)
    monkeypatch.setattr(pickle, "loads", refuse)
    with pytest.raises(UsageError, match=r"rl-zoo3 .*vecnormalize\.pkl: a pickle.*never loads"):
        load_predictor(str(run), ENV_ID, env, trust=trust)


def test_the_zoo_statistics_converted_to_plain_arrays_are_applied(tmp_path, env):
    from pathlib import Path

    from motiongym.agents.models.files import NORMALIZATION_FILE, save_normalization

    run = zoo_run(tmp_path, env, with_statistics=True)
    pickled = run / ZOO_NAME / "vecnormalize.pkl"
    # what the refusal tells the user to run where they trust the file
    save_normalization(VecNormalize.load(str(pickled), DummyVecEnv([lambda: env])),
                       Path(run / NORMALIZATION_FILE))  # fmt: skip
    predictor = load_predictor(str(run), ENV_ID, env, trust=True)
    assert isinstance(predictor, NormalizedModel)
    space = env.observation_space
    expected = np.clip(np.full(space.shape, 0.25), space.low, space.high)
    assert np.all(predictor.normalization.obs_rms.mean == expected)
    assert not predictor.normalization.training and not predictor.normalization.norm_reward


def test_a_zoo_run_without_normalisation_says_it_found_none(tmp_path, env, capsys):
    run = zoo_run(tmp_path, env, with_statistics=False)
    predictor = load_predictor(str(run / f"{ZOO_NAME}.zip"), ENV_ID, env, trust=True)
    assert isinstance(predictor, PPO)
    assert "no observation normalisation found" in capsys.readouterr().err


def test_the_zoo_files_are_made_from_configs_and_hold_only_keys_the_zoo_knows():
    import inspect
    from pathlib import Path

    from torch import nn

    from motiongym.agents.integrations import zoo
    from motiongym.agents.models.files import algorithm_classes

    folder = Path(__file__).parents[2] / "configs" / "zoo"
    assert sorted(p.stem for p in folder.glob("*.yml")) == sorted(zoo.ALGORITHMS)
    for algo in zoo.ALGORITHMS:
        text = (folder / f"{algo}.yml").read_text()
        assert text == zoo.zoo_file(algo), f"configs/zoo/{algo}.yml is stale: regenerate it"
        constructor = set(inspect.signature(algorithm_classes()[algo].__init__).parameters)
        for env_id, block in yaml.safe_load(text).items():
            assert set(block) <= set(zoo.ZOO_KEYS) | constructor, (algo, env_id)
            kwargs = eval(block["policy_kwargs"], {"nn": nn})  # as the zoo evaluates it
            assert isinstance(kwargs["net_arch"], list | dict)
    ppo = yaml.safe_load((folder / "ppo.yml").read_text())
    assert "motiongym/Sweeper-v0" not in ppo  # its native vec env and extractor are ours
    assert "motiongym/Sweeper-v0: vec_env native" in (folder / "ppo.yml").read_text()
    assert ppo["motiongym/HarvestArm-v0"]["policy_kwargs"] == "dict(net_arch=[256, 256])"


def test_zoo_blocks_convert_our_names():
    from motiongym.agents.integrations.zoo import refusal, zoo_block

    block, options = zoo_block(
        {"policy_kwargs": {"activation_fn": "tanh"}, "replay_buffer_class": "her",
         "env_kwargs": {"distance": 1.0}, "eval_freq": 500, "deterministic": True}
    )  # fmt: skip
    assert block == {
        "policy_kwargs": "dict(activation_fn=nn.Tanh)",
        "replay_buffer_class": "HerReplayBuffer",
    }
    assert options == ["--env-kwargs distance:1.0", "--eval-freq 500"]
    assert refusal({"vec_env": "pettingzoo"}) and refusal({"residual": "dig-cycle"})
    assert refusal({"deterministic": False}) and refusal({}) is None


def test_a_zoo_model_whose_rate_is_a_schedule_object_loads(tmp_path, env):
    """rl-zoo3 saves the learning rate as SB3's ConstantSchedule, a pickled entry whose plain
    ``val`` stands beside it: it is read from there (before: 'would run code; refused')."""
    from stable_baselines3.common.utils import ConstantSchedule

    path = tmp_path / "zoo.zip"
    PPO("MlpPolicy", env, n_steps=64, learning_rate=ConstantSchedule(3e-4), device="cpu").save(path)
    model = load_predictor(str(path), ENV_ID, env, trust=True)
    assert model.learning_rate(1.0) == 3e-4
    action, _ = model.predict(env.reset(seed=0)[0], deterministic=True)
    assert env.action_space.contains(action)
