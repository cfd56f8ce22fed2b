"""Where the harvest arm's goal lives: the gripper (achieved) and the fruit (desired).

For :class:`motiongym.envs.goal.GoalConditionedEnv`: ``achieved_goal`` is the
last joint point (the gripper, m), ``desired_goal`` the fruit centre (m);
``fruit`` and ``fruit_error`` leave the observation. Success: the gripper
within ``success_tolerance`` of the fruit, as :class:`.env.HarvestArmEnv`.
"""

from __future__ import annotations

from typing import Any

from motiongym.envs.core import params_from_kwargs
from motiongym.envs.goal import GoalFields
from motiongym.envs.harvest_arm.observation import layout_for
from motiongym.envs.harvest_arm.params import HarvestArmParams


def goal_fields(kwargs: dict[str, Any]) -> GoalFields:
    """The :class:`GoalFields` of the arm that ``kwargs`` (the env's keywords) build."""
    p = params_from_kwargs(HarvestArmParams, kwargs)
    layout = layout_for(p)
    s, dim = layout.slices, p.arm.dim
    goal = slice(0, dim)
    return GoalFields(
        base_size=layout.size,
        achieved=slice(s["points"].stop - dim, s["points"].stop),
        desired=s["fruit"],
        error=s["fruit_error"],
        tolerances=((goal, p.success_tolerance),),
        collision_keys=("collision",),
        collision_ends=p.terminate_on_collision,
    )
