"""Making environments by ID with clear errors for unknown IDs and keywords."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from motiongym.agents.errors import UsageError
from motiongym.envs import ENV_IDS
from motiongym.envs.core import check_int, check_render_mode


def check_env_id(env_id: Any) -> str:
    """Return ``env_id`` if Gymnasium knows it, else raise with the valid IDs."""
    if not isinstance(env_id, str) or env_id not in gym.registry:
        raise UsageError(f"unknown environment ID {env_id!r}; valid IDs: {', '.join(ENV_IDS)}")
    return env_id


def resolved_env_kwargs(env_id: str, env_kwargs: dict[str, Any] | None) -> dict[str, Any]:
    """The registered keyword defaults of ``env_id`` updated with the user's."""
    return {**gym.spec(check_env_id(env_id)).kwargs, **(env_kwargs or {})}


def made_kwargs(env: gym.Env) -> dict[str, Any]:
    """The keywords ``env`` was made with (its ``spec``'s: the registered defaults and the
    user's, less gym.make's own); a ``ValueError`` for an environment not made by gym.make."""
    if env.spec is None:
        raise ValueError(f"{env} was not made by gym.make: it has no spec to read keywords from")
    return env.spec.kwargs


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


def _entry_class(env_id: str) -> Any:
    entry = gym.spec(env_id).entry_point
    if not isinstance(entry, str):  # the class (or a factory) itself
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


# An evaluation of an ID whose episodes may last longer than this many steps is
# announced before it starts (a policy that never finishes runs each to the limit).
LONG_EPISODE = 2_000


def episode_limit(env_id: str, env_kwargs: dict[str, Any] | None = None) -> int | None:
    """The steps after which an episode of ``env_id`` is cut (``max_episode_steps``:
    ``env_kwargs``' or the registered one; None for no limit)."""
    return (env_kwargs or {}).get("max_episode_steps", gym.spec(env_id).max_episode_steps)


def long_episodes_note(env_id: str, env_kwargs: dict[str, Any] | None, episodes: int) -> str | None:
    """What ``episodes`` episodes of ``env_id`` may cost, where its step limit passes
    :data:`LONG_EPISODE` (None elsewhere): said before an evaluation starts."""
    limit = episode_limit(env_id, env_kwargs)
    if limit is None or limit <= LONG_EPISODE:
        return None
    return (
        f"{short_name(env_id)}'s episodes end at success or at {limit:,} steps: a policy "
        f"that does not finish runs {episodes} x {limit:,} steps"
    )


def importable_id(env_id: str) -> str:
    """``motiongym:motiongym/X-v0``: the form that imports motiongym before making.

    A spawned subprocess (SubprocVecEnv) starts without motiongym imported,
    so the IDs are not registered there; this form registers them first.
    """
    return f"motiongym:{env_id}" if env_id in ENV_IDS else env_id


def short_name(env_id: str) -> str:
    """``motiongym/Sweeper-v0`` -> ``Sweeper-v0`` (file and folder names)."""
    return env_id.split("/")[-1]
