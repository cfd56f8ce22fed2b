"""Learner-side memories: what a wrapper adds to an environment's observation in training,
and the same built by a predictor in evaluation.

A memory class (a system's, declared in its learners module's ``MEMORIES``,
:func:`motiongym.agents.learners.memories`) has ``for_env(env, **kwargs)``,
``space(observation_space)`` (the observation space with the memory added),
``reset()`` and ``observe(observation)`` (the observation with the memory
added). It is a function of the episode's observations so far; it never reads
the world. :class:`MemoryWrapper` puts it in front of a training environment;
:class:`MapMemoryPredictor` in front of a trained model acting in the bare
environment, from the same observation stream, reset by ``episode_start``. A
run's ``config.yml`` names it (``memory: <name>``, ``memory_kwargs``), and
:func:`motiongym.agents.models.predictors.load_model` puts the predictor in
front of a model trained with it.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.agents.learners import memories


class MemoryWrapper(gym.ObservationWrapper):
    """An environment whose observations carry a learner-side memory (reset with it);
    subclasses name the memory class (``for_env``, ``space``, ``reset``, ``observe``) and
    its settings' check (``check_kwargs``, defaults filled in).
    ``raw_observation`` is the environment's own last observation (what a scripted
    teacher reads)."""

    memory_class: Any = None
    check_kwargs: Any = None

    def __init__(self, env: gym.Env, **memory_kwargs: Any) -> None:
        super().__init__(env)
        self.memory = self.memory_class.for_env(env, **memory_kwargs)
        self.observation_space = self.memory.space(env.observation_space)

    def reset(self, **kwargs: Any) -> tuple[Any, dict]:
        self.memory.reset()
        return super().reset(**kwargs)

    def observation(self, observation: Any) -> Any:
        self.raw_observation = observation  # the environment's own, for a DAgger teacher
        return self.memory.observe(observation)


class MapMemoryPredictor:
    """A model trained on a :class:`MemoryWrapper`'s observations, acting in the bare
    environment: it builds the same memory from the observations it is given.

    One memory per sub-environment (observations may come batched, with a
    leading axis); a sub-environment's memory is emptied where ``episode_start``
    is true (without ``episode_start`` it persists from call to call, as a
    scripted policy's does). Keywords after ``deterministic`` (the action
    masks) go to the model unchanged. ``memory``: a name of
    :func:`~motiongym.agents.learners.memories`.
    """

    def __init__(self, model: Any, env: gym.Env, memory: str = "sweeper_map", **memory_kwargs):
        self.model = model
        memory_class = memories()[memory].memory_class
        self.make = lambda: memory_class.for_env(env, **memory_kwargs)
        space = env.observation_space
        self.key: str | None = None  # a Dict observation's first entry
        first = space
        if isinstance(space, spaces.Dict):
            self.key = key = next(iter(space.spaces))
            first = space[key]
        self.rank = len(first.shape or ())
        self.memories: list[Any] = []

    def predict(self, observation, state=None, episode_start=None, deterministic=True, **kwargs):
        first = observation[self.key] if self.key else observation
        batched = np.ndim(first) > self.rank
        n = len(first) if batched else 1
        if len(self.memories) != n:
            self.memories = [self.make() for _ in range(n)]
        starts = np.zeros(n, bool)
        if episode_start is not None:
            starts |= np.asarray(episode_start, dtype=bool).reshape(-1)
        seen = []
        for i, memory in enumerate(self.memories):
            if starts[i]:
                memory.reset()
            if not batched:
                one = observation
            elif self.key:
                one = {k: v[i] for k, v in observation.items()}
            else:
                one = observation[i]
            seen.append(memory.observe(one))
        if not batched:
            observation = seen[0]
        elif self.key:
            observation = {k: np.stack([s[k] for s in seen]) for k in seen[0]}
        else:
            observation = np.stack(seen)
        return self.model.predict(observation, state, episode_start, deterministic, **kwargs)


def check_memory_kwargs(kwargs: dict[str, Any], memory: str = "sweeper_map") -> dict[str, Any]:
    """``memory``'s settings checked, defaults filled in (an ``ArgumentError`` if bad)."""
    return memories()[memory].check_kwargs(kwargs)
