"""The dual-arm cell: two PUMA-560 arms, fixed paths, collision avoided by timing.

``motiongym/DualArmCell-v0`` (Gymnasium, :class:`~.env.DualArmCellEnv`) and
:func:`parallel_env` (PettingZoo ``ParallelEnv`` over the same world, agents
``robot_1`` and ``robot_2``). Nothing heavy is imported here.

The IDs leave ``pairs`` at its default ("colliding") rather than naming it, so
that ``gym.make(ID, task=...)``, its deprecated name, still works for one
release (a keyword and its deprecated name together are refused).
"""

from __future__ import annotations

from typing import Any

REGISTRATIONS: tuple[dict, ...] = (
    {
        "id": "motiongym/DualArmCell-v0",
        "entry_point": "motiongym.envs.dual_arm.env:DualArmCellEnv",
        "max_episode_steps": 1000,
        "kwargs": {"control": "both"},
    },
    {
        "id": "motiongym/DualArmCell-v1",
        "entry_point": "motiongym.envs.dual_arm.env:DualArmCellEnv",
        "max_episode_steps": 1000,
        "kwargs": {"control": "both", "collision_check": "swept"},
    },
)


def parallel_env(**kwargs: Any):  # -> DualArmParallelEnv
    """The PettingZoo parallel environment (keywords as :class:`~.parallel.DualArmParallelEnv`)."""
    from motiongym.envs.dual_arm.parallel import DualArmParallelEnv

    return DualArmParallelEnv(**kwargs)


def parallel_env_v1(**kwargs: Any):  # -> DualArmParallelEnv
    """:func:`parallel_env` on ``DualArmCell-v1``'s check (the motion between samples)."""
    return parallel_env(**{"collision_check": "swept", **kwargs})


# PettingZoo versions of IDs: ID -> "module:factory".
PARALLEL_ENVS: dict[str, str] = {
    "motiongym/DualArmCell-v0": "motiongym.envs.dual_arm:parallel_env",
    "motiongym/DualArmCell-v1": "motiongym.envs.dual_arm:parallel_env_v1",
}
# Throughput goals of `motiongym bench`: ID -> (reference ID, least ratio to it).
BENCH_GOALS: dict[str, tuple[str, float]] = {
    "motiongym/DualArmCell-v0": ("Reacher-v5", 1.0),
    "motiongym/DualArmCell-v1": ("Reacher-v5", 1.0),
}
