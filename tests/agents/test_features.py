"""The sweeper's egocentric features extractor: frames, invariance, use from a config."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch

from motiongym.agents.environments import make_env
from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.episodes import evaluate
from motiongym.agents.learners.excavator import ExcavatorFields
from motiongym.agents.learners.sweeper import SweeperEgocentric
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.training.train import train
from motiongym.envs.excavator.observation import layout

SWEEPER = "motiongym/Sweeper-v0"
K, S = 16, 9  # the registered coarse resolution and window side (w 3, R 3)


@pytest.fixture(scope="module")
def space() -> gym.spaces.Dict:
    return gym.make(SWEEPER).observation_space


def _observation(windows, pose, sweep_map, obstacle_map) -> dict[str, torch.Tensor]:
    """A batch of one hand-made observation, as SB3 hands it to the extractor."""
    values = {
        "sensed": windows[0],
        "swept": windows[1],
        "pose": np.asarray(pose, np.float32),
        "sweep_map": sweep_map,
        "obstacle_map": obstacle_map,
    }
    return {
        key: torch.as_tensor(np.ravel(v), dtype=torch.float32)[None] for key, v in values.items()
    }


def test_features_of_a_batch_of_environment_observations(space):
    env = gym.make(SWEEPER)
    observations = [env.reset(seed=seed)[0] for seed in range(5)]
    batch = {key: torch.as_tensor(np.stack([o[key] for o in observations])) for key in space}
    extractor = SweeperEgocentric(space, map_shape=(30, 40), features_dim=24)
    assert extractor(batch).shape == (5, 24)
    assert extractor.egocentric_maps(batch).shape == (5, 3, 2 * K - 1, 2 * K - 1)


def test_the_robot_block_is_centred_and_its_heading_points_up(space):
    # Map 30 x 40: blocks 2 x 3, 15 rows and 14 columns of them hold map cells.
    extractor = SweeperEgocentric(space, map_shape=(30, 40))
    sweep = np.zeros((K, K), np.float32)
    sweep[5, 4], sweep[5, 5] = 0.5, 1.0  # the robot's block, the block east of it
    windows = np.zeros((2, S, S), np.float32)
    windows[0, 4, 8] = 1.0  # an obstacle east of the footprint's centre
    pose = (10, 13, 0, 0)  # cell (10, 13): block (5, 4); heading east
    observation = _observation(windows, pose, sweep, np.zeros((K, K)))
    maps = extractor.egocentric_maps(observation)[0]
    centre = K - 1
    assert maps[0, centre, centre] == 0.5
    assert maps[0, centre - 1, centre] == 1.0  # east is up
    assert maps[0].sum() == 1.5
    # Outside the map: block row 15 is 10 rows south of row 5; facing east, south is right.
    assert maps[2, centre, centre + 10] == 1.0 and maps[2, centre, centre + 9] == 0.0
    local = extractor.egocentric_windows(observation)[0].reshape(2, S, S)
    assert local[0, 0, 4] == 1.0 and local[0].sum() == 1.0


def test_turning_the_world_a_quarter_turn_leaves_the_features_unchanged(space):
    # Square blocks (32 x 32 map: 2 x 2 cells a block, 16 x 16 blocks), so a quarter
    # turn of the world is a quarter turn of the coarse maps.
    extractor = SweeperEgocentric(space, map_shape=(32, 32))
    rng = np.random.default_rng(0)
    windows = (rng.random((2, S, S)) < 0.3).astype(np.float32)
    sweep, obstacle = rng.random((K, K)), rng.random((K, K))
    (i, j), heading = (3, 11), 2
    observation = _observation(windows, (2 * i, 2 * j, heading, 1), sweep, obstacle)
    # Counter-clockwise: block (i, j) goes to (K - 1 - j, i), west becomes south.
    turned = _observation(
        np.rot90(windows, axes=(1, 2)),
        (2 * (K - 1 - j), 2 * i, (heading + 1) % 4, 1),
        np.rot90(sweep),
        np.rot90(obstacle),
    )
    torch.testing.assert_close(
        extractor.egocentric_maps(observation), extractor.egocentric_maps(turned)
    )
    torch.testing.assert_close(
        extractor.egocentric_windows(observation), extractor.egocentric_windows(turned)
    )
    assert not torch.equal(
        extractor.egocentric_maps(observation),
        extractor.egocentric_maps(_observation(windows, (2 * i, 2 * j, 0, 1), sweep, obstacle)),
    )


def test_bad_keywords_are_named(space):
    with pytest.raises(ValueError, match="map_shape"):
        SweeperEgocentric(space, map_shape=(30,))
    with pytest.raises(ValueError, match="channels"):
        SweeperEgocentric(space, map_shape=(30, 40), channels=(16, 0))
    with pytest.raises(ValueError, match="shrink"):
        SweeperEgocentric(space, map_shape=(30, 40), channels=(4, 4, 4, 4, 4))


def test_v1_known_window_is_a_third_window_channel():
    space = gym.make("motiongym/Sweeper-v1").observation_space
    env = gym.make("motiongym/Sweeper-v1")
    observations = [env.reset(seed=seed)[0] for seed in range(3)]
    batch = {key: torch.as_tensor(np.stack([o[key] for o in observations])) for key in space}
    extractor = SweeperEgocentric(space, map_shape=(30, 40), features_dim=24)
    windows = extractor.egocentric_windows(batch)
    assert windows.shape == (3, 3, S * S)
    assert torch.equal(windows[:, 2].sum(1), batch["known"].sum(1))  # a permutation of it
    unknown = dict(batch, known=torch.zeros_like(batch["known"]))
    assert not torch.equal(extractor(batch), extractor(unknown))  # the features read it


@pytest.mark.parametrize("env_id", [SWEEPER, "motiongym/Sweeper-v1"])
def test_a_config_naming_it_trains_and_the_model_evaluates(tmp_path, env_id):
    config = tmp_path / "ego.yml"
    config.write_text(
        "maskableppo:\n  n_envs: 2\n  n_timesteps: 256\n  policy: MultiInputPolicy\n"
        "  policy_kwargs:\n    features_extractor_class: sweeper_egocentric\n"
        "    features_extractor_kwargs: {map_shape: [30, 40], features_dim: 16}\n"
        "    net_arch: [16]\n  n_steps: 64\n  batch_size: 64\n  eval_freq: 128\n"
        "  n_eval_episodes: 1\n  env_kwargs: {max_episode_steps: 50}\n"
    )
    run_dir = train(env_id, "maskableppo", config_path=config, out_root=tmp_path, progress=False)
    env = make_env(env_id, {"max_episode_steps": 50})
    predictor = load_predictor(str(run_dir), env_id, env)
    assert isinstance(predictor.model.policy.features_extractor, SweeperEgocentric)
    assert evaluate(env, predictor, [3], env_id, "ego", progress=False).episodes[0]["length"] == 50


def test_an_unknown_extractor_name_lists_the_known_ones(tmp_path):
    config = tmp_path / "bad.yml"
    config.write_text(
        "ppo:\n  n_timesteps: 10\n  policy: MultiInputPolicy\n"
        "  policy_kwargs: {features_extractor_class: NatureCNN}\n"
    )
    valid = (
        "excavator_fields, goal_error, harvest_obstacle_set, sweeper_egocentric, "
        "sweeper_map_pyramid"
    )
    with pytest.raises(UsageError, match=f"'NatureCNN' unknown; valid: {valid}"):
        train(SWEEPER, "ppo", config_path=config, out_root=tmp_path)


def test_excavator_fields_keep_the_named_entries_and_squash_the_error():
    """The fields in the order named, unchanged; then tanh(target_error / s) for each scale."""
    env = gym.make("motiongym/ExcavatorReach-v1")
    obs = np.stack([env.reset(seed=seed)[0] for seed in range(3)])
    lay = layout("reach", "v1")
    extractor = ExcavatorFields(
        env.observation_space, ["target_error", "q", "base"], physics="v1", error_scales=[0.03, 1]
    )
    out = extractor(torch.as_tensor(obs)).numpy()
    error = obs[:, lay["target_error"]]
    expected = [error, obs[:, lay["q"]], obs[:, lay["base"]], np.tanh(error / 0.03), np.tanh(error)]
    assert extractor.features_dim == 4 + 4 + 2 + 8 == out.shape[1]
    np.testing.assert_allclose(out, np.concatenate(expected, 1), rtol=1e-6, atol=1e-7)


def test_excavator_fields_refuse_bad_keywords_by_name():
    space = gym.make("motiongym/ExcavatorReach-v0").observation_space
    with pytest.raises(ValueError, match="fields must be names of the reach observation.*'pose'"):
        ExcavatorFields(space, ["q", "pose"])
    with pytest.raises(ValueError, match="under physics v1 .shape .60,.., got shape .58,."):
        ExcavatorFields(space, ["q"], physics="v1")
    with pytest.raises(ValueError, match="error_scales must be positive numbers.*got .0.1, 0."):
        ExcavatorFields(space, ["q"], error_scales=[0.1, 0])
    with pytest.raises(ValueError, match="target_error, got .0.1. for the dig observation"):
        ExcavatorFields(
            gym.make("motiongym/Excavator-v0").observation_space, ["q"], "dig", error_scales=[0.1]
        )
