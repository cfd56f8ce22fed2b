"""Scripted reference policies for the harvest arm world.

``potential-field``: the paper's three layers (potential-field gripper path,
joint-point reference velocities, weighted pseudo-inverse with null-space
term). ``resolved-rate``: the plain pseudo-inverse straight to the fruit.
"""

from __future__ import annotations

_POLICIES = {
    "potential-field": "motiongym.baselines.harvest_arm.policy:PotentialFieldPolicy",
    "potential-field-extended": (
        "motiongym.baselines.harvest_arm.policy:ExtendedPotentialFieldPolicy"
    ),
    "resolved-rate": "motiongym.baselines.harvest_arm.policy:ResolvedRatePolicy",
}

POLICIES: dict[str, dict[str, str]] = {
    "motiongym/HarvestArm-v0": dict(_POLICIES),
    "motiongym/HarvestArmPlanar-v0": dict(_POLICIES),
    "motiongym/HarvestArm-v1": dict(_POLICIES),
    "motiongym/HarvestArmPlanar-v1": dict(_POLICIES),
}
# The goal-conditioned IDs: the same policies reading the goal Dict (baselines/goal.py).
for _name in ("HarvestArm", "HarvestArmPlanar"):
    POLICIES[f"motiongym/{_name}Goal-v1"] = {
        policy: path.replace(":", ":Goal") for policy, path in _POLICIES.items()
    }
