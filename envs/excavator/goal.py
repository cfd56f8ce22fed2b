"""Where the excavator reach task's goal lives: the bucket pose (achieved) and the target.

For :class:`motiongym.envs.goal.GoalConditionedEnv`: ``achieved_goal`` is
the bucket tip x, y, z (m) and bucket angle (rad), ``desired_goal`` the
target pose in the same order; ``target`` and ``target_error`` leave the
observation. Success: tip within ``tolerance_position`` and angle (wrapped)
within ``tolerance_angle``, as :class:`.task.ReachTask`. A collision is a
contact with the pipe or the truck (physics v1: or the machine itself).
"""

from __future__ import annotations

from typing import Any, cast

from motiongym.envs.excavator.observation import layout
from motiongym.envs.excavator.params import ReachParams, params_for
from motiongym.envs.goal import GoalFields


def goal_fields(kwargs: dict[str, Any]) -> GoalFields:
    """The :class:`GoalFields` of the reach task that ``kwargs`` (the env's keywords) build."""
    p = cast(ReachParams, params_for("reach", kwargs))
    s = layout("reach", p.physics)
    assert s["tip"].stop == s["bucket"].start  # the achieved goal is one slice
    contacts = ("pipe_contact", "truck_contact")
    return GoalFields(
        base_size=s["base" if p.physics == "v1" else "pipe"].stop,
        achieved=slice(s["tip"].start, s["bucket"].stop),
        desired=s["target"],
        error=s["target_error"],
        tolerances=((slice(0, 3), p.tolerance_position), (slice(3, 4), p.tolerance_angle)),
        collision_keys=(*contacts, "self_contact") if p.physics == "v1" else contacts,
        angles=(3,),
    )
