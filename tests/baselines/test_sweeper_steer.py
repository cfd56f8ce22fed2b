"""Steering by the estimated heading error (motiongym.baselines.sweeper.steer), checked
against the environment's own odometry (World._noisy_forward), not against steer's model."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

from motiongym.baselines.sweeper.steer import DIRECTION, steer
from motiongym.envs.sweeper.world import FORWARD

ENV_ID = "motiongym/Sweeper-v1"


def _drive(error: float, target_step: tuple[int, int], steering: bool) -> tuple[int, int]:
    """From a free cell of the room, the robot's true heading off by ``error``, try to
    reach the neighbour ``target_step`` away; return where the world puts the robot."""
    env = gym.make(ENV_ID, map_name="room", heading_noise=1e-9, slip_noise=0.0)
    env.reset(seed=0)
    world = env.unwrapped.world
    s = world.state
    reach = s.scenario.reach_configs
    rows, cols = np.nonzero(reach)
    for r0, c0 in zip(rows, cols, strict=True):  # a cell with every neighbour reachable
        if reach[r0 - 1 : r0 + 2, c0 - 1 : c0 + 2].all():
            break
    s.row, s.col, s.y, s.x = int(r0), int(c0), float(r0), float(c0)
    s.heading, s.heading_error = 0, error
    target = (s.row + target_step[0], s.col + target_step[1])
    for _ in range(4):  # turns first, then one forward move
        if steering:
            action = steer(
                s.heading,
                (s.y, s.x, s.heading_error),
                (s.row, s.col),
                [target],
                lambda q: bool(reach[q]),
            )
        else:  # the plain rule: face the target's direction, then forward
            want = DIRECTION[target_step]
            action = FORWARD if s.heading == want else (1 if (want - s.heading) % 4 == 1 else 2)
        world.advance(action)  # noise from the episode's generator
        if action == FORWARD:
            break
    return (s.row, s.col), target


# Errors near a quarter turn: from the cell centre one of the four commanded headings then
# leads to each neighbour (between quarter turns none does, and steer creeps instead).
@pytest.mark.parametrize(
    "error",
    [math.pi / 2 - 0.1, math.pi / 2 + 0.3, -math.pi / 2 + 0.2, math.pi - 0.35, -math.pi + 0.2],
)
@pytest.mark.parametrize("step", [(0, 1), (-1, 0), (0, -1), (1, 0)])
def test_steering_reaches_the_next_cell_where_the_plain_rule_misses(error, step) -> None:
    reached, target = _drive(error, step, steering=True)
    assert reached == target
    plain, _ = _drive(error, step, steering=False)
    assert plain != target  # the plain rule goes a quarter turn or more astray
