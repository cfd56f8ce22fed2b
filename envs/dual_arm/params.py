"""The dual-arm cell's keyword arguments, checked once: the environment, its
PettingZoo version and the scripted policies build this one dataclass.

=================== ======================================= ============================
keyword             meaning                                 allowed
=================== ======================================= ============================
control             which arms the agent drives             "both", "robot_2"
pairs               how task pairs are sampled              "colliding", "any", "paper"
safety_margin       collision when d(R1, R2) <= this (m)    [0, 0.5]
clearance_distance  range of the clearance term (m)         (0, 2]
time, collision,    reward weights: magnitudes (``advance`` finite, in [0, 1e6]
clearance, advance  is paid, the others are costs)          (:func:`.core.check_weight`)
collision_check     "samples" (v0) or "swept" (v1)          :data:`.collision.CHECKS`
render_size         (rows, columns) of a frame              integers in [16, 2048]
=================== ======================================= ============================

``task`` is the deprecated name of ``pairs`` (warns once).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from motiongym.envs.core import (
    Deprecated,
    check_choice,
    check_float,
    check_render_size,
    check_weight,
    params_from_kwargs,
)
from motiongym.envs.dual_arm.collision import CHECKS
from motiongym.envs.dual_arm.task import PAIRS

CONTROLS = ("both", "robot_2")
COLLISION_CHECKS = CHECKS
WEIGHTS = ("time", "collision", "clearance", "advance")  # the reward terms, in order
PAID = ("advance",)  # the terms added; the others are costs


def _pairs_from_task(value: Any, current: Any) -> str:
    """``pairs`` from its deprecated name ``task`` (a bad value refused under that name)."""
    return check_choice("task", value, PAIRS)


@dataclass(frozen=True)
class DualArmParams:
    """The dual-arm cell's parameters (module docstring)."""

    control: str = "both"
    pairs: str = "colliding"
    safety_margin: float = 0.0  # m
    clearance_distance: float = 0.05  # m
    time: float = 1.0
    collision: float = 10.0
    clearance: float = 0.1
    advance: float = 0.0
    collision_check: str = "samples"
    render_size: tuple[int, int] = (480, 640)  # rows, columns of a frame

    DEPRECATED: ClassVar[dict[str, Deprecated]] = {"task": Deprecated("pairs", _pairs_from_task)}

    def __post_init__(self) -> None:
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        check_choice("control", self.control, CONTROLS)
        check_choice("pairs", self.pairs, PAIRS)
        check_choice("collision_check", self.collision_check, CHECKS)
        put("safety_margin", check_float("safety_margin", self.safety_margin, 0.0, 0.5))
        put(
            "clearance_distance",
            check_float("clearance_distance", self.clearance_distance, 0.0, 2.0, low_open=True),
        )
        for name in WEIGHTS:
            put(name, check_weight(name, getattr(self, name), cost=name not in PAID))
        put("render_size", check_render_size("render_size", self.render_size))

    @property
    def weights(self) -> dict[str, float]:
        """``{term: weight}`` in the order of the reward terms."""
        return {name: getattr(self, name) for name in WEIGHTS}


def params_for(kwargs: dict[str, Any] | None) -> DualArmParams:
    """The parameters from environment keyword arguments (``render_mode`` and
    ``max_episode_steps`` ignored: what a policy's ``env_kwargs`` may hold)."""
    return params_from_kwargs(
        DualArmParams, dict(kwargs or {}), ignore=("render_mode", "max_episode_steps")
    )
