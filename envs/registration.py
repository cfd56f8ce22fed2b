"""Registration of every motiongym environment with Gymnasium.

Each system's environments module declares its IDs in a ``REGISTRATIONS``
tuple of keyword dictionaries for :func:`gymnasium.register` (entry points
are strings, so nothing heavy is imported until an environment is made);
the systems are listed once, in :mod:`motiongym.systems`.
"""

from __future__ import annotations

import gymnasium as gym

from motiongym.systems import SYSTEMS

NAMESPACE = "motiongym"


def _declared() -> list[dict]:
    return [spec for system in SYSTEMS for spec in system.envs_module().REGISTRATIONS]


def register_all() -> None:
    """Register every declared ID once (re-importing is harmless)."""
    for spec in _declared():
        if spec["id"] not in gym.registry:
            gym.register(**spec)


def env_ids() -> tuple[str, ...]:
    """Every declared ID, systems added at run time included."""
    return tuple(spec["id"] for spec in _declared())


ENV_IDS: tuple[str, ...] = env_ids()
