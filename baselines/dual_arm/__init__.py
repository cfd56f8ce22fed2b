"""Scripted reference policies for the dual-arm cell (paper 001: time delay by
boundary following on the collision map), and the schedules they compare with."""

from __future__ import annotations

_MODULE = "motiongym.baselines.dual_arm.policies"

POLICIES: dict[str, dict[str, str]] = {
    "motiongym/DualArmCell-v0": {
        "boundary-following": f"{_MODULE}:BoundaryFollowingPolicy",
        "exhaustive-delay": f"{_MODULE}:ExhaustiveDelayPolicy",
        "sequential": f"{_MODULE}:SequentialPolicy",
        "min-makespan": f"{_MODULE}:MinMakespanPolicy",
        "undelayed": f"{_MODULE}:UndelayedPolicy",
        "either-waits": f"{_MODULE}:EitherWaitsPolicy",
    },
}
POLICIES["motiongym/DualArmCell-v1"] = dict(POLICIES["motiongym/DualArmCell-v0"])

# Planning times of `motiongym bench`: label -> ("module:function", goal in s).
PLANNERS: dict[str, tuple[str, float | None]] = {
    "boundary following, dual-arm paper case": (
        "motiongym.baselines.dual_arm.boundary_following:plan_paper_case",
        0.1,
    ),
    "boundary following + exact checks (v1), dual-arm paper case": (
        "motiongym.baselines.dual_arm.bracket:plan_paper_case",
        0.1,
    ),
    "exact delay by brute force (v1 check), dual-arm paper case": (
        "motiongym.baselines.dual_arm.exact_delay:solve_paper_case",
        None,
    ),
    "boundary following + exact checks (v1), per sampled pair (10 pairs in turn)": (
        "motiongym.baselines.dual_arm.bracket:plan_sampled_pair",
        0.1,
    ),
    "exact delay by brute force (v1 check), per sampled pair (the same pairs)": (
        "motiongym.baselines.dual_arm.exact_delay:solve_sampled_pair",
        None,
    ),
}
