"""The excavator world: a 20 t backhoe, carving ground, a buried pipe and a truck.

Paper: ``../shared/papers/002_884a424d690ac408.txt`` (kinematics eq. 1-5,
Newton-Raphson IK eq. 9-13); our reading: ``../shared/specs/excavator.md``.
"""

from __future__ import annotations

REGISTRATIONS: tuple[dict, ...] = (
    {
        "id": "motiongym/ExcavatorReach-v0",
        "entry_point": "motiongym.envs.excavator.env:ExcavatorReachEnv",
        "max_episode_steps": 200,
    },
    {
        "id": "motiongym/Excavator-v0",
        "entry_point": "motiongym.envs.excavator.env:ExcavatorEnv",
        "max_episode_steps": 600,
    },
)
