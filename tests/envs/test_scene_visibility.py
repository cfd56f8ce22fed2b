"""What a reader must see in a rendered frame: the excavator's reach target (a glowing green
sphere where the target projects) and its buried pipe (glowing blue through the ground);
the harvest arm's scene filling the frame. Each test renders the same state with and
without the object and asserts where and how much the picture changes."""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
import pytest

import motiongym  # noqa: F401  (registers the IDs)


@pytest.fixture
def reach():
    env = gym.make("motiongym/ExcavatorReach-v0", render_mode="rgb_array")
    env.reset(seed=0)
    yield env.unwrapped
    env.close()


def _changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a.astype(int) - b.astype(int)).sum(axis=2) > 60  # (H, W)


def test_the_reach_target_is_a_green_blob_in_the_frame(reach):
    shown = reach.render()
    scene = reach.world.scene
    reach.world.scene = dataclasses.replace(scene, target=None)
    hidden = reach.render()
    reach.world.scene = scene
    r, g, b = (shown.astype(int)[:, :, k] for k in range(3))
    green = _changed(shown, hidden) & (g > r + 80) & (g > b + 80)  # not its shadow
    assert green.sum() >= 100  # pixels: a 0.35 m sphere at 24 m in a 640 x 480 frame
    rows, cols = np.nonzero(green)
    assert rows.max() - rows.min() < 60 and cols.max() - cols.min() < 60  # one blob


def test_the_buried_pipe_shows_through_the_ground(reach):
    shown = reach.render()
    pipe = reach.world.pipe
    reach.world.pipe = dataclasses.replace(pipe, a=(0.0, 0.0, -50.0), b=(1.0, 0.0, -50.0))
    hidden = reach.render()
    reach.world.pipe = pipe
    changed = _changed(shown, hidden)
    assert changed.sum() >= 1000  # a line across the site, not a speck
    rows, cols = np.nonzero(changed)
    assert cols.max() - cols.min() > 200  # pixels: across a third of the frame
    shift = (shown.astype(int) - hidden.astype(int))[changed].mean(axis=0)  # (3,) RGB
    assert shift[2] > 40 and shift[2] > 3 * shift[0]  # the ground turns blue over it


def _coloured_extent(frame: np.ndarray) -> tuple[float, float]:
    """Width and height (fractions of the frame's) of the box around the coloured pixels:
    arm, fruit and obstacles (the floor is grey, the sky black)."""
    f = frame.astype(int)
    rows, cols = np.nonzero(f.max(axis=2) - f.min(axis=2) > 40)
    return (cols.max() - cols.min()) / f.shape[1], (rows.max() - rows.min()) / f.shape[0]


def test_the_spatial_harvest_scene_fills_the_frame():
    extents = []
    for seed in range(4):
        env = gym.make("motiongym/HarvestArm-v0", render_mode="rgb_array")
        env.reset(seed=seed)
        extents.append(_coloured_extent(env.render()))
        env.close()
    width, height = np.mean(extents, axis=0)
    # the former camera (1.7 m away, 20 degrees down): 0.36 of the width, 0.55 of the height
    assert width > 0.45 and height > 0.65
