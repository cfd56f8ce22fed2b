"""SweeperVectorEnv: step-for-step equal to SyncVectorEnv of SweeperEnv (same-step autoreset)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, SyncVectorEnv

import motiongym  # noqa: F401
from motiongym.envs.checks import VECTOR_MEMORY_BOUND
from motiongym.envs.sweeper.env import SweeperEnv
from motiongym.envs.sweeper.generator import empty_room
from motiongym.envs.sweeper.vector_env import SweeperVectorEnv, bytes_per_env

ENV_ID = "motiongym/Sweeper-v0"


def assert_same(a, b, path: str = "") -> None:
    """Exact equality of nested dicts / object arrays / arrays, dtypes included."""
    if isinstance(a, (tuple, list)):
        assert isinstance(b, (tuple, list)) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{path}[{i}]")
    elif isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), (path, set(a) ^ set(b))
        for key in a:
            assert_same(a[key], b[key], f"{path}/{key}")
    elif isinstance(a, np.ndarray) and a.dtype == object:
        assert isinstance(b, np.ndarray) and b.dtype == object and a.shape == b.shape, path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert (x is None) == (y is None), (path, i)
            if x is not None:
                assert_same(x, y, f"{path}[{i}]")
    else:
        a, b = np.asarray(a), np.asarray(b)
        assert a.dtype == b.dtype and a.shape == b.shape, (path, a.dtype, b.dtype, a.shape, b.shape)
        np.testing.assert_array_equal(a, b, err_msg=path)


def sync_twin(num_envs: int, max_steps: int, **kwargs) -> SyncVectorEnv:
    return SyncVectorEnv(
        [lambda: gym.make(ENV_ID, max_episode_steps=max_steps, **kwargs)] * num_envs,
        autoreset_mode=AutoresetMode.SAME_STEP,
    )


def compare(num_envs: int, max_steps: int, n_steps: int, seed: int, **kwargs) -> tuple[int, int]:
    """Step both with the same random actions; return (terminations, truncations)."""
    native = SweeperVectorEnv(num_envs=num_envs, max_episode_steps=max_steps, **kwargs)
    sync = sync_twin(num_envs, max_steps, **kwargs)
    assert_same(native.reset(seed=seed), sync.reset(seed=seed), "reset")
    rng = np.random.default_rng(seed)
    n_term = n_trunc = 0
    for t in range(n_steps):
        actions = rng.choice(3, size=num_envs, p=[0.6, 0.2, 0.2])
        got, want = native.step(actions), sync.step(actions)
        for name, x, y in zip(("obs", "reward", "term", "trunc", "info"), got, want, strict=True):
            assert_same(x, y, f"step {t} {name}")
        n_term += int(got[2].sum())
        n_trunc += int(got[3].sum())
    return n_term, n_trunc


@pytest.mark.parametrize(
    ("kwargs", "num_envs", "max_steps", "n_steps"),
    [
        ({"grid": empty_room(8, 11)}, 4, 150, 800),  # terminations (full coverage) and truncations
        ({"map_name": "room"}, 3, 70, 600),
        ({"map_name": "maze", "robot_width": 2, "coarse": 8}, 2, 90, 400),
        (
            {"map_name": "apartment", "robot_width": 4, "sensor_range": 1, "sweep": 2.0},
            2,
            80,
            400,
        ),
        ({"map_name": "random-room"}, 5, 60, 300),  # maps of several shapes: the layout grows
        ({"map_name": "random"}, 3, 50, 300),
        # v1 (line of sight): the whole window is sensed again after every move
        ({"grid": empty_room(8, 11), "line_of_sight": True}, 4, 150, 800),
        ({"map_name": "room", "line_of_sight": True}, 3, 70, 600),
        ({"map_name": "maze", "robot_width": 2, "coarse": 8, "line_of_sight": True}, 2, 90, 400),
        ({"map_name": "random", "sensor_range": 5, "line_of_sight": True}, 3, 50, 300),
    ],
)
def test_step_for_step_equal_to_sync_vector_env(kwargs, num_envs, max_steps, n_steps) -> None:
    n_term, n_trunc = compare(num_envs, max_steps, n_steps, seed=7, **kwargs)
    assert n_trunc > 0
    if "grid" in kwargs:
        assert n_term > 0  # the small room gets fully swept by random actions


@pytest.mark.parametrize("map_name", ["room", "random-room"])
def test_full_coverage_episodes_with_the_scripted_policy(map_name: str) -> None:
    """PSA+CWA sweeps whole maps: terminations by success, compared step for step."""
    from motiongym.baselines.registry import make_policy

    native, sync = (
        SweeperVectorEnv(4, 3000, map_name=map_name),
        sync_twin(4, 3000, map_name=map_name),
    )
    policy = make_policy(
        ENV_ID,
        "psa-cwa",
        native.single_observation_space,
        native.single_action_space,
        {"map_name": map_name},
    )
    got = native.reset(seed=1)
    assert_same(got, sync.reset(seed=1))
    obs, start, successes = got[0], np.ones(4, bool), 0
    for t in range(4000):
        actions, _ = policy.predict(obs, episode_start=start)
        got, want = native.step(actions), sync.step(actions)
        assert_same(got, want, f"step {t}")
        obs, start = got[0], got[2] | got[3]
        successes += int(got[4].get("final_info", {}).get("is_success", np.zeros(4))[got[2]].sum())
        if successes >= 5:
            break
    assert successes >= 5


def test_same_seed_same_trajectory_and_reseeding() -> None:
    actions = np.random.default_rng(1).integers(0, 3, size=(300, 6))

    def rollout(env: SweeperVectorEnv) -> list:
        out = [env.reset(seed=11)]
        out += [env.step(a) for a in actions]
        return out

    env = SweeperVectorEnv(num_envs=6, max_episode_steps=40, map_name="random-apartment")
    first = rollout(env)
    assert_same(first, rollout(env))  # the same env, reseeded
    assert_same(first, rollout(SweeperVectorEnv(6, 40, map_name="random-apartment")))
    # Sub-environment i is seeded with seed + i: different scenarios.
    pose = first[0][0]["pose"]
    assert len({tuple(p) for p in pose}) > 1


def test_returned_observations_are_not_overwritten() -> None:
    env = SweeperVectorEnv(num_envs=8, max_episode_steps=5)
    obs, _ = env.reset(seed=0)
    kept = {k: v.copy() for k, v in obs.items()}
    view = obs["sweep_map"][2:4]
    view_copy = view.copy()
    rng = np.random.default_rng(0)
    for _ in range(12):  # with autoresets
        env.step(rng.integers(0, 3, size=8))
    assert_same(obs, kept)
    np.testing.assert_array_equal(view, view_copy)


def test_recycled_observations_equal_sync_whatever_is_held() -> None:
    """Observations held for a while, dropped in any order: every one still matches."""
    native, sync = SweeperVectorEnv(6, 40), sync_twin(6, 40)
    assert_same(native.reset(seed=4), sync.reset(seed=4))
    rng = np.random.default_rng(4)
    held: list[tuple[dict, dict]] = []
    for _ in range(400):
        actions = rng.choice(3, size=6, p=[0.6, 0.2, 0.2])
        got, want = native.step(actions), sync.step(actions)
        assert_same(got, want)
        held.append((got[0], want[0]))
        while held and rng.random() < 0.7:  # drop one at random; the rest stay held
            mine, theirs = held.pop(int(rng.integers(len(held))))
            assert_same(mine, theirs)
    for mine, theirs in held:
        assert_same(mine, theirs)


def test_without_recycling_every_observation_is_fresh(monkeypatch) -> None:
    monkeypatch.setattr(SweeperVectorEnv, "recycle_observations", False)
    native, sync = SweeperVectorEnv(3, 25), sync_twin(3, 25)
    first = native.reset(seed=9)
    assert_same(first, sync.reset(seed=9))
    actions = np.random.default_rng(9).integers(0, 3, size=(60, 3))
    previous = first[0]
    for a in actions:
        got = native.step(a)
        assert_same(got, sync.step(a))
        assert all(got[0][k] is not previous[k] for k in got[0])
        previous = got[0]


def test_spaces_and_metadata() -> None:
    env = SweeperVectorEnv(num_envs=3, map_name="apartment", robot_width=2)
    single = gym.make(ENV_ID, map_name="apartment", robot_width=2)
    assert env.single_observation_space == single.observation_space
    assert env.single_action_space == single.action_space
    assert env.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    assert env.metadata["info_measures"] == single.unwrapped.metadata["info_measures"]
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    obs, *_ = env.step(np.zeros(3, np.int64))
    assert env.observation_space.contains(obs)


def test_partial_reset_with_mask() -> None:
    env = SweeperVectorEnv(num_envs=4)
    sync = sync_twin(4, 20_000)
    assert_same(env.reset(seed=3), sync.reset(seed=3))
    actions = np.random.default_rng(0).integers(0, 3, size=(20, 4))
    for a in actions:
        assert_same(env.step(a), sync.step(a))
    mask = np.array([False, True, False, True])
    assert_same(
        env.reset(seed=50, options={"reset_mask": mask}),
        sync.reset(seed=50, options={"reset_mask": mask.copy()}),
    )
    for a in actions:
        assert_same(env.step(a), sync.step(a))


def test_reset_options_reach_every_sub_environment() -> None:
    options = {"start": (2, 3), "heading": 1}
    env, sync = SweeperVectorEnv(3, 30), sync_twin(3, 30)
    got = env.reset(seed=0, options=options)
    assert_same(got, sync.reset(seed=0, options=options))
    assert (got[0]["pose"][:, :3] == [2, 3, 1]).all()
    for a in np.random.default_rng(0).integers(0, 3, size=(40, 3)):  # autoresets: random again
        assert_same(env.step(a), sync.step(a))
    with pytest.raises(ValueError, match="unknown reset option"):
        env.reset(options={"goal": 1})


@pytest.mark.parametrize(
    ("actions", "match"),
    [
        (np.zeros(3, np.int64), "shape"),
        (np.zeros((4, 2), np.int64), "shape"),
        (np.array([0, 1, 3, 0]), "sub-environment 2 got 3"),
        (np.array([0, -1, 0, 0]), "sub-environment 1 got -1"),
        (np.array([0.0, np.nan, 1.0, 2.0]), "got dtype float64"),
        (np.array([0.0, 0.5, 1.0, 2.0]), "got dtype float64"),
        (np.array([0.0, 1.0, 1.0, 2.0]), "got dtype float64"),  # as MultiDiscrete.contains
        (np.array(["a", "b", "c", "d"]), "got dtype <U1"),
        (np.zeros((4, 1), np.int64), r"shape \(4,\) in MultiDiscrete\(\[3\] \* 4\)"),
        ("0101", "got shape"),
        (np.array([0, 1, 2, 2], np.uint64), "got dtype uint64"),
    ],
)
def test_bad_actions_raise(actions, match) -> None:
    env = SweeperVectorEnv(num_envs=4)
    env.reset(seed=0)
    assert not env.action_space.contains(actions)
    with pytest.raises(ValueError, match=match):
        env.step(actions)


def test_accepts_what_the_action_space_contains() -> None:
    env = SweeperVectorEnv(num_envs=4)
    env.reset(seed=0)
    for actions in ([0, 1, 2, 0], np.array([2, 1, 0, 0], np.uint8), np.ones(4, bool)):
        assert env.action_space.contains(actions)
        env.step(actions)


def test_bad_construction_raises() -> None:
    with pytest.raises(ValueError, match="heading_noise"):
        SweeperVectorEnv(num_envs=2, heading_noise=0.1)
    with pytest.raises(ValueError, match="slip_noise"):
        SweeperVectorEnv(num_envs=2, slip_noise=0.1)
    with pytest.raises(ValueError, match="map_name must be one of"):
        SweeperVectorEnv(num_envs=2, map_name="castle")
    with pytest.raises(ValueError, match="max_episode_steps must be an integer >= 1, got None"):
        SweeperVectorEnv(num_envs=2, max_episode_steps=None)
    with pytest.raises(RuntimeError, match="reset"):
        SweeperVectorEnv(num_envs=2).step(np.zeros(2, np.int64))


def test_sb3_adapter_over_native_vector_env() -> None:
    from motiongym.agents.training.vector import VectorEnvAdapter

    venv = VectorEnvAdapter(SweeperVectorEnv(num_envs=4, max_episode_steps=6))
    venv.seed(0)
    obs = venv.reset()
    assert obs["pose"].shape == (4, 4)
    for t in range(6):
        obs, rewards, dones, infos = venv.step(np.full(4, t % 3))
        assert rewards.dtype == np.float32 and len(infos) == 4
    assert dones.all()  # truncated at 6 steps
    for info in infos:
        assert info["TimeLimit.truncated"] is True
        assert info["terminal_observation"]["pose"].shape == (4,)
        assert info["steps"] == 6
    assert (obs["pose"][:, 3] == 0).all()  # the new episodes' first observations


def test_render_matches_single_env() -> None:
    kwargs = {"grid": empty_room(8, 11), "render_mode": "rgb_array", "render_size": (40, 50)}
    env = SweeperVectorEnv(num_envs=2, max_episode_steps=30, **kwargs)
    sync = sync_twin(2, 30, **kwargs)
    env.reset(seed=2)
    sync.reset(seed=2)
    for a in np.random.default_rng(2).integers(0, 3, size=(20, 2)):
        env.step(a)
        sync.step(a)
    for got, want in zip(env.render(), sync.render(), strict=True):
        np.testing.assert_array_equal(got, want)


@pytest.mark.skipif(
    not gym.spec(ENV_ID).vector_entry_point, reason="vector_entry_point not registered yet"
)
def test_make_vec_vector_entry_point() -> None:
    env = gym.make_vec(ENV_ID, num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(env.unwrapped, SweeperVectorEnv)
    assert env.unwrapped.max_episode_steps == gym.spec(ENV_ID).max_episode_steps
    sync = sync_twin(3, gym.spec(ENV_ID).max_episode_steps)
    assert_same(env.reset(seed=5), sync.reset(seed=5))
    for a in np.random.default_rng(5).integers(0, 3, size=(50, 3)):
        assert_same(env.step(a), sync.step(a))


@pytest.mark.slow
@pytest.mark.parametrize(
    ("kwargs", "num_envs", "max_steps"),
    [
        ({"map_name": "room", "robot_width": 1, "sensor_range": 1}, 6, 300),
        ({"map_name": "apartment", "coarse": 64}, 4, 500),
        ({"map_name": "maze", "coarse": 1, "sensor_range": 6}, 4, 400),
        ({"map_name": "random-maze", "robot_width": 2}, 6, 200),
        ({"map_name": "random-apartment", "robot_width": 5, "sensor_range": 2}, 6, 200),
        ({"map_name": "random", "time": 0.3, "bump": 2.5}, 8, 150),
        ({"map_name": "apartment", "robot_width": 1, "line_of_sight": True}, 4, 400),
        ({"map_name": "random-apartment", "sensor_range": 6, "line_of_sight": True}, 6, 200),
    ],
)
def test_long_runs_equal_to_sync_vector_env(kwargs, num_envs, max_steps) -> None:
    """Edge widths, sensor ranges and coarse resolutions over thousands of steps."""
    _, n_trunc = compare(num_envs, max_steps, 3000, seed=123, **kwargs)
    assert n_trunc > 0


@pytest.mark.parametrize("line_of_sight", [False, True])
def test_state_of_each_sub_environment_equals_the_single_env_state(line_of_sight: bool) -> None:
    """The vector twin exports the single env's SweeperState (sweep counts stop at 2)."""
    import dataclasses

    kwargs = {"map_name": "room", "line_of_sight": line_of_sight, "render_mode": "rgb_array"}
    native = SweeperVectorEnv(num_envs=3, max_episode_steps=10_000, **kwargs)
    singles = [gym.make(ENV_ID, **kwargs).unwrapped for _ in range(3)]
    native.reset(seed=9)
    for i, env in enumerate(singles):
        env.reset(seed=9 + i)
    rng = np.random.default_rng(9)
    for _ in range(400):
        actions = rng.choice(3, size=3, p=[0.6, 0.2, 0.2])
        native.step(actions)
        for env, a in zip(singles, actions.tolist(), strict=True):
            env.step(a)
    for i, env in enumerate(singles):
        got, want = native.state(i), env.state
        for field in dataclasses.fields(want):
            a, b = getattr(got, field.name), getattr(want, field.name)
            if field.name == "sweeps":
                b = np.minimum(b, 2)
            if field.name == "scenario":
                np.testing.assert_array_equal(a.obstacle, b.obstacle)
                assert a.start == b.start
                continue
            np.testing.assert_array_equal(a, b, err_msg=field.name)
        assert got.n_overswept > 0 and got.known_obstacles.any()


# --- bad input: num_envs and per-env reset options ---

LARGE = {"sensor_range": 16, "robot_width": 10, "coarse": 64}  # the largest window and maps


@pytest.mark.parametrize("kwargs", [{}, {"map_name": "random"}, LARGE])
@pytest.mark.parametrize("num_envs", [0, -1, 2.5, "4", True, None, "bound + 1"])
def test_num_envs_outside_its_range_is_one_clear_error(kwargs, num_envs) -> None:
    """0, negative, not an integer, or beyond the memory bound (4 GiB over the estimate of
    one sub-environment for these parameters): a ValueError naming num_envs, the value
    and the range, from the class and through gym.make_vec alike."""
    bound = VECTOR_MEMORY_BOUND // bytes_per_env(SweeperEnv(**kwargs))
    value = bound + 1 if num_envs == "bound + 1" else num_envs
    message = (
        rf"num_envs must be an integer in \[1, {bound}\], got {value!r} "
        r"\(the memory bound: 4 GiB at up to \d+\.\d KiB per sub-environment"
    )
    with pytest.raises(ValueError, match=message):
        SweeperVectorEnv(num_envs=value, **kwargs)
    with pytest.raises(ValueError, match=message):
        gym.make_vec(ENV_ID, num_envs=value, vectorization_mode="vector_entry_point", **kwargs)


def test_the_memory_bound_holds_for_the_bytes_each_sub_environment_takes() -> None:
    """bytes_per_env is an upper estimate: the traced memory grows by less per added
    sub-environment (reset and a few steps, a fixed map and procedural ones), and by more
    than half of it, so the bound is not loose by more than a factor of two."""
    import tracemalloc

    for kwargs in ({"map_name": "room"}, {"map_name": "random"}):
        peaks = []
        for n in (16, 80):
            tracemalloc.start()
            env = SweeperVectorEnv(num_envs=n, **kwargs)
            env.reset(seed=0)
            for _ in range(3):
                env.step(np.zeros(n, np.int64))
            peaks.append(tracemalloc.get_traced_memory()[1])
            tracemalloc.stop()
            env.close()
            del env
        per_env = (peaks[1] - peaks[0]) / 64
        estimate = bytes_per_env(SweeperEnv(**kwargs))
        assert 0.5 * estimate < per_env < estimate, (kwargs, per_env, estimate)
    assert VECTOR_MEMORY_BOUND // bytes_per_env(SweeperEnv(map_name="random")) == 69_897


def test_per_env_reset_options_reach_their_own_sub_environment() -> None:
    """A list of num_envs starts or headings gives value i to sub-environment i, as a
    single environment reset with seed + i and that value (None: sampled)."""
    starts, headings = [(2, 3), None, (4, 5)], [1, 2, None]
    env = SweeperVectorEnv(3, 30)
    observation, _ = env.reset(seed=0, options={"start": starts, "heading": headings})
    for i in range(3):
        single = SweeperEnv()
        options = {"start": starts[i], "heading": headings[i]}
        expected, _ = single.reset(seed=i, options=options)
        for key, value in expected.items():
            np.testing.assert_array_equal(observation[key][i], value, err_msg=f"{i} {key}")
    assert observation["pose"][0, :3].tolist() == [2, 3, 1]
    assert observation["pose"][2, :2].tolist() == [4, 5]
    mask = np.array([False, True, False])
    observation, _ = env.reset(seed=9, options={"heading": [0, 3, 0], "reset_mask": mask})
    assert observation["pose"][1, 2] == 3  # indexed by sub-environment under a mask


@pytest.mark.parametrize(
    ("options", "match"),
    [
        (
            {"start": [(2, 3), (2, 4)]},
            r"options\['start'\] must be one value for every sub-environment or a sequence "
            r"of num_envs=3 values, got 2 values: \[\(2, 3\), \(2, 4\)\]",
        ),
        ({"heading": [0, 1, 2, 3]}, r"options\['heading'\] .* num_envs=3 values, got 4 values"),
        ({"heading": np.zeros(2, int)}, r"options\['heading'\] .* got 2 values"),
        ({"heading": []}, r"options\['heading'\] .* got 0 values"),
        ({"heading": 4}, r"options\['heading'\] must be an integer in \[0, 3\], got 4"),
        ({"heading": [0, 9, 0]}, r"options\['heading'\]\[1\] must be an integer in \[0, 3\]"),
        ({"start": [(2, 3), None, (1,)]}, r"options\['start'\]\[2\] must be \(row, col\)"),
        (
            {"reset_mask": np.ones(2, bool)},
            r"options\['reset_mask'\] must be a bool array of shape \(3,\) with a True, "
            r"got shape \(2,\)",
        ),
    ],
)
def test_per_env_reset_options_of_the_wrong_length_are_one_clear_error(options, match) -> None:
    env = SweeperVectorEnv(3, 30)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=match):
        env.reset(seed=0, options=options)
    with pytest.raises(ValueError, match=r"seed must be .* num_envs=3 seeds, got 2 seeds"):
        env.reset(seed=[1, 2])


def test_the_memory_bound_reads_a_generated_familys_map_size():
    from motiongym.envs.sweeper.vector_env import bytes_per_env

    small = gym.make("motiongym/Sweeper-v1", map_family="hall").unwrapped
    large = gym.make("motiongym/Sweeper-v1", map_family="hall", map_size=(200, 200)).unwrapped
    assert bytes_per_env(large) > 5 * bytes_per_env(small)  # 200 x 200 cells against 40 x 60
