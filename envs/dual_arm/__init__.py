"""The dual-arm cell: two PUMA-560 arms, fixed paths, collision avoided by timing.

``motiongym/DualArmCell-v0`` (Gymnasium, :class:`~.env.DualArmCellEnv`) and
:func:`parallel_env` (PettingZoo ``ParallelEnv`` over the same world, agents
``robot_1`` and ``robot_2``). Nothing heavy is imported here.
"""

from __future__ import annotations

from typing import Any

REGISTRATIONS: tuple[dict, ...] = (
    {
        "id": "motiongym/DualArmCell-v0",
        "entry_point": "motiongym.envs.dual_arm.env:DualArmCellEnv",
        "max_episode_steps": 1000,
        "kwargs": {"control": "both", "task": "colliding"},
    },
    {
        "id": "motiongym/DualArmCell-v1",
        "entry_point": "motiongym.envs.dual_arm.env:DualArmCellEnv",
        "max_episode_steps": 1000,
        "kwargs": {"control": "both", "task": "colliding", "collision_check": "swept"},
    },
)


def parallel_env(**kwargs: Any):  # -> DualArmParallelEnv
    """The PettingZoo parallel environment (keywords as :class:`~.parallel.DualArmParallelEnv`)."""
    from motiongym.envs.dual_arm.parallel import DualArmParallelEnv

    return DualArmParallelEnv(**kwargs)
