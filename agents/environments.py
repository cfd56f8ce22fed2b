"""Making environments by ID with clear errors for unknown IDs and keywords."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from motiongym.agents.errors import UsageError
from motiongym.envs import ENV_IDS
from motiongym.envs.core import ArgumentError


def check_env_id(env_id: str) -> str:
    """Return ``env_id`` if Gymnasium knows it, else raise with the valid IDs."""
    if env_id not in gym.registry:
        raise UsageError(f"unknown environment ID {env_id!r}; valid IDs: {', '.join(ENV_IDS)}")
    return env_id


def resolved_env_kwargs(env_id: str, env_kwargs: dict[str, Any] | None) -> dict[str, Any]:
    """The registered keyword defaults of ``env_id`` updated with the user's."""
    return {**gym.spec(check_env_id(env_id)).kwargs, **(env_kwargs or {})}


def make_env(env_id: str, env_kwargs: dict[str, Any] | None = None, **make_kwargs: Any) -> gym.Env:
    """``gym.make`` with the problem named when an ID or keyword is wrong."""
    check_env_id(env_id)
    try:
        return gym.make(env_id, **(env_kwargs or {}), **make_kwargs)
    except (TypeError, ArgumentError) as error:
        raise UsageError(f"bad keyword for {env_id}: {error}") from error


def importable_id(env_id: str) -> str:
    """``motiongym:motiongym/X-v0``: the form that imports motiongym before making.

    A spawned subprocess (SubprocVecEnv) starts without motiongym imported,
    so the IDs are not registered there; this form registers them first.
    """
    return f"motiongym:{env_id}" if env_id in ENV_IDS else env_id


def short_name(env_id: str) -> str:
    """``motiongym/Sweeper-v0`` -> ``Sweeper-v0`` (file and folder names)."""
    return env_id.split("/")[-1]
