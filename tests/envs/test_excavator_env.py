"""ExcavatorReach-v0 and Excavator-v0: API, determinism, reward terms, physics, errors."""

from __future__ import annotations

import os
import pickle
import warnings

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from gymnasium.utils.env_checker import check_env  # noqa: E402
from stable_baselines3.common.env_checker import check_env as sb3_check_env  # noqa: E402

import motiongym  # noqa: E402, F401
from motiongym.envs.excavator import world as base  # noqa: E402
from motiongym.envs.excavator.obstacles import pipe_clearance, truck_clearance  # noqa: E402

IDS = ("motiongym/ExcavatorReach-v0", "motiongym/Excavator-v0")
ALL_IDS = (*IDS, "motiongym/ExcavatorReach-v1", "motiongym/Excavator-v1")


@pytest.mark.parametrize("env_id", ALL_IDS)
def test_api_checks(env_id, drawing_display):
    env = gym.make(env_id, render_mode="rgb_array")
    check_env(env.unwrapped)
    sb3_check_env(env.unwrapped, warn=False)
    env.close()


@pytest.mark.parametrize("env_id", ALL_IDS)
def test_determinism_reward_terms_and_bounds(env_id):
    def rollout(seed):
        env = gym.make(env_id)
        obs, info = env.reset(seed=seed)
        rng = np.random.default_rng(0)
        out = [obs]
        for _ in range(150):
            obs, reward, terminated, truncated, info = env.step(rng.uniform(-1, 1, 4))
            assert env.observation_space.contains(obs)
            terms = [v for k, v in info.items() if k.startswith("reward_")]
            assert sum(terms) == pytest.approx(reward, abs=1e-9)
            for key in env.unwrapped.metadata["info_measures"]:
                assert np.isscalar(info[key]), key
            assert info["cost"] in (0.0, 1.0)
            out.append(obs)
            if terminated or truncated:
                break
        return np.array(out)

    a, b = rollout(7), rollout(7)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(rollout(7)[0], rollout(8)[0])


@pytest.mark.parametrize("env_id", ALL_IDS)
def test_bad_input_raises(env_id):
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros(3))
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([0.0, np.nan, 0.0, 0.0]))
    for bad in (np.array([1j, 0, 0, 0]), "1111", ["a", "b", "c", "d"], np.zeros((1, 4)), 1.0):
        with pytest.raises(ValueError, match="Box"):
            env.step(bad)
    with pytest.raises(ValueError, match="unknown reset option"):
        env.reset(options={"target": 1})
    with pytest.raises(ValueError, match=r"options\['start'\] must be an array of shape \(4,\)"):
        env.reset(options={"start": [0.0, 1.0]})
    with pytest.raises(ValueError, match="render_mode"):
        type(env)(render_mode="human")
    with pytest.raises(ValueError, match="unknown keyword argument"):
        gym.make(env_id, unknown_weight=1.0)
    with pytest.raises(ValueError, match="options must be None or a dict"):
        env.reset(options="notadict")
    with pytest.raises(ValueError, match=r"options\['start'\] must be finite"):
        env.reset(options={"start": [0.0, np.nan, 0.0, 0.0]})


@pytest.mark.parametrize("env_id", IDS)
@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"machine": {"L2": -5}}, "machine.L2"),
        ({"machine": {"q_min": (0.0, 0.0, 0.0, 0.0), "q_max": (0.0, 1.0, 1.0, 1.0)}}, "q_min"),
        ({"machine": "big"}, "machine"),
        ({"dt": float("nan")}, "dt"),
        ({"dt": 0.0}, "dt"),
        ({"dt": 1e9}, "dt"),
        ({"time": float("inf")}, "time"),
        ({"pipe_safety": -1.0}, "pipe_safety"),
        ({"render_size": (0, 0)}, "render_size"),
        ({"physics": "v9"}, "physics"),
        ({"slope": 0.1}, "slope"),  # v0 physics is level
        ({"physics": "v1", "slope": 2.0}, "slope"),
    ],
)
def test_bad_keyword_arguments_name_the_argument(env_id, kwargs, name):
    with pytest.raises(ValueError, match=name):
        gym.make(env_id, **kwargs)


@pytest.mark.parametrize("env_id", ALL_IDS)
def test_step_and_render_before_reset_are_a_clear_error(env_id):
    env = gym.make(env_id, render_mode="rgb_array").unwrapped
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(4))
    with pytest.raises(RuntimeError, match="reset"):
        env.render()


@pytest.mark.parametrize("env_id", ALL_IDS)
def test_pickle_and_render(env_id):
    env = gym.make(env_id, render_mode="rgb_array", render_size=(120, 160))
    env.reset(seed=3)
    env.step(np.zeros(4))
    image = env.render()
    assert image.shape == (120, 160, 3) and image.dtype == np.uint8 and image.std() > 5
    clone = pickle.loads(pickle.dumps(env.unwrapped))
    action = np.array([0.3, -0.2, 0.5, -1.0])
    a = env.unwrapped.step(action)[0]
    b = clone.step(action)[0]
    np.testing.assert_array_equal(a, b)
    env.close()


def test_reported_clearances_are_exact_near_and_lower_bounds_far():
    env = gym.make("motiongym/Excavator-v0").unwrapped
    rng = np.random.default_rng(5)
    m = env.m
    for seed in range(30):
        env.reset(seed=seed)
        for _ in range(40):
            env.world.q = list(rng.uniform(m.q_min, m.q_max))
            env.world._forward()
            env.world._clearances()
            pipe = pipe_clearance(env.world.points, m.link_radius, env.world.pipe)
            truck = truck_clearance(env.world.points, m.link_radius, env.world.truck)
            for got, exact in ((env.world.pipe_clear, pipe), (env.world.truck_clear, truck)):
                if exact < base.HORIZON:
                    assert got == pytest.approx(exact, abs=1e-9)
                else:
                    assert base.HORIZON <= got <= exact + 1e-9


def test_digging_fills_the_bucket_slows_the_arm_and_pouring_spills():
    from motiongym.baselines.excavator.newton_raphson import analytic_solutions, within_limits

    env = gym.make("motiongym/Excavator-v0").unwrapped
    seed = 0
    env.reset(seed=seed)
    zone = env.scene.zone
    tip = np.array([np.cos(zone.azimuth), np.sin(zone.azimuth), 0.0]) * zone.r_far
    tip[2] = env.world.terrain.height_at(tip[0], tip[1]) + 0.05
    q0 = next(s for s in analytic_solutions(tip, -1.6, env.m) if within_limits(s, env.m))
    env.reset(seed=seed, options={"start": q0})
    volume0 = env.world.terrain.volume()
    rates = []
    for _ in range(8):  # boom down: the bucket enters the ground
        _, _, terminated, _, info = env.step(np.array([0.0, -0.15, 0.0, 0.0]))
        rates.append(abs(env.world.qdot[1]) / (0.15 * env.m.rate_max[1]))
        assert not terminated
    t = env.world.terrain
    i, j = int((env.world.tip[0] - t.x0) / t.cell), int((env.world.tip[1] - t.y0) / t.cell)
    assert env.scene.heights[i, j] - env.world.tip[2] > 0.3  # below the original surface
    assert rates[0] == 1.0 and min(rates) < 0.9  # slowed by the soil
    for _ in range(15):  # stick in: drag toward the machine
        _, _, terminated, _, info = env.step(np.array([0.0, 0.0, -0.5, -0.2]))
        assert not terminated
    assert info["bucket_fill"] > 0.1
    assert volume0 - env.world.terrain.volume() == pytest.approx(info["bucket_fill"], abs=1e-9)
    assert info["outside_zone"] < 0.05 * info["bucket_fill"]  # dug along the marked strip
    # Lift and open the bucket away from the truck: the soil is spilled on the ground.
    for _ in range(40):
        _, _, _, _, info = env.step(np.array([0.0, 1.0, 0.0, 1.0]))
    assert info["spill"] > 0.0 and info["truck_soil"] == 0.0
    assert info["spill"] + info["bucket_fill"] == pytest.approx(info["dig_fill"], abs=1e-9)
    assert volume0 - env.world.terrain.volume() == pytest.approx(info["bucket_fill"], abs=1e-9)


def test_joint_limits_hold_and_rates_are_the_hydraulic_limits():
    env = gym.make("motiongym/ExcavatorReach-v0").unwrapped
    env.reset(seed=0)
    _, _, _, _, _ = env.step(np.ones(4))
    assert env.world.qdot == pytest.approx(list(env.m.rate_max))
    for _ in range(100):
        env.step(np.ones(4))
    assert env.world.q[1] == pytest.approx(env.m.q_max[1])
    assert env.world.qdot[1] == 0.0


def test_reach_success_terminates_with_the_bonus():
    from motiongym.baselines.excavator.newton_raphson import analytic_solutions, within_limits

    env = gym.make("motiongym/ExcavatorReach-v0").unwrapped
    _, info = env.reset(seed=1)
    assert info["position_error"] > env.params.tolerance_position and not info["is_success"]
    target = env.scene.target
    q = next(s for s in analytic_solutions(target[:3], target[3], env.m) if within_limits(s, env.m))
    env.reset(seed=1, options={"start": q})
    _, reward, terminated, _, info = env.step(np.zeros(4))
    assert terminated and info["is_success"]
    assert info["position_error"] < 1e-9 and info["angle_error"] < 1e-9
    assert info["reward_success"] == env.params.weights["success"]


@pytest.mark.parametrize("env_id, task", [(IDS[0], "reach"), (IDS[1], "dig")])
def test_observation_slices_match_the_state(env_id, task):
    from motiongym.envs.excavator.observation import layout

    env = gym.make(env_id).unwrapped
    env.reset(seed=2)
    rng = np.random.default_rng(0)
    for _ in range(30):
        obs, *_ = env.step(rng.uniform(-1, 1, 4))
    lay = layout(task)
    assert obs.shape == env.observation_space.shape and obs.dtype == np.float32
    np.testing.assert_allclose(obs[lay["q"]], env.world.q, atol=1e-6)
    np.testing.assert_allclose(obs[lay["qdot"]], env.world.qdot, atol=1e-6)
    np.testing.assert_allclose(obs[lay["tip"]], env.world.tip, atol=1e-5)
    assert obs[lay["bucket"]][0] == pytest.approx(env.world.beta, abs=1e-6)
    np.testing.assert_allclose(obs[lay["truck"]], env.world.truck.as_array(), atol=1e-5)
    np.testing.assert_allclose(obs[lay["pipe"]], env.world.pipe.as_array(), atol=1e-5)
    c, s = np.cos(env.world.q[0]), np.sin(env.world.q[0])
    r = 1.0 + 0.4 * np.arange(24)
    np.testing.assert_allclose(
        obs[lay["profile"]], env.world.terrain.heights_at(c * r, s * r), atol=0.2
    )
    if task == "dig":
        np.testing.assert_allclose(obs[lay["zone"]], env.scene.zone.as_array(), atol=1e-5)
        assert obs[lay["truck_soil"]][0] == pytest.approx(env.world.truck_soil)
    else:
        np.testing.assert_allclose(obs[lay["target"]], env.scene.target, atol=1e-5)


def test_digging_beside_the_zone_is_reported():
    from motiongym.baselines.excavator.newton_raphson import analytic_solutions, within_limits

    env = gym.make("motiongym/Excavator-v0").unwrapped
    env.reset(seed=4)
    zone = env.scene.zone
    azimuth = zone.azimuth + 0.6  # well beside the strip
    tip = np.array([np.cos(azimuth), np.sin(azimuth), 0.0]) * zone.r_far
    tip[2] = env.world.terrain.height_at(tip[0], tip[1]) + 0.05
    q0 = next(s for s in analytic_solutions(tip, -1.6, env.m) if within_limits(s, env.m))
    env.reset(seed=4, options={"start": q0})
    for _ in range(8):
        env.step(np.array([0.0, -0.15, 0.0, 0.0]))
    for _ in range(10):
        _, _, _, _, info = env.step(np.array([0.0, 0.0, -0.5, -0.2]))
    assert info["bucket_fill"] > 0.05
    assert info["outside_zone"] == pytest.approx(info["bucket_fill"], rel=1e-9)


# ----------------------------------------------------------------- the core contract
@pytest.mark.parametrize("env_id", ALL_IDS)
def test_the_environments_are_system_envs_on_the_protocols(env_id):
    from motiongym.envs import core

    env = gym.make(env_id).unwrapped
    assert isinstance(env, core.SystemEnv)
    assert isinstance(env.world, core.World) and isinstance(env.task, core.Task)
    assert env.action_space is env.world.action_space
    assert env.observation_space is env.task.observation_space
    assert env.task.reward_terms == type(env.params).REWARD_TERMS
    _, info = env.reset(seed=0)
    assert [k for k in info if k.startswith("reward_")] == [
        f"reward_{t}" for t in env.task.reward_terms
    ]
    assert env.scene is env.world.scene and env.scene.start == env.m.q_ready


@pytest.mark.parametrize("env_id", ["motiongym/ExcavatorReach-v0", "motiongym/Excavator-v1"])
def test_the_start_option_and_its_deprecated_name_q0(env_id):
    from motiongym.envs import checks, core

    env = gym.make(env_id).unwrapped
    q = np.array([0.3, 0.1, -1.2, -0.8])
    new, _ = env.reset(seed=5, options={"start": q})
    np.testing.assert_array_equal(env.scene.start, q)
    assert env.world.q == pytest.approx(q.tolist(), abs=0.0)
    checks._warned.clear()
    with pytest.warns(core.MotiongymDeprecationWarning, match="reset option: 'q0' is deprecated"):
        old, _ = env.reset(seed=5, options={"q0": q})
    np.testing.assert_array_equal(old, new)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once per process
        env.reset(seed=5, options={"q0": q})
    with pytest.raises(ValueError, match="give 'start' or its deprecated name 'q0', not both"):
        env.reset(options={"start": q, "q0": q})
    with pytest.raises(ValueError, match=r"options\['start'\] must be finite"):
        env.reset(options={"q0": [0.0, np.inf, 0.0, 0.0]})


@pytest.mark.parametrize(
    ("env_id", "name", "cost"),
    [
        ("motiongym/ExcavatorReach-v0", "time", True),
        ("motiongym/ExcavatorReach-v0", "contact", True),
        ("motiongym/ExcavatorReach-v1", "closeness", False),
        ("motiongym/Excavator-v0", "spill", True),
        ("motiongym/Excavator-v1", "approach", False),
        ("motiongym/Excavator-v1", "delivered", False),
    ],
)
def test_reward_weights_are_magnitudes(env_id, name, cost):
    why = (
        rf"a cost term is subtracted \(give {name}=0.5 for the same reward\)"
        if cost
        else rf"{name} is paid \(added\), so no weight makes it a cost"
    )
    with pytest.raises(ValueError, match=rf"{name} must be a reward weight .*got -0.5: .*{why}"):
        gym.make(env_id, **{name: -0.5})
    with pytest.raises(ValueError, match=rf"{name} must be a finite number in \[0.0, 1000000.0\]"):
        gym.make(env_id, **{name: 2e6})
    assert gym.make(env_id, **{name: 0.0}).unwrapped.params.weights[name] == 0.0


@pytest.mark.parametrize("size", [(720, 1280), (16, 2048), (2048, 16)])
def test_every_allowed_render_size_renders(size):
    """Past MuJoCo's default 640 x 480 offscreen buffer too (the world enlarges it)."""
    env = gym.make("motiongym/ExcavatorReach-v1", render_mode="rgb_array", render_size=size)
    env.reset(seed=1)
    frame = env.render()
    assert frame.shape == (*size, 3) and frame.dtype == np.uint8 and frame.std() > 1
    env.close()
