"""The sweeper world: a cleaning robot covering an unknown closed area."""

from __future__ import annotations

REGISTRATIONS: tuple[dict, ...] = (
    {
        "id": "motiongym/Sweeper-v0",
        "entry_point": "motiongym.envs.sweeper.env:SweeperEnv",
        "max_episode_steps": 20_000,
    },
)
