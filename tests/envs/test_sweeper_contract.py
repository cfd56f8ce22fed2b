"""The sweeper on the core contract: protocols, weights as magnitudes, render size, aliases."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401
from motiongym.envs import checks, core
from motiongym.envs.sweeper.env import FORWARD, LEFT, SweeperEnv
from motiongym.envs.sweeper.generator import empty_room
from motiongym.envs.sweeper.render import OBSTACLE, draw
from motiongym.envs.sweeper.vector_env import SweeperVectorEnv

ENV_ID = "motiongym/Sweeper-v1"


def test_the_environment_is_a_system_env_on_the_protocols() -> None:
    env = gym.make(ENV_ID).unwrapped
    assert isinstance(env, core.SystemEnv)
    assert isinstance(env.world, core.World) and isinstance(env.task, core.Task)
    assert env.action_space is env.world.action_space
    assert env.observation_space is env.task.observation_space
    assert env.task.reward_terms == ("sweep", "time", "bump")
    assert set(env.task.options) == {core.START, "heading"}
    env.reset(seed=3, options={"start": (5, 5), "heading": 2})
    assert env.scene is env.scenario is env.world.state.scenario
    assert (env.scene.start, env.scene.heading) == ((5, 5), 2)


def test_odometry_noise_draws_from_the_episode_generator() -> None:
    """World.reset keeps the episode's generator: advance(action) takes none, and the
    same seed gives the same noisy episode."""

    def run(seed: int) -> list[tuple[float, float, float]]:
        env = SweeperEnv(map_name="room", heading_noise=0.05, slip_noise=0.2)
        env.reset(seed=seed)
        out = []
        for a in np.random.default_rng(0).choice(3, size=200, p=[0.8, 0.1, 0.1]):
            env.step(int(a))
            out.append((env.state.y, env.state.x, env.state.heading_error))
        return out

    assert run(4) == run(4)
    assert run(4) != run(5)


def test_costs_are_magnitudes_subtracted_bit_for_bit() -> None:
    """Defaults time = 0.05, bump = 1.0 subtracted: exactly the rewards of -0.05 and -1.0
    added (IEEE negation is exact)."""
    env = SweeperEnv(grid=empty_room(5, 8), robot_width=3)
    assert (env.params.time, env.params.bump) == (0.05, 1.0)
    env.reset(seed=0, options={"start": (1, 1), "heading": 2})  # facing the west wall
    _, reward, _, _, info = env.step(FORWARD)  # a bump
    assert info["reward_time"] == -0.05 and info["reward_bump"] == -1.0
    assert info["reward_sweep"] == 0.0 and info["cost"] == 1.0
    assert reward == 0.0 + -0.05 + -1.0
    _, reward, _, _, info = env.step(LEFT)
    assert (reward, info["reward_bump"]) == (-0.05, 0.0)
    custom = SweeperEnv(grid=empty_room(5, 8), robot_width=3, time=0.3, bump=2.5)
    custom.reset(seed=0, options={"start": (1, 1), "heading": 2})
    _, reward, _, _, info = custom.step(FORWARD)
    assert (info["reward_time"], info["reward_bump"], reward) == (-0.3, -2.5, -0.3 + -2.5)


@pytest.mark.parametrize(
    ("name", "value", "why"),
    [
        ("time", -0.05, r"a cost term is subtracted \(give time=0.05 for the same reward\)"),
        ("bump", -1.0, r"a cost term is subtracted \(give bump=1.0 for the same reward\)"),
        ("sweep", -1.0, r"sweep is paid \(added\), so no weight makes it a cost"),
    ],
)
def test_a_negative_weight_is_refused_with_its_positive_equivalent(name, value, why) -> None:
    match = rf"{name} must be a reward weight in \[0, 1e\+06\], got {value}: .*{why}"
    for make in (
        lambda: SweeperEnv(**{name: value}),
        lambda: gym.make(ENV_ID, **{name: value}),
        lambda: SweeperVectorEnv(num_envs=2, **{name: value}),
    ):
        with pytest.raises(core.ArgumentError, match=match):
            make()


def test_render_size_none_is_eight_pixels_per_cell() -> None:
    env = SweeperEnv(map_name="room", render_mode="rgb_array")
    env.reset(seed=0)
    assert env.params.render_size is None
    assert env.render().shape == (30 * 8, 40 * 8, 3)


@pytest.mark.parametrize(
    ("map_name", "size", "px"),  # room 30 x 40 cells, maze 48 x 48
    [
        ("room", (300, 500), 10),
        ("room", (240, 320), 8),
        ("maze", (100, 200), 2),
        ("room", (29, 80), 0),
    ],
)
def test_a_render_size_fits_the_map_at_whole_pixels_per_cell_centred(map_name, size, px) -> None:
    env = SweeperEnv(map_name=map_name, render_mode="rgb_array", render_size=size)
    env.reset(seed=2)
    for a in (0, 0, 1, 0, 0):
        env.step(a)
    frame = env.render()
    assert frame.shape == (*size, 3) and frame.dtype == np.uint8
    h, w = env.scenario.obstacle.shape
    if px == 0:  # larger than the frame at one pixel per cell: shrunk to fit, centred
        rows = np.flatnonzero((frame != OBSTACLE).any(axis=(1, 2)))
        cols = np.flatnonzero((frame != OBSTACLE).any(axis=(0, 2)))
        assert 0 < len(rows) <= size[0] and 0 < len(cols) <= size[1]
        return
    top, left = (size[0] - h * px) // 2, (size[1] - w * px) // 2
    inner = frame[top : top + h * px, left : left + w * px]
    np.testing.assert_array_equal(inner, draw(env.state, 3, px))
    assert min(size[0] // h, size[1] // w) == px  # the largest whole number that fits
    margin = np.ones(size, bool)
    margin[top : top + h * px, left : left + w * px] = False
    assert (frame[margin] == OBSTACLE).all()  # outside the map is obstacle


def test_random_maps_render_to_one_frame_shape() -> None:
    """A GIF of procedural maps has one frame size (the maps' sizes differ)."""
    env = gym.make(ENV_ID, map_name="random", render_mode="rgb_array", render_size=(256, 320))
    shapes, maps = set(), set()
    for seed in range(6):
        env.reset(seed=seed)
        maps.add(env.unwrapped.scenario.obstacle.shape)
        shapes.add(env.render().shape)
    assert len(maps) > 1 and shapes == {(256, 320, 3)}


def test_cell_pixels_is_a_deprecated_alias_that_warns_once() -> None:
    checks._warned.clear()
    with pytest.warns(core.MotiongymDeprecationWarning, match="'cell_pixels' is deprecated"):
        env = SweeperEnv(map_name="room", render_mode="rgb_array", cell_pixels=3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once per process
        gym.make(ENV_ID, cell_pixels=5)
    env.reset(seed=0)
    assert env.render().shape == (30 * 3, 40 * 3, 3)  # read as before
    assert SweeperEnv.Params.DEPRECATED["cell_pixels"].new is None
    with pytest.raises(core.ArgumentError, match="give render_size or the deprecated cell_pixels"):
        SweeperEnv(render_size=(64, 64), cell_pixels=3)
    with pytest.raises(core.ArgumentError, match=r"cell_pixels must be an integer in \[1, 32\]"):
        SweeperEnv(cell_pixels=33)
    with pytest.raises(core.ArgumentError, match=r"render_size\[0\] must be an integer in"):
        SweeperEnv(render_size=(8, 64))


@pytest.mark.parametrize("kwargs", [{"render_size": (100, 120)}, {"cell_pixels": 2}])
def test_the_vector_twin_renders_as_the_single_env(kwargs) -> None:
    common = {"grid": empty_room(8, 11), "render_mode": "rgb_array", **kwargs}
    native = SweeperVectorEnv(num_envs=2, max_episode_steps=30, **common)
    singles = [gym.make(ENV_ID.replace("v1", "v0"), **common).unwrapped for _ in range(2)]
    native.reset(seed=4)
    for i, single in enumerate(singles):
        single.reset(seed=4 + i)
    for a in np.random.default_rng(4).integers(0, 3, size=(12, 2)):
        native.step(a)
        for single, action in zip(singles, a.tolist(), strict=True):
            single.step(action)
    for got, single in zip(native.render(), singles, strict=True):
        np.testing.assert_array_equal(got, single.render())
