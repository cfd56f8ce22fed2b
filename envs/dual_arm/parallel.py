"""PettingZoo ``ParallelEnv`` over the dual-arm cell: each robot times its own arm.

The same world and task as the Gymnasium environment (:class:`.world.DualArmWorld`,
:class:`.task.DualArmTask`), through one :class:`~.env.DualArmCellEnv` with
``control="both"``: the step, reward, ``info`` and checks are that environment's.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from motiongym.envs.actions import checked_box_action
from motiongym.envs.core import ArgumentError, check_int
from motiongym.envs.dual_arm.env import DualArmCellEnv
from motiongym.envs.dual_arm.task import DualArmTask
from motiongym.envs.dual_arm.world import DualArmWorld

AGENTS = ("robot_1", "robot_2")


class DualArmParallelEnv(ParallelEnv):
    """Agents ``robot_1`` and ``robot_2``, each choosing its own arm's advance.

    The world, observation, reward and ``info`` are those of
    :class:`~motiongym.envs.dual_arm.env.DualArmCellEnv` (``control="both"``):
    both agents see the full observation (94,) and share the reward. Actions:
    Box(0, 1, (1,)) per agent. All agents terminate together (both arms done
    or a collision); truncated together after ``max_steps`` steps (no
    ``TimeLimit`` wrapper in PettingZoo; an integer in [1, 10**6]). Each
    agent's action is checked as the Gymnasium environment checks its own
    (shape (1,), finite, clipped to [0, 1]); an action for a name that is not
    an agent is an error naming it, as is a space asked for such a name. Reset
    options must be a dict; keys other than the task's (``pairs``, and ``task``,
    its deprecated name) are ignored (PettingZoo's API
    test passes arbitrary ones). Other keywords go to the Gymnasium environment
    (``pairs``, ``safety_margin``, reward weights, ``collision_check``,
    ``render_mode``, ``render_size``).
    """

    metadata = {
        "name": "dual_arm_cell_v0",
        "render_modes": ["rgb_array", "human"],
        "is_parallelizable": True,
    }

    def __init__(self, max_steps: int = 1000, **kwargs: Any) -> None:
        if "control" in kwargs:
            raise ArgumentError("control is fixed to 'both' in the parallel environment")
        self.max_steps = check_int("max_steps", max_steps, 1, 10**6)
        self._env = DualArmCellEnv(control="both", **kwargs)
        self.possible_agents = list(AGENTS)
        self.agents: list[str] = []
        self.render_mode = self._env.render_mode
        self._steps = 0
        self._action_space = spaces.Box(0.0, 1.0, (1,), np.float32)
        task = self._env.task
        self._options = set(task.options) | set(task.deprecated_options)

    @property
    def world(self) -> DualArmWorld:
        """The world both agents move (the Gymnasium environment's)."""
        return self._env.world

    @property
    def task(self) -> DualArmTask:
        """The task that scores and observes it (the Gymnasium environment's)."""
        return self._env.task

    def _check_agent(self, agent: Any) -> None:
        if agent not in AGENTS:
            raise ArgumentError(f"agent must be one of {list(AGENTS)}, got {agent!r}")

    def observation_space(self, agent: str) -> spaces.Space:
        self._check_agent(agent)
        return self._env.observation_space

    def action_space(self, agent: str) -> spaces.Box:
        self._check_agent(agent)
        return self._action_space

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, dict]]:
        if options is not None and not isinstance(options, dict):
            raise ArgumentError(f"options must be a dict or None, got {options!r:.80}")
        # PettingZoo's API test resets with arbitrary options: pass on only ours.
        ours = {k: v for k, v in (options or {}).items() if k in self._options}
        obs, info = self._env.reset(seed=seed, options=ours)
        self.agents = list(AGENTS)
        self._steps = 0
        return {a: obs.copy() for a in self.agents}, {a: dict(info) for a in self.agents}

    def step(self, actions: dict[str, Any]):
        if not self.agents:
            raise RuntimeError("no episode under way: call reset() before step()")
        if not isinstance(actions, dict):
            raise ArgumentError(f"actions must be a dict {{agent: action}}, got {actions!r}")
        missing = set(self.agents) - set(actions)
        if missing:
            raise ArgumentError(f"missing actions for {sorted(missing)}; agents: {self.agents}")
        unknown = [name for name in actions if name not in AGENTS]
        if unknown:
            raise ArgumentError(f"actions for unknown agent(s) {unknown}; agents: {AGENTS}")
        a = [checked_box_action(actions[n], (1,), f"the advance of {n}'s arm") for n in AGENTS]
        obs, reward, terminated, _, info = self._env.step(np.concatenate(a))
        self._steps += 1
        truncated = not terminated and self._steps >= self.max_steps
        agents = self.agents
        out = (
            {n: obs.copy() for n in agents},
            {n: reward for n in agents},
            {n: terminated for n in agents},
            {n: truncated for n in agents},
            {n: dict(info) for n in agents},
        )
        if terminated or truncated:
            self.agents = []
        return out

    def render(self) -> np.ndarray | None:
        return self._env.render()

    def close(self) -> None:
        self._env.close()

    @property
    def state_space(self) -> spaces.Space:
        """The global state: the single-agent environment's observation (both arms)."""
        return self._env.observation_space

    def state(self) -> np.ndarray:
        return self.task.observe(self.world)
