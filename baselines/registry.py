"""Which scripted policies exist for which environment IDs.

Each system's baselines module declares ``POLICIES``: a mapping from
environment ID to ``{policy name: "module:Class"}`` (the systems are listed
in :mod:`motiongym.systems`). Classes are imported only when a policy is
made.
"""

from __future__ import annotations

import importlib
from typing import Any

import gymnasium as gym

from motiongym.baselines.policy import ScriptedPolicy
from motiongym.systems import declared


class UnknownPolicyError(ValueError):
    """A policy name that is not declared for the environment ID."""


def scripted_policies(env_id: str) -> dict[str, str]:
    """``{name: "module:Class"}`` of the scripted policies for ``env_id``."""
    return dict(declared("baselines", "POLICIES").get(env_id, {}))


def make_policy(
    env_id: str,
    name: str,
    observation_space: gym.Space,
    action_space: gym.Space,
    env_kwargs: dict[str, Any] | None = None,
    **options: Any,
) -> ScriptedPolicy:
    """Instantiate the scripted policy ``name`` declared for ``env_id``; ``options`` go to
    its constructor (its own keywords, e.g. ``replan`` of the excavator reach teacher)."""
    declared = scripted_policies(env_id)
    if name not in declared:
        choices = ", ".join(sorted(declared)) or "none"
        raise UnknownPolicyError(
            f"unknown policy {name!r} for {env_id}; scripted policies: {choices}"
        )
    module_name, class_name = declared[name].split(":")
    cls = getattr(importlib.import_module(module_name), class_name)
    policy = cls(observation_space, action_space, env_kwargs, **options)
    policy.env_id = env_id
    return policy
