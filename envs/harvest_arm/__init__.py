"""The harvest arm world: a redundant fruit-harvesting arm among branches and immature fruit.

Two IDs cover the paper's six arms: ``motiongym/HarvestArm-v0`` (spatial,
``dof`` 5, 6 or 7, default 7; 10 obstacles, 3 bars) and
``motiongym/HarvestArmPlanar-v0`` (planar, ``dof`` 3, 4 or 5, default 5; 8
obstacles). ``-v1`` of each also counts self-collision (two non-adjacent
links touching) as a collision. See
:class:`motiongym.envs.harvest_arm.env.HarvestArmEnv`.

``motiongym/HarvestArmGoal-v1`` and ``motiongym/HarvestArmPlanarGoal-v1``:
the ``-v1`` tasks as goal-conditioned environments (HER), see
:mod:`motiongym.envs.goal` and :mod:`.goal`.
"""

from __future__ import annotations

from motiongym.envs.goal import goal_registration

REGISTRATIONS: tuple[dict, ...] = (
    {
        "id": "motiongym/HarvestArm-v0",
        "entry_point": "motiongym.envs.harvest_arm.env:HarvestArmEnv",
        "max_episode_steps": 300,
        "kwargs": {"dof": 7, "planar": False},
    },
    {
        "id": "motiongym/HarvestArmPlanar-v0",
        "entry_point": "motiongym.envs.harvest_arm.env:HarvestArmEnv",
        "max_episode_steps": 300,
        "kwargs": {"dof": 5, "planar": True},
    },
    {
        "id": "motiongym/HarvestArm-v1",
        "entry_point": "motiongym.envs.harvest_arm.env:HarvestArmEnv",
        "max_episode_steps": 300,
        "kwargs": {"dof": 7, "planar": False, "self_collision": True},
    },
    {
        "id": "motiongym/HarvestArmPlanar-v1",
        "entry_point": "motiongym.envs.harvest_arm.env:HarvestArmEnv",
        "max_episode_steps": 300,
        "kwargs": {"dof": 5, "planar": True, "self_collision": True},
    },
)
REGISTRATIONS += tuple(
    goal_registration(base, base["id"].replace("-v1", "Goal-v1"), f"{__name__}.goal:goal_fields")
    for base in REGISTRATIONS
    if base["id"].endswith("-v1")
)

# Throughput goals of `motiongym bench`: ID -> (reference ID, least ratio to it).
BENCH_GOALS: dict[str, tuple[str, float]] = {
    f"motiongym/{name}-{version}": ("Reacher-v5", 1.0)
    for name in ("HarvestArm", "HarvestArmPlanar")
    for version in ("v0", "v1")
}
