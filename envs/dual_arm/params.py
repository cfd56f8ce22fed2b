"""The dual-arm cell's keyword arguments, checked once: the environment, its
PettingZoo version and the scripted policies build this one dataclass.

=================== ======================================= ==============
keyword             meaning                                 allowed
=================== ======================================= ==============
control             which arms the agent drives             "both", "robot_2"
task                how task pairs are sampled              "colliding", "any", "paper"
safety_margin       collision when d(R1, R2) <= this (m)    [0, 0.5]
clearance_distance  range of the clearance term (m)         (0, 2]
time, collision,    reward weights                          finite, |w| <= 1e6
clearance, advance
collision_check     "samples" (v0) or "swept" (v1)          as said
=================== ======================================= ==============
"""

from __future__ import annotations

from dataclasses import dataclass

from motiongym.envs.core import check_choice, check_float
from motiongym.envs.dual_arm.task import TASK_MODES

CONTROLS = ("both", "robot_2")
COLLISION_CHECKS = ("samples", "swept")
WEIGHTS = ("time", "collision", "clearance", "advance")


@dataclass(frozen=True)
class DualArmParams:
    control: str = "both"
    task: str = "colliding"
    safety_margin: float = 0.0  # m
    clearance_distance: float = 0.05  # m
    time: float = 1.0
    collision: float = 10.0
    clearance: float = 0.1
    advance: float = 0.0
    collision_check: str = "samples"

    def __post_init__(self) -> None:
        check_choice("control", self.control, CONTROLS)
        check_choice("task", self.task, TASK_MODES)
        check_choice("collision_check", self.collision_check, COLLISION_CHECKS)
        set_ = object.__setattr__
        set_(self, "safety_margin", check_float("safety_margin", self.safety_margin, 0.0, 0.5))
        set_(
            self,
            "clearance_distance",
            check_float("clearance_distance", self.clearance_distance, 0.0, 2.0, low_open=True),
        )
        for name in WEIGHTS:
            set_(self, name, check_float(name, getattr(self, name), -1e6, 1e6))
