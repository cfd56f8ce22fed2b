"""A learner-side view of the dual-arm cell's step table: robot 2's choices from now.

The dual-arm observation holds both tasks (54 numbers) and the current state;
the minimum start delay is a function of the tasks that a network fed them
did not learn (docs/experiments/DualArmCell-v1.md). Planners
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

``yielding: either`` (for a learner taught by ``either-waits``, where either
robot may be the one that waits) shows both orders: after the progress, each
robot's remaining samples as a fraction of the horizon (2 entries), then for
robot 2 yielding and then for robot 1 yielding, that order's smallest
collision-free wait as a fraction of the horizon and the steps until both arms
would be done after it as a fraction of twice the horizon (both 1 where no
wait is free; clipped at 1), followed by its lag map rows; last, how many
steps sooner robot 2's yielding is done than robot 1's, squashed at
``bin_steps`` (``0.5 + tanh(d / bin_steps) / 2``: 0.5 on a tie, above it where
robot 2 should wait; ``sooner: false`` leaves it out). The two finishing
times differ by a few steps in a thousand-number view; the squashed
difference shows which is sooner (docs/experiments/DualArmCell-v1.md measures
the learner without it).
Which order to take is left to the learner. The default ``yielding:
robot_2`` is the view above, unchanged.

The table is built once per task pair (per order), when an
observation's tasks differ from the last ones seen.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.agents.learners.memory import MemoryWrapper
from motiongym.baselines.dual_arm.lag_map import LagMap
from motiongym.envs.core import ArgumentError, check_bool, check_choice, check_int, check_keys
from motiongym.envs.dual_arm.collision import CHECKS
from motiongym.envs.dual_arm.task import LAYOUT, tasks_from_observation

TASKS = slice(LAYOUT["task1"].start, LAYOUT["task2"].stop)
YIELDING = ("robot_2", "either")


def check_dual_arm_map_kwargs(kwargs: dict[str, Any]) -> dict[str, Any]:
    """``lags`` (distinct steps, 0 first), ``bin_steps``, ``bins``, ``first_hit`` (each
    row's first-collision entry shown; False only for its ablation) and ``yielding``
    (``robot_2`` or ``either``: whose waits are shown) and ``sooner`` (with ``either``, the
    squashed difference shown; False only for its ablation) checked, defaults filled in; an
    unknown key or a bad value is an ``ArgumentError``."""
    settings: dict[str, Any] = {
        "lags": [0, 1, 2, 4, 8, 16, 32, 64],
        "bin_steps": 8,
        "bins": 64,
        "first_hit": True,
        "yielding": "robot_2",
        "sooner": True,
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
    check_bool("memory_kwargs.sooner", settings["sooner"])
    if settings["yielding"] not in YIELDING:
        raise ArgumentError(
            f"memory_kwargs.yielding must be one of {list(YIELDING)}, got {settings['yielding']!r}"
        )
    settings["lags"] = list(lags)
    return settings


class DualArmMapMemory:
    """One task pair's lag map, shown for the current state (module docstring).

    Args:
        margin: the environment's ``safety_margin`` (m).
        check: the environment's ``collision_check`` (``"swept"``, v1, or ``"samples"``, v0).
        lags, bin_steps, bins, first_hit, yielding, sooner: the view
            (:func:`check_dual_arm_map_kwargs`).
    """

    def __init__(self, margin: float, check: str, **kwargs: Any) -> None:
        settings = check_dual_arm_map_kwargs(kwargs)
        self.margin, self.check = float(margin), check_choice("check", check, CHECKS)
        self.lags, self.bin_steps = settings["lags"], settings["bin_steps"]
        self.bins, self.first_hit = settings["bins"], settings["first_hit"]
        self.either = settings["yielding"] == "either"
        self.sooner = self.either and settings["sooner"]
        rows = len(self.lags) * (self.bins + int(self.first_hit))
        self.size = 2 + (2 + 2 * (2 + rows) + int(self.sooner) if self.either else rows)
        self.tasks: np.ndarray | None = None
        self.maps: tuple[LagMap, ...] = ()

    @classmethod
    def for_env(cls, env: gym.Env, **kwargs: Any) -> DualArmMapMemory:
        """The memory for a dual-arm environment (its margin and check)."""
        params: Any = getattr(env.unwrapped, "params", None)
        if env.observation_space.shape != (LAYOUT.size,) or not hasattr(params, "collision_check"):
            raise ValueError(f"the dual_arm_map memory needs a dual-arm environment, got {env}")
        return cls(params.safety_margin, params.collision_check, **kwargs)

    def space(self, observation_space: spaces.Space) -> spaces.Box:
        """What the learner sees: progress (2) and the lag map (flattened)."""
        return spaces.Box(0.0, 1.0, (self.size,), np.float32)

    def reset(self) -> None:
        """Forget the task pair."""
        self.tasks, self.maps = None, ()

    def observe(self, observation: np.ndarray) -> np.ndarray:
        """The learner's view of ``observation`` (its task pair's table built if new)."""
        obs = np.asarray(observation, dtype=float)
        tasks = obs[TASKS]
        if not self.maps or self.tasks is None or not np.array_equal(tasks, self.tasks):
            traj1, traj2 = tasks_from_observation(obs)
            orders = ((traj1, traj2), (traj2, traj1)) if self.either else ((traj1, traj2),)
            self.maps = tuple(LagMap(a, b, self.margin, self.check) for a, b in orders)
            self.tasks = tasks
        horizon = self.bins * self.bin_steps
        parts: list[Any] = [obs[LAYOUT["progress"]]]
        states = [lag_map.state(obs) for lag_map in self.maps]
        if self.either:  # each robot's remaining samples (the first order: robot 1 runs)
            (x, p2), lag_map = states[0], self.maps[0]
            parts.append(np.array([lag_map.n1 - x, lag_map.n2 - p2]) / horizon)
        finish = []
        for lag_map, (x, p2) in zip(self.maps, states, strict=True):
            if self.either:  # the smallest wait, and when both would be done after it
                found = lag_map.finish(x, p2)
                if found is None:  # no free wait: shown as the longest, ends after any other
                    finish.append(4 * horizon)
                    parts.append([1.0, 1.0])
                else:
                    finish.append(found[1])
                    parts.append([found[0] / horizon, found[1] / (2 * horizon)])
            view = lag_map.window(x, p2, self.lags, self.bin_steps, self.bins)
            parts.append((view if self.first_hit else view[:, :-1]).ravel())
        if self.sooner:  # how much sooner robot 2's yielding is done, squashed at a bin
            parts.append([0.5 + 0.5 * np.tanh((finish[1] - finish[0]) / self.bin_steps)])
        return np.clip(np.concatenate(parts), 0.0, 1.0).astype(np.float32)


class DualArmMapWrapper(MemoryWrapper):
    """A dual-arm environment seen through the lag map
    (:mod:`motiongym.agents.learners.dual_arm`)."""

    memory_class = DualArmMapMemory
    check_kwargs = staticmethod(check_dual_arm_map_kwargs)


# Names a config may give ``memory`` -> the wrapper that adds it in training.
MEMORIES: dict[str, type[MemoryWrapper]] = {"dual_arm_map": DualArmMapWrapper}
