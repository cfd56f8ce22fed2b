"""The scripted-policy interface: Stable-Baselines3's predictor protocol.

A scripted policy is interchangeable with a learned SB3 model: it offers
``predict(observation, state=None, episode_start=None, deterministic=True)``
and returns ``(action, state)``. It acts from the observation alone; whatever
it must remember within an episode (a plan, a map, a stack) lives in a
per-episode *memory* object that it creates with :meth:`new_memory` and that
is replaced whenever ``episode_start`` is true.

Observations may come one at a time (a plain ``gym.Env``) or batched with a
leading ``n_envs`` axis (a ``VecEnv`` or Gymnasium vector env, as in SB3's
``evaluate_policy``); the policy then keeps one memory per sub-environment.
Batching is recognised by comparing the observation's shape with the
observation space.

Without ``episode_start`` (a hand-written loop), memory persists from call to
call: pass ``episode_start=True`` on an episode's first step or call
:meth:`reset` after ``env.reset``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, cast

import numpy as np
from gymnasium import spaces

Shape = tuple[int, ...]  # a space's shape (None only for spaces without one)


class ScriptedPolicy(ABC):
    """Base class of every scripted reference policy.

    Args:
        observation_space: the environment's (single) observation space.
        action_space: the environment's (single) action space.
        env_kwargs: the keyword arguments the environment was made with
            (its registered defaults merged with the user's), so that a policy
            can rebuild the same static model (an arm's link table, the
            robot's width) as the environment; never the environment itself.
    """

    env_id: str | None = None  # the ID it was declared for (set by ``make_policy``)

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        env_kwargs: dict[str, Any] | None = None,
    ) -> None:
        self.observation_space = observation_space
        self.action_space = action_space
        self.env_kwargs = dict(env_kwargs or {})
        self._memories: list[Any] = []

    @abstractmethod
    def new_memory(self) -> Any:
        """A fresh per-episode memory (None if the policy is memoryless)."""

    @abstractmethod
    def act(self, observation: Any, memory: Any) -> Any:
        """The action for one unbatched observation; may update ``memory``."""

    def reset(self) -> None:
        """Forget every episode in progress."""
        self._memories = []

    def diagnostics(self, index: int = 0) -> dict[str, Any]:
        """What the policy knows of its episode in progress (sub-environment ``index``).

        The public view that evaluations and reproductions read (a plan's
        delay, whether the policy has declared itself done, ...), so that
        none of them reads private memory. Empty where a policy has nothing to
        report; each policy documents its keys.
        """
        if not self._memories:
            return {}
        return self.describe(self._memories[index])

    def describe(self, memory: Any) -> dict[str, Any]:
        """``diagnostics()`` of one memory; override to report (default: nothing)."""
        return {}

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: np.ndarray | bool | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """SB3's predictor interface; ``state`` is passed through untouched."""
        batched = self._is_batched(observation)
        observations = _unbatch(observation) if batched else [observation]
        starts = np.zeros(len(observations), dtype=bool)
        if episode_start is not None:
            starts |= np.asarray(episode_start, dtype=bool).reshape(-1)
        if len(self._memories) != len(observations):
            self._memories = [self.new_memory() for _ in observations]
            starts[:] = False
        actions = []
        for i, obs in enumerate(observations):
            if starts[i]:
                self._memories[i] = self.new_memory()
            actions.append(self.act(obs, self._memories[i]))
        if batched:
            return np.stack([np.asarray(a) for a in actions]), state
        return np.asarray(actions[0]), state

    def _is_batched(self, observation: Any) -> bool:
        space = self.observation_space
        if isinstance(space, spaces.Dict):
            key = next(iter(space.spaces))
            return np.ndim(observation[key]) > len(cast(Shape, space.spaces[key].shape))
        return np.ndim(observation) > len(cast(Shape, space.shape))


def _unbatch(observation: Any) -> list[Any]:
    if isinstance(observation, dict):
        keys = list(observation)
        n = len(observation[keys[0]])
        return [{k: observation[k][i] for k in keys} for i in range(n)]
    return list(observation)
