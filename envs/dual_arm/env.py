"""``motiongym/DualArmCell-v0``: two PUMA-560 arms sharing a cell (Gymnasium)."""

from __future__ import annotations

from functools import partial
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.envs.actions import checked_box_action
from motiongym.envs.core import NeedsReset, check_choice, check_options, check_render_mode
from motiongym.envs.dual_arm import motion
from motiongym.envs.dual_arm import task as task_module
from motiongym.envs.dual_arm.params import CONTROLS, WEIGHTS, DualArmParams
from motiongym.envs.dual_arm.task import DT, TASK_MODES
from motiongym.envs.dual_arm.world import OBS, DualArmWorld, observation_bounds
from motiongym.envs.rendering import Renders


class DualArmCellEnv(NeedsReset, Renders, gym.Env):
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
    wrong shape raises ``ValueError``. Between samples the joints are
    interpolated linearly.

    ## Observation
    Box (94,) float32 (slices by name in ``world.OBS``):

    ======  ==========================================  =====  ===============
    index   meaning                                      unit   frame
    ======  ==========================================  =====  ===============
    0-5     robot 1 joint angles q1..q6                  rad    robot 1 joints
    6-11    robot 2 joint angles q1..q6                  rad    robot 2 joints
    12-13   progress p_r / N_r of robot 1, robot 2       -      -
    14      elapsed time (steps x 0.02)                  s      -
    15-39   d_ij (paper eq. 1), row i = robot-1 body,    m      -
            col j = robot-2 body; bodies: upper arm,
            forearm, wrist roll, wrist bend, gripper
    40-63   robot 1 via configurations (4 x 6)           rad    robot 1 joints
    64-66   robot 1 segment durations (3)                s      -
    67-90   robot 2 via configurations (4 x 6)           rad    robot 2 joints
    91-93   robot 2 segment durations (3)                s      -
    ======  ==========================================  =====  ===============

    From the tasks (40-93) a planner rebuilds both trajectories
    (``world.tasks_from_observation``) and the collision map.

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
    ``control`` ("both" | "robot_2"), ``task`` ("colliding": pairs that collide
    if started together and are collision free one after the other; "any";
    "paper": the fixed paper case), ``safety_margin`` (m), ``clearance_distance``
    (m), reward weights ``time``, ``collision``, ``clearance``, ``advance``, ``render_mode``
    ("rgb_array"). ``reset(options={"task": ...})`` overrides the task mode.

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
    * v0: first version (collision checked at the control samples only).
    """

    dt = DT  # s, the control period (the paper's 20 ms sample time)
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

    def __init__(
        self,
        control: str = "both",
        task: str = "colliding",
        safety_margin: float = 0.0,  # m
        clearance_distance: float = 0.05,  # m
        time: float = 1.0,
        collision: float = 10.0,
        clearance: float = 0.1,
        advance: float = 0.0,
        render_mode: str | None = None,
        collision_check: str = "samples",
    ) -> None:
        self.params = p = DualArmParams(
            control,
            task,
            safety_margin,
            clearance_distance,
            time,
            collision,
            clearance,
            advance,
            collision_check,
        )
        self.render_mode = check_render_mode(render_mode, self.metadata["render_modes"])
        self.control, self.task, self.collision_check = p.control, p.task, p.collision_check
        self.safety_margin = p.safety_margin
        self.clearance_distance = p.clearance_distance
        self.weights = {name: getattr(p, name) for name in WEIGHTS}
        n_act = 2 if control == "both" else 1
        self.action_space: spaces.Box = spaces.Box(0.0, 1.0, (n_act,), np.float32)
        lo, hi = observation_bounds()
        self.observation_space: spaces.Box = spaces.Box(lo, hi, dtype=np.float32)
        self.world = DualArmWorld()

    # ------------------------------------------------------------------ API

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        options = check_options(options, {"task": partial(check_choice, choices=TASK_MODES)})
        mode = options.get("task", self.task)
        swept = self.collision_check == "swept"
        pair = task_module.sample_pair(self.np_random, mode, self.safety_margin, in_motion=swept)
        self.world.load(*pair)
        self._wait2 = 0.0
        info = self._info(collided=False, terms={k: 0.0 for k in self.weights})
        self._was_reset = True
        self._show_if_human()
        return self.world.observation(), info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        self._require_reset("step")
        a1, a2 = self._parse(action)
        w = self.world
        if w.p2 < w.n2:  # robot 2 not done before this step
            self._wait2 += (1.0 - a2) * DT
        done_before = w.p1 / w.n1 + w.p2 / w.n2
        before = (w.p1, w.p2, w.distances)
        w.advance(a1, a2)
        d = w.distance
        collided = d <= self.safety_margin or (
            self.collision_check == "swept" and self._collides_between(*before)
        )
        weights = self.weights
        terms = {
            "time": -weights["time"] * DT,
            "collision": -weights["collision"] if collided else 0.0,
            "clearance": -weights["clearance"] * max(0.0, 1.0 - d / self.clearance_distance),
            "advance": weights["advance"] * (w.p1 / w.n1 + w.p2 / w.n2 - done_before),
        }
        reward = sum(terms.values())
        terminated = collided or (w.p1 >= w.n1 and w.p2 >= w.n2)
        self._show_if_human()
        return w.observation(), float(reward), terminated, False, self._info(collided, terms)

    def _frame(self) -> np.ndarray:
        return self.world.render()

    def close(self) -> None:
        super().close()
        self.world.close()

    # ------------------------------------------------------------------ helpers

    def _collides_between(self, p1: float, p2: float, d_start: np.ndarray) -> bool:
        """Whether the step's motion (both arms at once) comes within the margin.

        A cheap certificate first: every configuration of the step lies within
        half the step's motion bound of one of its two ends (:mod:`.motion`);
        only a step that this cannot clear is checked by halving.
        """
        w, margin = self.world, self.safety_margin
        samples1, samples2 = w.samples
        m1 = motion.body_motion(motion.span_variation(w.slopes[0], p1, w.p1))
        m2 = motion.body_motion(motion.span_variation(w.slopes[1], p2, w.p2))
        slack = m1[:, None] / 2 + m2[None, :] / 2
        if min((d_start - slack).min(), (w.distances - slack).min()) > margin:
            return False
        return motion.simultaneous_collide(samples1, (p1, w.p1), samples2, (p2, w.p2), margin)

    def _parse(self, action: Any) -> tuple[float, float]:
        a = checked_box_action(
            action, self.action_space.shape, f"advance per arm, control={self.control!r}"
        )
        values = [min(max(v, 0.0), 1.0) for v in a.tolist()]
        if self.control == "both":
            return values[0], values[1]
        return 1.0, values[0]

    def _info(self, collided: bool, terms: dict[str, float]) -> dict[str, Any]:
        w = self.world
        info = {
            "is_success": not collided and w.p1 >= w.n1 and w.p2 >= w.n2,
            "cost": 1.0 if collided else 0.0,
            "collision": collided,
            "distance": w.distance,
            "makespan": w.steps * DT,
            "progress_1": w.p1,
            "progress_2": w.p2,
            "robot_2_wait": self._wait2,
        }
        for k, v in terms.items():
            info[f"reward_{k}"] = float(v)
        return info


OPTIONS = ("task",)  # reset options

__all__ = ["CONTROLS", "OBS", "OPTIONS", "DualArmCellEnv"]
