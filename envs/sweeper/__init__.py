"""The sweeper world: a cleaning robot covering an unknown closed area (paper 003)."""

from __future__ import annotations

REGISTRATIONS: tuple[dict, ...] = (
    {
        "id": "motiongym/Sweeper-v0",
        "entry_point": "motiongym.envs.sweeper.env:SweeperEnv",
        "vector_entry_point": "motiongym.envs.sweeper.vector_env:SweeperVectorEnv",
        "max_episode_steps": 20_000,
        "kwargs": {"map_name": "room", "robot_width": 3},
    },
    {
        "id": "motiongym/Sweeper-v1",
        "entry_point": "motiongym.envs.sweeper.env:SweeperEnv",
        "vector_entry_point": "motiongym.envs.sweeper.vector_env:SweeperVectorEnv",
        "max_episode_steps": 20_000,
        "kwargs": {"map_name": "room", "robot_width": 3, "line_of_sight": True},
    },
)

# Throughput goals of `motiongym bench`: ID -> (reference ID, least ratio to it).
BENCH_GOALS: dict[str, tuple[str, float]] = {
    "motiongym/Sweeper-v0": ("CartPole-v1", 0.3),
    "motiongym/Sweeper-v1": ("CartPole-v1", 0.3),
}
# Vectorised: ID -> (least steps/s, least ratio to SyncVectorEnv).
BENCH_VECTOR_GOALS: dict[str, tuple[float, float]] = {
    "motiongym/Sweeper-v0": (1_000_000.0, 100.0),
}
