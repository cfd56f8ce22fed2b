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
from motiongym.baselines.sweeper.psa_cwa import robot_geometry
from motiongym.baselines.sweeper.steer import turn_towards
from motiongym.envs.sweeper.occupancy import DC, DR, bfs_distance, box_sum, config_free
from motiongym.envs.sweeper.world import FORWARD, LEFT


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
        open_ = config_free(obstacle, w)
        goal = open_ & (box_sum((~swept & ~obstacle).astype(np.int64), w) > 0)
        dist = bfs_distance(open_, goal)  # -1: no goal reachable
        best, action = np.iinfo(np.int64).max, LEFT
        for k in (0, 1, 3, 2):  # ahead, left, right, back: ties favour the first
            heading = (h + k) % 4
            i, j = r - r0 + DR[heading], c - c0 + DC[heading]
            if 0 <= i < dist.shape[0] and 0 <= j < dist.shape[1] and 0 <= dist[i, j] < best:
                best = dist[i, j]
                action = FORWARD if k == 0 else turn_towards(h, heading)
        return int(action)
