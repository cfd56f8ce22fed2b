"""``motiongym/DualArmCell-v0``/``-v1``: two PUMA-560 arms sharing a cell (Gymnasium).

A :class:`motiongym.envs.core.SystemEnv`: the world is
:class:`.world.DualArmWorld` (the arms, MuJoCo, the collision check of
:mod:`.collision`), the task :class:`.task.DualArmTask` (pairs, reward,
observation :data:`.task.LAYOUT`), the parameters :mod:`.params`.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from motiongym.envs.actions import checked_box_action
from motiongym.envs.core import SystemEnv
from motiongym.envs.dual_arm.params import CONTROLS, DualArmParams
from motiongym.envs.dual_arm.task import DT, LAYOUT, DualArmTask
from motiongym.envs.dual_arm.world import DualArmWorld

_FLOAT32 = np.dtype(np.float32)


class DualArmCellEnv(SystemEnv):
    """Two PUMA-560 arms, each on a fixed pick-and-place trajectory; avoid collisions
    by timing alone (Chang, Chung & Lee: time delay by boundary following).

    Each arm follows a joint trajectory planned without regard to the other
    (vias and a quintic time law, sampled at 20 ms). The agent never changes a
    path: each step (20 ms) it chooses how far each arm advances along its own
    trajectory, 0 (wait) to 1 (one sample, nominal speed). The paper's answer
    is to start robot 2 late by the smallest delay that avoids collision.

    ## Action
    ``control="both"``: Box(0, 1, (2,)) float32; ``control="robot_2"`` (the
    paper's setting, robot 1 on its nominal schedule): Box(0, 1, (1,)).

    =====  =========================================  ===============
    index  meaning                                    unit
    =====  =========================================  ===============
    0      robot 1 advance ("both" only)              samples / step
    0 / 1  robot 2 advance                            samples / step
    =====  =========================================  ===============

    Values are clipped into [0, 1] (never faster, never backwards); NaN or a
    wrong shape raises ``ValueError``; ``step()`` before ``reset()``:
    ``RuntimeError``. Between samples the joints are interpolated linearly.

    ## Observation
    Box (94,) float32, the fields of :data:`motiongym.envs.dual_arm.task.LAYOUT`
    (``LAYOUT["progress"]`` is their slice, ``LAYOUT.parse`` reads them):

    OBSERVATION_TABLE

    The bodies of ``distances``, in order: upper arm, forearm, wrist roll,
    wrist bend, gripper. Each task field is the arm's 4 x 6 via configurations (rad, its own
    joints) then its 3 segment durations (s). From the tasks (40-93) a planner
    rebuilds both trajectories (``task.tasks_from_observation``) and the
    collision map.

    ## Reward
    Sum of named terms, each in ``info`` as ``reward_<term>``, weighted by the
    keyword argument of the same name:

    * ``time``: ``-time * 0.02`` per step (s of makespan; every step counts,
      since the episode ends when both arms are done);
    * ``collision``: ``-collision`` on the step that collides;
    * ``clearance``: ``-clearance * max(0, 1 - d / clearance_distance)``,
      ``d = d(R1, R2)``;
    * ``advance``: ``advance * (dp_1 / N_1 + dp_2 / N_2)``, the step's progress
      of both arms as fractions of their paths (``2 * advance`` over a
      completed task), 0 in the registered ID: a potential-based shaping for
      training (configs), since ``time`` alone ranks waiting out the 20 s
      (-20) near finishing (-8 to -12) for a learner that has not yet found
      how to finish.

    ## Episode
    Terminated when both arms are done (success) or on collision
    (``d(R1, R2) <= safety_margin``, paper eq. 2). Truncation is left to
    ``TimeLimit`` (``max_episode_steps=1000``, 20 s).

    ## Info
    ``is_success`` (both done, no collision), ``cost`` (1.0 on a colliding
    step), ``collision``, ``distance`` (``d(R1, R2)``, m), ``makespan`` (s
    elapsed so far; the makespan when done), ``progress_1``/``progress_2``
    (samples), ``robot_2_wait`` (s robot 2 spent not advancing before it was
    done), and the reward terms.

    ## Arguments
    Keywords (:mod:`motiongym.envs.dual_arm.params`, checked at construction):
    ``control`` ("both" | "robot_2"), ``pairs`` ("colliding": pairs that
    collide if started together and are collision free one after the other;
    "any"; "paper": the fixed paper case; ``task`` is its deprecated name),
    ``safety_margin`` (m), ``clearance_distance`` (m), reward weights ``time``,
    ``collision``, ``clearance``, ``advance`` (magnitudes in [0, 1e6]: the
    first three are costs, subtracted; ``advance`` is paid), ``render_mode``
    ("rgb_array", or "human"), ``render_size`` (rows, columns of a frame,
    each in [16, 2048]; default (480, 640)). ``reset(options={"pairs": ...})``
    overrides the pairs mode (``"task"`` its deprecated name). The arms'
    start poses are the sampled tasks' first vias: there is no ``start``
    option.

    ``collision_check``: "samples" (v0: ``d(R1, R2)`` at the end of each step
    only) or "swept" (v1: the whole motion of the step, both arms moving at
    once, is checked with the certified bound of :mod:`.motion`; a step is a
    collision when any instant of it comes within ``safety_margin``, up to
    1 mm of resolution, never missed).

    ## Version history

    * v1: ``collision_check="swept"``: collisions between control samples
      count (an undelayed pair that grazed between two 20 ms samples passed
      v0's check); a "colliding" pair also runs one after the other without
      contact in motion (:func:`.task.sequential_clear_in_motion`), so a
      start delay always exists on v1's check.
    * v0: first version (collision checked at the control samples only). Its
      minimum pure delay can collide between samples: on v0's own pairs of
      2,000 held-out seeds, v1's check rejects it on 15 % and the arms
      physically interpenetrate between two samples on 7 % (up to 7 mm
      deep), which v0 counts a success. Prefer v1.
    """

    dt = DT  # s, the control period (the paper's 20 ms sample time)
    Params: ClassVar[type] = DualArmParams
    params: DualArmParams
    world: DualArmWorld
    task: DualArmTask
    metadata = {
        "render_modes": ["rgb_array", "human"],
        "render_fps": int(1 / DT),
        "info_measures": {
            "is_success": "last",
            "cost": "sum",
            "collision": "max",
            "distance": "min",
            "makespan": "last",
            "robot_2_wait": "last",
        },
        "info_units": {
            "is_success": "rate",
            "cost": "steps",
            "collision": "rate",
            "distance": "m",
            "makespan": "s",
            "robot_2_wait": "s",
        },
    }

    def make_world(self, params: DualArmParams) -> DualArmWorld:
        return DualArmWorld(params.control, params.collision_check, params.safety_margin)

    def make_task(self, params: DualArmParams) -> DualArmTask:
        return DualArmTask(params)

    def check_action(self, action: Any) -> list[float]:
        """The action as finite floats of the space's shape (clipped by the world), else a
        ``ValueError`` naming the space."""
        if type(action) is np.ndarray and action.dtype == _FLOAT32:  # the space's own type
            values = action.tolist()
            if action.shape == self.action_space.shape and math.isfinite(sum(values)):
                return values
        meaning = f"advance per arm, control={self.params.control!r}"
        return checked_box_action(action, self.action_space.shape or (), meaning).tolist()


DualArmCellEnv.__doc__ = (DualArmCellEnv.__doc__ or "").replace(
    "OBSERVATION_TABLE", LAYOUT.table().replace("\n", "\n    ")
)

__all__ = ["CONTROLS", "DualArmCellEnv"]
