"""Scripted reference policies for the excavator world.

``newton_raphson`` (the paper's IK, eq. 9-13, with a damped variant),
``bucket_path`` (the dig-cycle path generator), ``tracking`` (joint-rate
tracking, IK with fallbacks), ``policies`` (the two policies).
"""

from __future__ import annotations

POLICIES: dict[str, dict[str, str]] = {
    "motiongym/ExcavatorReach-v0": {
        "newton-raphson-reach": "motiongym.baselines.excavator.policies:ReachPolicy",
    },
    "motiongym/Excavator-v0": {
        "dig-cycle": "motiongym.baselines.excavator.policies:DigCyclePolicy",
    },
    "motiongym/ExcavatorReach-v1": {
        "newton-raphson-reach": "motiongym.baselines.excavator.policies:ReachPolicy",
    },
    "motiongym/Excavator-v1": {
        "dig-cycle": "motiongym.baselines.excavator.policies:DigCyclePolicy",
    },
    "motiongym/ExcavatorReachGoal-v1": {
        "newton-raphson-reach": "motiongym.baselines.excavator.policies:GoalReachPolicy",
    },
}

# Planning times of `motiongym bench`: label -> ("module:function", goal in s).
PLANNERS: dict[str, tuple[str, float | None]] = {
    "Newton-Raphson IK, excavator paper case": (
        "motiongym.baselines.excavator.newton_raphson:solve_paper_case",
        None,
    ),
}
