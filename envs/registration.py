"""Registration of every motiongym environment with Gymnasium.

Each system's subpackage declares its IDs in a ``REGISTRATIONS`` tuple of
keyword dictionaries for :func:`gymnasium.register` (entry points are strings,
so nothing heavy is imported until an environment is made). This module walks
the systems once; a new system only adds its name to ``SYSTEMS``.
"""

from __future__ import annotations

import importlib

import gymnasium as gym

SYSTEMS = ("sweeper", "harvest_arm", "dual_arm", "excavator")
NAMESPACE = "motiongym"


def _declared() -> list[dict]:
    declared = []
    for system in SYSTEMS:
        module = importlib.import_module(f"motiongym.envs.{system}")
        declared.extend(module.REGISTRATIONS)
    return declared


def register_all() -> None:
    """Register every declared ID once (re-importing is harmless)."""
    for spec in _declared():
        if spec["id"] not in gym.registry:
            gym.register(**spec)


ENV_IDS: tuple[str, ...] = tuple(spec["id"] for spec in _declared())
