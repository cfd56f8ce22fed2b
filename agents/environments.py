"""Making environments by ID with clear errors for unknown IDs and keywords."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from motiongym.agents.errors import UsageError
from motiongym.envs import ENV_IDS
from motiongym.envs.core import check_int, check_render_mode


def check_env_id(env_id: str) -> str:
    """Return ``env_id`` if Gymnasium knows it, else raise with the valid IDs."""
    if not isinstance(env_id, str) or env_id not in gym.registry:
        raise UsageError(f"unknown environment ID {env_id!r}; valid IDs: {', '.join(ENV_IDS)}")
    return env_id


def resolved_env_kwargs(env_id: str, env_kwargs: dict[str, Any] | None) -> dict[str, Any]:
    """The registered keyword defaults of ``env_id`` updated with the user's."""
    return {**gym.spec(check_env_id(env_id)).kwargs, **(env_kwargs or {})}


def check_make_kwargs(env_id: str, kwargs: dict[str, Any]) -> None:
    """Gymnasium's own keywords of ``gym.make`` checked in the environments' style:
    ``max_episode_steps`` an integer >= 1 (Gymnasium asserts), ``render_mode`` one
    of the environment's (Gymnasium warns first; "human" is left to Gymnasium,
    which may wrap an "rgb_array" environment for it)."""
    if "max_episode_steps" in kwargs:
        check_int("max_episode_steps", kwargs["max_episode_steps"], 1)
    if kwargs.get("render_mode") != "human":
        modes = _entry_class(env_id).metadata.get("render_modes", [])
        check_render_mode(kwargs.get("render_mode"), modes)


def _entry_class(env_id: str) -> type:
    entry = gym.spec(env_id).entry_point
    if callable(entry):
        return entry
    module, name = entry.split(":")
    import importlib

    return getattr(importlib.import_module(module), name)


def make_env(env_id: str, env_kwargs: dict[str, Any] | None = None, **make_kwargs: Any) -> gym.Env:
    """``gym.make`` with the problem named when an ID or keyword is wrong.

    Any ``ValueError`` or ``TypeError`` while the environment is built comes
    from the user's keywords (the environments check every one at
    construction, :mod:`motiongym.envs.core`), and is one usage error.
    """
    check_env_id(env_id)
    kwargs = {**(env_kwargs or {}), **make_kwargs}
    try:
        check_make_kwargs(env_id, kwargs)
        return gym.make(env_id, **kwargs)
    except (TypeError, ValueError) as error:
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
