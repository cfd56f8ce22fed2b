"""The harvest-arm world: arms, Jacobians, clearances, scenes, env conventions."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium as gym  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from gymnasium.utils.env_checker import check_env  # noqa: E402
from stable_baselines3.common.env_checker import check_env as sb3_check_env  # noqa: E402

import motiongym  # noqa: E402, F401
from motiongym.envs.geometry import closest_points_between_segments  # noqa: E402
from motiongym.envs.harvest_arm.model import ArmKinematics, arm_spec  # noqa: E402
from motiongym.envs.harvest_arm.observation import observation_views  # noqa: E402
from motiongym.envs.harvest_arm.task import (  # noqa: E402
    START_CLEARANCE,
    clearance_to_arm,
    solve_ik,
)

ARMS = [(True, 3), (True, 4), (True, 5), (False, 5), (False, 6), (False, 7)]


def _make(planar: bool, dof: int, **kwargs) -> gym.Env:
    env_id = "motiongym/HarvestArmPlanar-v0" if planar else "motiongym/HarvestArm-v0"
    return gym.make(env_id, dof=dof, **kwargs)


@pytest.mark.parametrize(("planar", "dof"), ARMS)
def test_every_arm_passes_the_gymnasium_and_sb3_checkers(planar, dof):
    env = _make(planar, dof)
    check_env(env.unwrapped, skip_render_check=True)
    sb3_check_env(_make(planar, dof), warn=True)
    observation, _ = env.reset(seed=0)
    assert observation.shape == (env.unwrapped.task.layout.size,)


def test_a465_table_3_ranges_and_speeds():
    spec = arm_spec(5, planar=False)
    np.testing.assert_allclose(np.rad2deg(spec.limits), [175, 90, 110, 180, 105])
    np.testing.assert_allclose(spec.speeds, [3.14, 3.14, 3.14, 2.99, 3.02])
    kin = ArmKinematics(spec)
    points = kin.forward(np.zeros(5))  # stretched straight up
    np.testing.assert_allclose(points[-1], [0, 0, 0.3302 + 0.3048 + 0.3302 + 0.226], atol=1e-12)


@pytest.mark.parametrize(("planar", "dof"), ARMS)
def test_point_jacobians_match_finite_differences(planar, dof):
    spec = arm_spec(dof, planar)
    kin = ArmKinematics(spec)
    rng = np.random.default_rng(dof)
    for _ in range(3):
        q = rng.uniform(-0.8, 0.8, dof) * spec.limits
        _, jac = kin.jacobians(q)  # (P, dim, n)
        np.testing.assert_allclose(kin.jacobians_from_axes(q)[1], jac, atol=1e-12)
        numeric = np.zeros_like(jac)
        for j in range(dof):
            dq = np.zeros(dof)
            dq[j] = 1e-6
            numeric[:, :, j] = (kin.forward(q + dq) - kin.forward(q - dq)) / 2e-6
        np.testing.assert_allclose(jac, numeric, atol=1e-8)


def test_clearances_match_numpy_geometry_and_mj_geom_distance():
    env = _make(False, 7).unwrapped
    rng = np.random.default_rng(0)
    for seed in range(3):
        observation, _ = env.reset(seed=seed, options={"start": rng.uniform(-1, 1, 7)})
        o = observation_views(env.task.layout, observation)
        scene = env.scene
        points = o["points"]
        dist, _, _ = closest_points_between_segments(
            points[:-1, None], points[1:, None], o["a"][None], o["b"][None]
        )
        expected = np.minimum(dist - env.params.link_radius - o["radius"][None], 1.0)  # (L, K)
        np.testing.assert_allclose(o["distances"], expected, atol=1e-6)
        assert scene.is_bar.sum() == 3
        fromto = np.zeros(6)
        world = env.world
        for li, lg in enumerate(world.index["link_geoms"]):
            for k, og in enumerate(world.index["obstacle_geoms"]):
                d = mujoco.mj_geomDistance(world.model, world.data, lg, og, 10.0, fromto)
                assert min(d, 1.0) == pytest.approx(expected[li, k], abs=1e-6)


@pytest.mark.parametrize(("planar", "dof"), [(False, 7), (True, 4)])
def test_clearances_stay_exact_along_a_rollout(planar, dof):
    env = _make(planar, dof, terminate_on_collision=False).unwrapped
    env.reset(seed=5)
    rng = np.random.default_rng(5)
    for _ in range(40):
        observation, *_ = env.step(rng.uniform(-1, 1, dof).astype(np.float32))
        o = observation_views(env.task.layout, observation)
        dist, _, _ = closest_points_between_segments(
            o["points"][:-1, None], o["points"][1:, None], o["a"][None], o["b"][None]
        )
        expected = np.minimum(dist - env.params.link_radius - o["radius"][None], 1.0)
        np.testing.assert_allclose(o["distances"], expected, atol=1e-5)


def test_planar_clearance_of_a_known_case():
    env = _make(True, 3).unwrapped
    length = 0.861 / 3
    # arm stretched along +x; a 0.02 m sphere 0.1 m above the middle of link 2
    centre = [1.5 * length, 0.1]
    observation, info = env.reset(
        options={
            "start": np.zeros(3),
            "fruit": [0.5, -0.3],
            "obstacles": [{"center": centre, "radius": 0.02}],
        }
    )
    assert info["min_distance"] == pytest.approx(0.1 - 0.02 - 0.02, abs=1e-9)
    o = observation_views(env.task.layout, observation)
    assert o["mask"].sum() == 1
    assert o["distances"][1, 0] == pytest.approx(0.06, abs=1e-6)
    assert (o["distances"][:, 1:] == 1.0).all()  # empty slots read the clip value


@pytest.mark.parametrize(("planar", "dof"), ARMS)
def test_scenes_are_reachable_and_clear_of_the_start_pose(planar, dof):
    env = _make(planar, dof).unwrapped
    for seed in range(3):
        env.reset(seed=seed)
        scene = env.scene
        assert len(scene) == (8 if planar else 10)
        assert scene.is_bar.sum() == (0 if planar else 3)
        kin = env.world.kinematics
        start = kin.forward(np.array(kin.spec.home))
        assert clearance_to_arm(start, env.params.link_radius, scene).min() >= START_CLEARANCE
        assert solve_ik(kin, scene.fruit, np.array(kin.spec.home))[1] < 2e-3


def test_reward_terms_sum_and_info_keys():
    env = _make(False, 5)
    env.reset(seed=2)
    env.action_space.seed(2)
    for _ in range(20):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        terms = {k: v for k, v in info.items() if k.startswith("reward_")}
        assert set(terms) == {
            f"reward_{t}"
            for t in ("progress", "clearance", "collision", "effort", "success", "distance")
        }
        assert sum(terms.values()) == pytest.approx(reward)
        assert info["cost"] == float(info["min_distance"] < 0.03 or info["collision"])
        assert info["min_distance_so_far"] <= info["min_distance"]
        if terminated or truncated:
            break


def test_arriving_at_the_fruit_terminates_with_success():
    env = _make(True, 3).unwrapped
    kin = env.world.kinematics
    q_goal, _ = solve_ik(kin, np.array([0.5, -0.3]), np.array(kin.spec.home))
    fruit = kin.forward(q_goal)[-1]
    env.reset(options={"start": q_goal, "fruit": fruit, "obstacles": []})
    _, reward, terminated, _, info = env.step(np.zeros(3, np.float32))
    assert terminated and info["is_success"]
    assert info["reward_success"] == pytest.approx(10.0)


def test_same_seed_same_scene_and_trajectory():
    a, b = _make(False, 6), _make(False, 6)
    oa, _ = a.reset(seed=11)
    ob, _ = b.reset(seed=11)
    np.testing.assert_array_equal(oa, ob)
    action = np.linspace(-1, 1, 6).astype(np.float32)
    for _ in range(5):
        np.testing.assert_array_equal(a.step(action)[0], b.step(action)[0])


# gym.make warns of the unknown mode, and the deprecated alias of its use, before the
# environment refuses the value (the alias's own test is in test_core)
@pytest.mark.filterwarnings("ignore:.*render_mode='depth' that is not in")
@pytest.mark.filterwarnings("ignore:.*'width' is deprecated")
def test_bad_input_is_rejected_with_the_valid_choices():
    with pytest.raises(ValueError, match=r"dof must be an integer in \[5, 7\], got 4"):
        _make(False, 4)
    with pytest.raises(ValueError, match=r"dof must be an integer in \[3, 5\], got 7"):
        _make(True, 7)
    bad_kwargs = [
        ({"dof": 5.5}, "dof must be an integer"),
        ({"planar": "no"}, "planar must be True or False, got 'no'"),
        ({"link_radius": 0.0}, r"link_radius must be a finite number in \(0.0, 0.1\]"),
        ({"dt": float("nan")}, "dt must be a finite number"),
        ({"safety_distance": 0}, "safety_distance must be"),
        ({"n_obstacles": 10**5}, r"n_obstacles must be an integer in \[1, 32\]"),
        ({"n_bars": 11}, r"n_bars must be an integer in \[0, 10\]"),
        ({"collision": float("inf")}, "collision must be a finite number"),
        ({"self_collision": 1}, "self_collision must be True or False"),
        ({"render_mode": "depth"}, "render_mode must be one of"),
        ({"width": 0}, "width must be an integer"),
        ({"render_size": (360, 4096)}, r"render_size\[1\] must be an integer in \[16, 2048\]"),
        ({"effort": -0.5}, "give effort=0.5 for the same reward"),
        ({"effort": 1e308}, r"effort must be a finite number in \[0.0, 1000000.0\]"),
    ]
    for kwargs, message in bad_kwargs:
        with pytest.raises(ValueError, match=message):
            gym.make("motiongym/HarvestArm-v1", **kwargs)
    env = _make(True, 3)
    with pytest.raises(ValueError, match="valid: fruit, obstacles, start"):
        env.reset(options={"q0": 1})
    with pytest.raises(ValueError, match=r"options\['start'\] must be an array of shape \(3,\)"):
        env.reset(options={"start": 1})
    with pytest.raises(ValueError, match="None or a dict"):
        env.reset(options="notadict")
    with pytest.raises(ValueError, match="together"):
        env.reset(options={"fruit": [0.5, 0.0]})
    with pytest.raises(ValueError, match="keys"):
        env.reset(options={"fruit": [0.5, 0.0], "obstacles": [{"centre": [0, 0], "radius": 1}]})
    nan_obstacle = [{"center": [np.nan, 0.1], "radius": 0.02}]
    with pytest.raises(ValueError, match=r"options\['obstacles'\]\[0\]\['center'\] must be finite"):
        env.reset(options={"fruit": [0.5, 0.0], "obstacles": nan_obstacle})
    with pytest.raises(ValueError, match=r"options\['start'\] must be finite"):
        env.reset(options={"start": [np.nan, 0.0, 0.0]})
    inside = [{"center": [0.51, 0.0], "radius": 0.02}]
    with pytest.raises(ValueError, match=r"\[0\] must not overlap the fruit"):
        env.reset(options={"fruit": [0.5, 0.0], "obstacles": inside})
    too_many = [{"center": [0.1 * i, 0.5], "radius": 0.01} for i in range(9)]
    with pytest.raises(ValueError, match="at most 8 spheres and 0 bars"):
        env.reset(options={"fruit": [0.5, 0.0], "obstacles": too_many})
    env.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros(4))
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([np.nan, 0, 0]))
    with pytest.raises(RuntimeError, match="reset"):
        _make(True, 3).unwrapped.step(np.zeros(3, np.float32))


def test_an_unreachable_fruit_ends_by_the_time_limit():
    """Documented outcome: accepted, the episode truncates unsuccessfully (no hang)."""
    from motiongym.agents.evaluation.episodes import run_episode
    from motiongym.baselines import make_policy

    env = gym.make("motiongym/HarvestArmPlanar-v1", dof=3)
    policy = make_policy(
        "motiongym/HarvestArmPlanar-v1", "potential-field", env.observation_space,
        env.action_space, {"dof": 3, "planar": True},
    )  # fmt: skip
    options = {"fruit": [1.5, 1.5], "obstacles": [{"center": [0.4, 0.4], "radius": 0.02}]}
    result = run_episode(env, policy, seed=0, options=options)
    assert result["length"] == 300 and not result["is_success"]


def test_render_rgb_array_shows_the_scene():
    env = _make(False, 7, render_mode="rgb_array", render_size=(120, 160))
    env.reset(seed=0)
    for _ in range(3):
        env.step(env.action_space.sample())
    try:
        frame = env.render()
    except Exception as error:  # pragma: no cover - machines without EGL
        pytest.skip(f"offscreen rendering unavailable: {error}")
    assert frame.shape == (120, 160, 3)
    assert frame.std() > 5
    env.close()


@pytest.mark.parametrize(("planar", "dof"), ARMS)
def test_v1_self_distance_is_the_brute_force_distance_of_non_adjacent_links(planar, dof):
    """MuJoCo's link-link pairs against segment distances of our own joint points."""
    env_id = "motiongym/HarvestArmPlanar-v1" if planar else "motiongym/HarvestArm-v1"
    env = gym.make(env_id, dof=dof, terminate_on_collision=False)
    base = env.unwrapped
    kin = ArmKinematics(base.world.arm)
    rng = np.random.default_rng(dof + 10 * planar)
    limits = base.world.arm.limits
    r = base.params.link_radius
    seen_collision = seen_clear = 0
    for _ in range(60):
        q = rng.uniform(-limits, limits)
        _, info = env.reset(seed=1, options={"start": q})
        _, _, _, _, info = env.step(np.zeros(dof, dtype=np.float32))
        points = kin.forward(q)
        p0, p1 = points[:-1], points[1:]
        brute = min(
            float(closest_points_between_segments(p0[i], p1[i], p0[j], p1[j])[0]) - 2 * r
            for i in range(len(p0))
            for j in range(i + 2, len(p0))
        )
        assert info["self_distance"] == pytest.approx(min(brute, 1.0), abs=1e-6)
        assert info["self_collision"] == (brute <= 0.0)
        if brute <= 0.0:
            seen_collision += 1
            assert info["collision"] and info["cost"] == 1.0
            assert info["reward_collision"] == -base.params.collision
        else:
            seen_clear += 1
    assert seen_clear > 0
    if planar:  # random planar poses fold the arm onto itself often
        assert seen_collision > 0


def test_v1_terminates_on_self_collision_and_v0_ignores_it():
    """A planar 5-DOF arm folded back onto itself, no obstacle near."""
    q = np.array([0.0, 2.6, 2.6, 2.6, 0.0])
    far = [{"center": [0.8, 0.5], "radius": 0.01}]
    options = {"start": q, "fruit": np.array([0.5, -0.4]), "obstacles": far}
    v1 = gym.make("motiongym/HarvestArmPlanar-v1")
    v1.reset(seed=0, options=options)
    _, _, terminated, _, info = v1.step(np.zeros(5, dtype=np.float32))
    assert info["self_collision"] and info["collision"] and terminated
    v0 = gym.make("motiongym/HarvestArmPlanar-v0")
    v0.reset(seed=0, options=options)
    _, _, terminated, _, info = v0.step(np.zeros(5, dtype=np.float32))
    assert not info["collision"] and not terminated and "self_collision" not in info


def test_docstring_table_is_the_default_arms_layout():
    env = gym.make("motiongym/HarvestArm-v1").unwrapped
    layout = env.task.layout
    table = layout.table()
    doc = "\n".join(line.strip() for line in type(env).__doc__.splitlines())
    assert "\n".join(line.strip() for line in table.splitlines()) in doc
    observation, _ = env.reset(seed=0)
    assert set(observation_views(layout, observation)) >= {"q", "points", "distances"}
    with pytest.raises(ValueError, match="shape"):
        layout.parse(observation[:-1])  # the fields cover the whole vector


def test_the_env_is_a_world_and_a_task_on_the_core_contract():
    from motiongym.envs import core
    from motiongym.envs.harvest_arm.observation import layout_for, point_count

    env = _make(False, 7).unwrapped
    assert isinstance(env, core.SystemEnv)
    assert isinstance(env.world, core.World) and isinstance(env.task, core.Task)
    assert type(env).step is core.SystemEnv.step and type(env).reset is core.SystemEnv.reset
    assert env.dt == 0.05
    for planar, dof in ARMS:  # the layout's point count is the model's
        arm = arm_spec(dof, planar)
        assert point_count(arm) == ArmKinematics(arm).n_points
    p = env.params
    assert layout_for(p).size == env.observation_space.shape[0]


def test_deprecated_width_and_height_become_render_size_and_warn_once():
    from motiongym.envs import checks, core

    checks._warned.clear()
    with pytest.warns(core.MotiongymDeprecationWarning, match="'width' is deprecated"):
        env = _make(False, 7, width=160)
    assert env.unwrapped.params.render_size == (360, 160)
    with pytest.warns(core.MotiongymDeprecationWarning, match="'height' is deprecated"):
        env = _make(False, 7, width=160, height=120)
    assert env.unwrapped.params.render_size == (120, 160)
    with pytest.raises(ValueError, match="give 'render_size' or its deprecated name 'width'"):
        _make(False, 7, width=160, render_size=(120, 160))
    with pytest.raises(ValueError, match=r"height must be an integer in \[16, 2048\], got 5000"):
        _make(False, 7, height=5000)


def test_deprecated_reset_option_q_is_start_and_warns_once():
    from motiongym.envs import checks, core

    checks._warned.clear()
    q = np.array([0.3, -0.4, 0.5])
    new = _make(True, 3)
    old = _make(True, 3)
    observation, info = new.reset(seed=4, options={"start": q})
    with pytest.warns(core.MotiongymDeprecationWarning, match="reset option: 'q' is deprecated"):
        observation_q, info_q = old.reset(seed=4, options={"q": q})
    np.testing.assert_array_equal(observation_q, observation)
    assert info_q == info
    np.testing.assert_allclose(new.unwrapped.world.q, q)
    with pytest.raises(ValueError, match="give 'start' or its deprecated name 'q'"):
        old.reset(options={"q": q, "start": q})


def test_reward_weights_are_magnitudes():
    for term in ("progress", "clearance", "collision", "effort", "success", "distance"):
        with pytest.raises(ValueError, match=f"give {term}=2.0 for the same reward"):
            gym.make("motiongym/HarvestArm-v1", **{term: -2.0})
        with pytest.raises(ValueError, match=f"{term} must be a finite number in"):
            gym.make("motiongym/HarvestArm-v1", **{term: 1e308})
    env = gym.make("motiongym/HarvestArm-v1", effort=1e6, distance=1e6)  # the largest allowed
    env.reset(seed=0)
    _, reward, *_, info = env.step(np.ones(7, np.float32))
    assert np.isfinite(reward) and info["reward_effort"] == -1e6


def test_a_large_render_size_renders_at_that_size():
    env = _make(True, 5, render_mode="rgb_array", render_size=(1200, 1600))
    env.reset(seed=0)
    env.step(np.full(5, 0.5, np.float32))
    try:
        frame = env.render()
    except Exception as error:  # pragma: no cover - machines without EGL
        pytest.skip(f"offscreen rendering unavailable: {error}")
    assert frame.shape == (1200, 1600, 3)
    assert frame.std() > 5
    env.close()
