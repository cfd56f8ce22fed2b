"""A learner-side view of the dual-arm cell's step table: robot 2's choices from now.

The dual-arm observation holds both tasks (54 numbers) and the current state;
the minimum start delay is a function of the tasks that a network did not
learn from 3,000 scenes (docs/experiments/DualArmCell-v1.md). Planners
rebuild the trajectories from the tasks and check the arms' motion against
each other; this memory does the same for a learner and shows it the result
in robot 2's terms (:class:`~motiongym.baselines.dual_arm.lag_map.LagMap`):
for each lag ``w`` of ``lags``, which bins of ``bin_steps`` environment steps
of "wait ``w`` more steps, then run at full speed" collide on the
environment's own check (v0's or v1's, from the environment's keywords),
over the next ``bins * bin_steps`` steps. The decision (when to go) is left
to the learner: the map says which waits are free, not which to take.

Observation seen by the learner (Box, float32): robot 1's and robot 2's
progress (the environment's ``progress``, 2 entries), then the lag map row
by row (``len(lags) * (bins + 1)`` entries: each row's bins, 0 or 1, then
its first colliding step's distance as a fraction of the horizon, 1 for
none; ``first_hit: false`` leaves it out). The distance is the row's pooled
summary: without it a learner has to find one blocked bin among 64
(docs/experiments/DualArmCell-v0.md measures the difference).
The rest of the environment's
observation is dropped: the tasks are in the map, and a network fed the 54
raw task numbers memorises its training scenes (the measure cited above).

The table is built once per task pair (0.1-0.7 s of CPU), when an
observation's tasks differ from the last ones seen.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.baselines.dual_arm.lag_map import LagMap
from motiongym.envs.core import ArgumentError, check_bool, check_int, check_keys
from motiongym.envs.dual_arm.world import OBS, OBS_SIZE, tasks_from_observation

TASKS = slice(OBS["task1"].start, OBS["task2"].stop)


def check_dual_arm_map_kwargs(kwargs: dict[str, Any]) -> dict[str, Any]:
    """``lags`` (distinct steps, 0 first), ``bin_steps``, ``bins`` and ``first_hit`` (each
    row's first-collision entry shown; False only for its ablation) checked, defaults
    filled in; an unknown key or a bad value is an ``ArgumentError``."""
    settings: dict[str, Any] = {
        "lags": [0, 1, 2, 4, 8, 16, 32, 64],
        "bin_steps": 8,
        "bins": 64,
        "first_hit": True,
    }
    settings.update(check_keys("memory_kwargs", kwargs, settings))
    lags = settings["lags"]
    if (
        not isinstance(lags, (list, tuple))
        or not lags
        or not all(isinstance(w, int) and not isinstance(w, bool) and 0 <= w <= 1000 for w in lags)
        or lags[0] != 0
        or len(set(lags)) != len(lags)
    ):
        raise ArgumentError(
            f"memory_kwargs.lags must be distinct integer steps in [0, 1000] starting with 0, "
            f"got {lags!r}"
        )
    check_int("memory_kwargs.bin_steps", settings["bin_steps"], 1, 100)
    check_int("memory_kwargs.bins", settings["bins"], 1, 1000)
    check_bool("memory_kwargs.first_hit", settings["first_hit"])
    settings["lags"] = list(lags)
    return settings


class DualArmMapMemory:
    """One task pair's lag map, shown for the current state (module docstring).

    Args:
        margin: the environment's ``safety_margin`` (m).
        swept: v1's check (True) or v0's (False).
        lags, bin_steps, bins: the view (:func:`check_dual_arm_map_kwargs`).
    """

    def __init__(self, margin: float, swept: bool, **kwargs: Any) -> None:
        settings = check_dual_arm_map_kwargs(kwargs)
        self.margin, self.swept = float(margin), bool(swept)
        self.lags, self.bin_steps = settings["lags"], settings["bin_steps"]
        self.bins, self.first_hit = settings["bins"], settings["first_hit"]
        self.size = 2 + len(self.lags) * (self.bins + int(self.first_hit))
        self.tasks: np.ndarray | None = None
        self.map: LagMap | None = None

    @classmethod
    def for_env(cls, env: gym.Env, **kwargs: Any) -> DualArmMapMemory:
        """The memory for a dual-arm environment (its margin and check)."""
        params = getattr(env.unwrapped, "params", None)
        if env.observation_space.shape != (OBS_SIZE,) or not hasattr(params, "collision_check"):
            raise ValueError(f"the dual_arm_map memory needs a dual-arm environment, got {env}")
        return cls(params.safety_margin, params.collision_check == "swept", **kwargs)

    def space(self, observation_space: spaces.Space) -> spaces.Box:
        """What the learner sees: progress (2) and the lag map (flattened)."""
        return spaces.Box(0.0, 1.0, (self.size,), np.float32)

    def reset(self) -> None:
        """Forget the task pair."""
        self.tasks, self.map = None, None

    def observe(self, observation: np.ndarray) -> np.ndarray:
        """The learner's view of ``observation`` (its task pair's table built if new)."""
        obs = np.asarray(observation, dtype=float)
        tasks = obs[TASKS]
        if self.map is None or not np.array_equal(tasks, self.tasks):
            traj1, traj2 = tasks_from_observation(obs)
            self.map, self.tasks = LagMap(traj1, traj2, self.margin, self.swept), tasks
        x, p2 = self.map.state(obs)
        view = self.map.window(x, p2, self.lags, self.bin_steps, self.bins)
        if not self.first_hit:
            view = view[:, :-1]
        progress = obs[OBS["progress"]].astype(np.float32)
        return np.concatenate([progress, view.ravel()]).astype(np.float32)
