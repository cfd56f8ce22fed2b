"""Scripted policies on the goal-conditioned variants (:mod:`motiongym.envs.goal`).

A goal ID's observation is a ``Dict`` whose ``observation`` lacks the goal
fields; :class:`GoalPolicy` rebuilds the base observation
(:meth:`GoalFields.join`: the target from ``desired_goal``, the target error
from both goals) and hands it to the base ID's policy, built from the base
ID's keyword arguments. So scripted and learned agents compare on the same
goal ID, on the same scenes (the base env's, from the same seed).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces

from motiongym.baselines.policy import ScriptedPolicy
from motiongym.envs.goal import resolve


class GoalPolicy(ScriptedPolicy):
    """The scripted policy ``INNER`` of a base ID, acting on its goal variant."""

    INNER: type[ScriptedPolicy]

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        env_kwargs: dict[str, Any] | None = None,
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        if not isinstance(observation_space, spaces.Dict) or "desired_goal" not in (
            observation_space.spaces
        ):
            raise ValueError(
                f"observation_space must be a goal Dict (observation, achieved_goal, "
                f"desired_goal), got {observation_space}"
            )
        self.base_id, base_kwargs, self.fields = resolve(self.env_kwargs)
        flat = spaces.Box(-np.inf, np.inf, (self.fields.base_size,), np.float32)
        self.inner = self.INNER(flat, action_space, base_kwargs)

    def new_memory(self) -> Any:
        return self.inner.new_memory()

    def act(self, observation: Any, memory: Any) -> Any:
        return self.inner.act(self.fields.join(observation), memory)

    def describe(self, memory: Any) -> dict[str, Any]:
        return self.inner.describe(memory)


def for_goal_env(inner: type[ScriptedPolicy], module: str) -> type[GoalPolicy]:
    """A :class:`GoalPolicy` subclass named ``Goal<inner>`` in ``module`` (picklable there)."""
    name = f"Goal{inner.__name__}"
    doc = f"{inner.__name__} on a goal-conditioned ID (:class:`GoalPolicy`)."
    return type(name, (GoalPolicy,), {"INNER": inner, "__module__": module, "__doc__": doc})
