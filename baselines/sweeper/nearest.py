"""Greedy coverage: head for the nearest configuration that sweeps something new.

A teacher for learned agents, not one of the paper's algorithms. Its decision
depends on the robot's maps and pose only, never on a plan: wherever the
robot is (on the teacher's own path or on a learner's), the label is "the
first step of a shortest path to unswept floor", so a memoryless learner that
sees the same maps can copy it and DAgger's labels along a learner's states
mean the same thing as along the teacher's (Ross et al. 2011; PSA's stack
and lanes would instead be a plan the learner's detours break).

Rule, from the maps of :class:`~.belief.RobotMap` (unknown cells count as
free, as PSA + CWA treat them, and a move into one is sensed before it is
made: the ``sensed`` window reaches ``R >= 1`` cells ahead):

- a configuration (footprint top-left cell) is *open* when its ``w x w``
  footprint holds no known obstacle; it is a *goal* when it is open and its
  footprint holds a cell that is neither swept nor a known obstacle;
- the distance of every open configuration to the nearest goal (moves of one
  cell, 4-neighbour breadth-first search from all goals at once);
- the robot moves forward when the configuration ahead is nearer than every
  other neighbour, else turns towards the nearest neighbour (left on a
  reversal); ties favour the current heading, then left, right, back;
- no goal connected to the robot: it has swept what it can reach, and turns
  left (the environment ends the episode on full coverage).

Travel on Sweeper-v1's held-out episodes: docs/experiments/Sweeper-v1.md.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from motiongym.baselines.policy import ScriptedPolicy
from motiongym.baselines.sweeper.belief import OBSTACLE, RobotMap
from motiongym.baselines.sweeper.psa_cwa import FORWARD, LEFT, robot_geometry, turn_towards
from motiongym.envs.sweeper.occupancy import DC, DR

FAR = np.iinfo(np.int32).max


def footprint_any(cells: np.ndarray, w: int) -> np.ndarray:
    """``(H - w + 1, W - w + 1)``: whether the ``w x w`` block at each top-left cell holds a
    true cell of ``cells`` (``(H, W)`` bool)."""
    h, v = cells.shape[0] - w + 1, cells.shape[1] - w + 1
    out = np.zeros((max(h, 0), max(v, 0)), bool)
    for i in range(w):
        for j in range(w):
            out |= cells[i : i + h, j : j + v]
    return out


def goal_distance(open_: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Moves from every open configuration to the nearest goal (:data:`FAR`: none
    reachable), by breadth-first search over 4-neighbours from all goals at once."""
    dist = np.full(open_.shape, FAR, np.int32)
    frontier = goal & open_
    d = 0
    while frontier.any():
        dist[frontier] = d
        grown = np.zeros_like(frontier)
        grown[1:] |= frontier[:-1]
        grown[:-1] |= frontier[1:]
        grown[:, 1:] |= frontier[:, :-1]
        grown[:, :-1] |= frontier[:, 1:]
        frontier = grown & open_ & (dist == FAR)
        d += 1
    return dist


class NearestUnsweptPolicy(ScriptedPolicy):
    """Greedy coverage: a shortest path to the nearest footprint with unswept floor."""

    def __init__(self, observation_space, action_space, env_kwargs=None) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        self.w, self.R = robot_geometry(observation_space, self.env_kwargs)

    def new_memory(self) -> RobotMap:
        return RobotMap(self.w, self.R)

    def act(self, observation: Any, memory: RobotMap) -> int:
        r, c, h, _ = memory.integrate(observation)
        r0, c0, occ, swept = memory.window()
        w = self.w
        obstacle = occ == OBSTACLE
        open_ = ~footprint_any(obstacle, w)
        goal = open_ & footprint_any(~swept & ~obstacle, w)
        dist = goal_distance(open_, goal)
        best, action = FAR, LEFT
        for k in (0, 1, 3, 2):  # ahead, left, right, back: ties favour the first
            heading = (h + k) % 4
            i, j = r - r0 + DR[heading], c - c0 + DC[heading]
            if 0 <= i < dist.shape[0] and 0 <= j < dist.shape[1] and dist[i, j] < best:
                best = dist[i, j]
                action = FORWARD if k == 0 else turn_towards(h, heading)
        return int(action)
