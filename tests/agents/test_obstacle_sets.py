"""The harvest arm's obstacle-set extractor: parsing by name, geometry, invariance, use."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import torch

from motiongym.agents.environments import make_env
from motiongym.agents.evaluation.episodes import evaluate
from motiongym.agents.learners.harvest_arm import HarvestObstacleSet, closest_points
from motiongym.agents.models.predictors import load_predictor
from motiongym.agents.training.train import train
from motiongym.envs.geometry import closest_points_between_segments
from motiongym.envs.harvest_arm.observation import observation_views, obstacle_width, point_count

VARIANTS = [("motiongym/HarvestArmPlanar-v0", {"planar": True}), ("motiongym/HarvestArm-v0", {})]


def _batch(env_id: str, seeds=range(4), steps: int = 5) -> tuple[gym.Env, torch.Tensor]:
    """Observations of a few scenes, a few random steps in (the arm off its home pose)."""
    env = gym.make(env_id)
    rows = []
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        env.action_space.seed(seed)
        for _ in range(steps):
            obs, *_ = env.step(0.3 * env.action_space.sample())
        rows.append(obs)
    return env, torch.as_tensor(np.stack(rows))


def _sizes(env: gym.Env) -> tuple[dict[str, slice], int, int, int, int]:
    """The environment's slices, obstacle slots K, links L, slot width and dim."""
    base = env.unwrapped
    dim = base.world.dim
    slots, links = base.params.n_obstacles, point_count(base.world.arm) - 1
    return base.task.layout.slices, slots, links, obstacle_width(dim), dim


@pytest.mark.parametrize(("env_id", "kwargs"), VARIANTS)
def test_the_parse_is_the_environments_layout_by_name(env_id, kwargs):
    env, obs = _batch(env_id)
    extractor = HarvestObstacleSet(env.observation_space, hidden=8, features_dim=16, **kwargs)
    assert extractor(obs).shape == (4, 16)
    parsed = extractor.parse(obs)
    for i, row in enumerate(obs.numpy()):
        truth = observation_views(env.unwrapped.task.layout, row)  # the environment's own
        for key in ("points", "fruit_error", "a", "b", "radius", "distances"):
            np.testing.assert_allclose(parsed[key][i].numpy(), truth[key], atol=1e-6)
        np.testing.assert_array_equal(parsed["mask"][i].numpy() > 0.5, truth["mask"])
        np.testing.assert_array_equal(parsed["is_bar"][i].numpy() > 0.5, truth["is_bar"])
        np.testing.assert_allclose(
            np.arctan2(parsed["sin_q"][i].numpy(), parsed["cos_q"][i].numpy()),
            truth["q"],
            atol=1e-6,
        )


@pytest.mark.parametrize(("env_id", "kwargs"), VARIANTS)
def test_link_obstacle_closest_points_give_mujocos_clearances(env_id, kwargs):
    """The pair geometry the extractor computes, minus the radii, is the clearance MuJoCo
    reports in the observation (an independent computation: ``mj_collision``)."""
    env, obs = _batch(env_id)
    extractor = HarvestObstacleSet(env.observation_space, **kwargs)
    o = {k: v.double() for k, v in extractor.parse(obs).items()}
    pts = o["points"]
    _, on_link, on_obstacle = closest_points(
        pts[:, :-1, None], pts[:, 1:, None], o["a"][:, None], o["b"][:, None]
    )
    surface = (on_link - on_obstacle).norm(dim=-1) - o["radius"][:, None] - 0.02  # link radius
    seen = o["distances"] < 1.0  # clipped at 1 m in the observation
    assert seen.float().mean() > 0.9
    torch.testing.assert_close(surface[seen], o["distances"][seen], atol=1e-5, rtol=0)


def test_closest_points_equal_the_numpy_geometry_with_degenerate_segments():
    rng = np.random.default_rng(0)
    p0, p1, q0, q1 = rng.normal(size=(4, 500, 3))
    p1[:50] = p0[:50]  # points
    q1[25:75] = q0[25:75]
    q0[100:150] = p0[100:150] + 0.3 * (p1[100:150] - p0[100:150])  # touching, parallel below
    q1[100:150] = q0[100:150] + 2.0 * (p1[100:150] - p0[100:150])
    _, on_p, on_q = closest_points_between_segments(p0, p1, q0, q1)
    s, tp, tq = closest_points(*(torch.as_tensor(x) for x in (p0, p1, q0, q1)))
    np.testing.assert_allclose(tp.numpy(), on_p, atol=1e-9)
    np.testing.assert_allclose(tq.numpy(), on_q, atol=1e-9)
    np.testing.assert_allclose((p0 + s.numpy()[:, None] * (p1 - p0)), on_p, atol=1e-9)


@pytest.mark.parametrize(("env_id", "kwargs"), VARIANTS)
def test_the_features_do_not_depend_on_the_obstacles_slot_order(env_id, kwargs):
    env, obs = _batch(env_id)
    torch.manual_seed(0)
    extractor = HarvestObstacleSet(env.observation_space, **kwargs)
    s, K, L, w, _ = _sizes(env)
    order = torch.as_tensor(np.random.default_rng(1).permutation(K))
    permuted = obs.clone()
    permuted[:, s["obstacles"]] = obs[:, s["obstacles"]].reshape(-1, K, w)[:, order].flatten(1)
    permuted[:, s["mask"]] = obs[:, s["mask"]][:, order]
    permuted[:, s["distances"]] = obs[:, s["distances"]].reshape(-1, L, K)[..., order].flatten(1)
    assert not torch.equal(permuted, obs)
    torch.testing.assert_close(extractor(permuted), extractor(obs), atol=1e-5, rtol=1e-5)
    # Not a constant: moving one obstacle changes them.
    moved = obs.clone()
    moved[:, s["obstacles"].start] += 0.05
    assert not torch.allclose(extractor(moved), extractor(obs))


def _turned(obs: torch.Tensor, env: gym.Env, angle: float) -> torch.Tensor:
    """The observation of the same scene and arm turned by ``angle`` about z (q_0 + angle)."""
    s, K, _, _, d = _sizes(env)
    c, sn = np.cos(angle), np.sin(angle)
    turn = torch.eye(d, dtype=obs.dtype)
    turn[:2, :2] = torch.tensor([[c, -sn], [sn, c]])
    out = obs.clone()
    for name in ("points", "fruit", "fruit_error"):
        out[:, s[name]] = (obs[:, s[name]].reshape(len(obs), -1, d) @ turn.T).flatten(1)
    rows = obs[:, s["obstacles"]].reshape(len(obs), K, -1).clone()
    rows[..., :d] = rows[..., :d] @ turn.T
    rows[..., d : 2 * d] = rows[..., d : 2 * d] @ turn.T
    out[:, s["obstacles"]] = rows.flatten(1)
    q0 = torch.atan2(obs[:, s["sin_q"].start], obs[:, s["cos_q"].start]) + angle
    out[:, s["sin_q"].start], out[:, s["cos_q"].start] = torch.sin(q0), torch.cos(q0)
    return out


@pytest.mark.parametrize(("env_id", "kwargs"), VARIANTS)
def test_in_the_waist_frame_a_scene_turned_with_the_arm_is_the_same_input(env_id, kwargs):
    env, obs = _batch(env_id)
    obs = obs.double()
    turned = _turned(obs, env, 0.7)
    # The turned observation is the environment's own: same clearances, same layout.
    s = _sizes(env)[0]
    q = np.arctan2(*(turned[0, s[k]].numpy() for k in ("sin_q", "cos_q")))
    env.unwrapped.world.pose(q)
    np.testing.assert_allclose(
        env.unwrapped.world.points.ravel(),
        turned[0, s["points"]].numpy(),
        atol=1e-6,
    )
    torch.manual_seed(0)
    extractor = HarvestObstacleSet(env.observation_space, **kwargs).double()
    torch.testing.assert_close(extractor(turned), extractor(obs))
    world = HarvestObstacleSet(env.observation_space, waist_frame=False, **kwargs).double()
    assert not torch.allclose(world(turned), world(obs))


def test_empty_slots_do_not_count():
    env, obs = _batch("motiongym/HarvestArmPlanar-v0")
    extractor = HarvestObstacleSet(env.observation_space, planar=True)
    s, K, _, w, _ = _sizes(env)
    emptied = obs.clone()
    emptied[:, s["mask"].start + 2] = 0.0  # slot 2 empty ...
    garbage = emptied.clone()  # ... whatever its row and clearances read
    row = s["obstacles"].start + 2 * w
    garbage[:, row : row + w] = 0.7
    garbage[:, s["distances"]][:, 2::K] = 0.01
    torch.testing.assert_close(extractor(garbage), extractor(emptied))
    assert not torch.allclose(extractor(emptied), extractor(obs))
    none = obs.clone()
    none[:, s["mask"]] = 0.0
    assert torch.isfinite(extractor(none)).all()


def test_bad_keywords_and_a_foreign_observation_are_refused_by_name():
    planar = gym.make("motiongym/HarvestArmPlanar-v0").observation_space
    with pytest.raises(ValueError, match=r"planar=False, dof=7, n_obstacles=10 \(shape \(185,\)"):
        HarvestObstacleSet(planar)
    with pytest.raises(ValueError, match="hidden must be a positive integer, got 0"):
        HarvestObstacleSet(planar, planar=True, hidden=0)
    with pytest.raises(ValueError, match="waist_frame must be true or false, got 'yes'"):
        HarvestObstacleSet(planar, planar=True, waist_frame="yes")


def test_a_dagger_config_naming_it_trains_and_the_model_evaluates(tmp_path):
    env_id = "motiongym/HarvestArmPlanar-v0"
    config = tmp_path / "set.yml"
    config.write_text(
        "sac:\n  n_timesteps: 0\n  policy: MlpPolicy\n"
        "  policy_kwargs:\n    net_arch: [16]\n"
        "    features_extractor_class: harvest_obstacle_set\n"
        "    features_extractor_kwargs: {planar: true, hidden: 8, features_dim: 16}\n"
        "  imitate: potential-field-extended\n  imitate_kwargs: {markov: true}\n"
        "  dagger_iterations: 1\n  dagger_episodes: 2\n  bc_epochs: 1\n"
    )
    run_dir = train(env_id, "sac", config_path=config, out_root=tmp_path, progress=False)
    env = make_env(env_id, {})
    predictor = load_predictor(str(run_dir), env_id, env)
    assert isinstance(predictor.actor.features_extractor, HarvestObstacleSet)  # raw inputs
    assert evaluate(env, predictor, [3], env_id, "set", progress=False).episodes[0]["length"] > 0
