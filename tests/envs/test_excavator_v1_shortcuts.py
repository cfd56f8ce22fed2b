"""The shortcuts of the v1 step give the numbers of the full computation.

The v1 world leaves out work that a lower bound shows cannot change a
result (a clearance's part, a box edge, a segment, a ground sample); with
``SKIP`` infinite nothing is left out. Each test compares the two, to the
last bit where the value is reported.
"""

from __future__ import annotations

import dataclasses
import math
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import motiongym  # noqa: E402,F401
from motiongym.envs.excavator import bodies, clearances_v1, world_v1  # noqa: E402
from motiongym.envs.excavator.digging import DEPTH_TOLERANCE  # noqa: E402
from motiongym.envs.excavator.obstacles import segment_box_distance  # noqa: E402
from motiongym.envs.excavator.scenes import CELL_XS, CELL_YS, ground_plane  # noqa: E402


def _box(rng, spread):
    axes = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    return bodies.Box(
        tuple(rng.uniform(-spread, spread, 3)),
        tuple(map(tuple, axes)),
        tuple(rng.uniform(0.2, 1.5, 3)),
    )


def _every_edge(p, q):
    """Box distance from all 24 edges, nothing left out (the definition)."""
    if p.contains(q.centre) or q.contains(p.centre):
        return 0.0
    return min(
        bodies.segment_to_box(a, b, other)
        for one, other in ((p, q), (q, p))
        for a, b in one.edges()
    )


def test_box_distance_equals_the_smallest_over_every_edge():
    rng = np.random.default_rng(5)
    apart = 0
    for spread in (1.0, 2.5, 6.0):  # overlapping, near, far
        for _ in range(300):
            p, q = _box(rng, spread), _box(rng, spread)
            d = bodies.box_to_box(p, q)
            assert d == _every_edge(p, q)
            apart += d > 0.0
    assert apart > 300


def test_segment_bound_stands_in_only_above_what_is_asked():
    rng = np.random.default_rng(6)
    ruled_out = 0
    for _ in range(2000):
        box = _box(rng, 1.0)
        a, b = tuple(rng.uniform(-4, 4, 3)), tuple(rng.uniform(-4, 4, 3))
        exact = bodies.segment_to_box(a, b, box)
        low = tuple(-h for h in box.half)
        assert exact == segment_box_distance(box.local(a), box.local(b), low, box.half)
        above = exact * rng.uniform(0.0, 1.2)
        d = bodies.segment_to_box(a, b, box, above)
        if d != exact:  # the bound: below the distance, past what was asked
            ruled_out += 1
            assert above + bodies.SKIP <= d <= exact + 1e-12  # a bound, to rounding
    assert ruled_out > 100


def _clearances(world):
    return world.pipe_clear, world.truck_clear, world.self_clear


def _every_part(world, monkeypatch):
    """The clearances with nothing left out (``SKIP`` infinite)."""
    with monkeypatch.context() as patch:
        patch.setattr(clearances_v1, "SKIP", math.inf)
        patch.setattr(world_v1, "SKIP", math.inf)
        patch.setattr(bodies, "SKIP", math.inf)
        world._clearances()
    return _clearances(world)


@pytest.mark.parametrize("env_id", ["motiongym/Excavator-v1", "motiongym/ExcavatorReach-v1"])
def test_clearances_are_those_of_every_part(env_id, monkeypatch):
    """Ablation: without the skips every part is measured; the same values, on random
    play (the arm folded by the cab and the truck) and on poses over the joint ranges."""
    env = gym.make(env_id)
    world, m = env.unwrapped.world, env.unwrapped.m
    near = 0
    for seed in range(8):
        env.reset(seed=seed)
        env.action_space.seed(seed)
        for _ in range(600):
            _, _, terminated, truncated, _ = env.step(env.action_space.sample())
            fast = _clearances(world)
            assert _every_part(world, monkeypatch) == fast
            near += world.truck_clear < clearances_v1.HORIZON or world.self_clear < 0.3
            if terminated or truncated:
                env.reset()
    for q in np.random.default_rng(3).uniform(m.q_min, m.q_max, size=(500, 4)):
        world.q = list(q)
        world._forward()
        world._clearances()
        assert _every_part(world, monkeypatch) == _clearances(world)
    assert near > 100  # the exact distances were exercised, not only the bounds


@pytest.mark.parametrize(("relief", "slope"), [("flat", 0.3), ("flat", 0.1), ("sampled", 0.1)])
def test_ground_depth_is_exact_over_the_tolerance(relief, slope):
    """Ablation: looking up every underside sample gives the same depth wherever a step
    reads it (over ``DEPTH_TOLERANCE``), and a depth within it otherwise; on a flat
    slope the relief bound is tight, and on the steepest slope (0.3 rad) the plane
    rises more within a cell than the relief's 1 cm margin."""
    env = gym.make("motiongym/Excavator-v1", slope=slope).unwrapped
    scene = env.task.sample_scene(np.random.default_rng(4))
    if relief == "flat":
        gx, gy = ground_plane(scene.base)
        plane = gx * CELL_XS[:, None] + gy * CELL_YS[None, :]
        scene = dataclasses.replace(scene, heights=plane)
    env.task.sample_scene = lambda rng: scene
    env.reset(seed=4)
    world, m = env.world, env.m
    rng = np.random.default_rng(4)
    over = 0
    for q in rng.uniform(m.q_min, m.q_max, size=(3000, 4)):
        pose = world_v1.Pose(list(q), world)
        h = world.terrain.height_at
        full = max(h(x, y) - z for x, y, z in pose.under())
        depth = world._penetration(pose)
        if full > DEPTH_TOLERANCE:
            over += 1
            assert depth == full
        else:
            assert depth <= DEPTH_TOLERANCE
    assert over > 100


@pytest.mark.parametrize("env_id", ["motiongym/Excavator-v1", "motiongym/ExcavatorReach-v1"])
def test_bounding_spheres_contain_their_boxes(env_id):
    """The bucket's and the house's spheres (whose gaps stand in for the boxes' distances
    above a horizon) contain every corner of their boxes, over the joint ranges."""
    env = gym.make(env_id)
    world, m = env.unwrapped.world, env.unwrapped.m
    env.reset(seed=0)
    for q in np.random.default_rng(4).uniform(m.q_min, m.q_max, size=(300, 4)):
        world.q = list(q)
        world._forward()
        for name in ("bucket", "house"):
            cache: dict = {}
            centre, radius = world._sphere(cache, name)
            corners = world._part(cache, name).corners()
            assert max(math.dist(centre, c) for c in corners) <= radius + 1e-9, name
