"""The excavator world: a 20 t backhoe, carving ground, a buried pipe and a truck.

Paper: Shin, Park, Lee and Hong, "Development of Optimal Path Planning for
Automated Excavator" (kinematics eq. 1-5, Newton-Raphson IK eq. 9-13).
``motiongym/ExcavatorReachGoal-v1``: ``ExcavatorReach-v1`` as a
goal-conditioned environment (HER), see :mod:`motiongym.envs.goal` and
:mod:`.goal`.
"""

from __future__ import annotations

from motiongym.envs.goal import goal_registration

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
    {
        "id": "motiongym/ExcavatorReach-v1",
        "entry_point": "motiongym.envs.excavator.env:ExcavatorReachEnv",
        "max_episode_steps": 200,
        "kwargs": {"physics": "v1", "slope": 0.1},
    },
    {
        "id": "motiongym/Excavator-v1",
        "entry_point": "motiongym.envs.excavator.env:ExcavatorEnv",
        "max_episode_steps": 600,
        "kwargs": {"physics": "v1", "slope": 0.1},
    },
)
REGISTRATIONS += (
    goal_registration(
        REGISTRATIONS[2], "motiongym/ExcavatorReachGoal-v1", f"{__name__}.goal:goal_fields"
    ),
)

# Throughput goals of `motiongym bench`: ID -> (reference ID, least ratio to it).
BENCH_GOALS: dict[str, tuple[str, float]] = {
    f"motiongym/{name}-{version}": ("Reacher-v5", 1.0)
    for name in ("Excavator", "ExcavatorReach")
    for version in ("v0", "v1")
}
