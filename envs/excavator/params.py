"""The excavator environments' parameters: one frozen dataclass per task.

The environment and its scripted policies build the same object from the same
keyword arguments (:func:`params_for`), so a default is written once and a
bad value is refused at construction with one message naming the argument.

Limits (checked in ``__post_init__``; they keep a step's time and memory bounded):

==================  ==========================================================
argument            allowed
==================  ==========================================================
machine             None, a :class:`Machine`, or a dict of its fields (each
                    checked, see :data:`motiongym.envs.excavator.config.LIMITS`)
dt                  finite, in (0, 1] s
pipe_safety         finite, in [0, 5] m
physics             "v0" (registered v0 IDs) or "v1" (see :mod:`.world`)
slope               finite, in [0, 0.3] rad: the largest base roll / pitch a
                    scene draws (v1 only; 0 is level ground)
render_size         (rows, columns) of a frame, integers in [16, 2048]
                    (:func:`motiongym.envs.core.check_render_size`)
tolerances          finite, in (0, 10] (m or rad)
closeness_scale     finite, in (0, 100] m
success_volume      finite, in (0, 50] m3
reward weights      magnitudes, finite, in [0, 1e6]
                    (:func:`motiongym.envs.core.check_weight`); a term's sign is
                    its meaning's (a cost is subtracted), so a negative weight is
                    refused (for a cost: naming the positive weight of the same
                    reward)
==================  ==========================================================
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, ClassVar

from motiongym.envs.core import (
    ArgumentError,
    check_choice,
    check_float,
    check_render_size,
    check_weight,
    params_from_kwargs,
)
from motiongym.envs.excavator.config import Machine, machine_from_kwargs


@dataclass(frozen=True)
class ExcavatorParams:
    """What both tasks share: the machine, the step, the safety distance and the physics."""

    machine: Any = None
    dt: float = 0.1  # s
    pipe_safety: float = 0.5  # m
    physics: str = "v0"
    slope: float = 0.0  # rad
    render_size: tuple[int, int] = (480, 640)  # rows, columns of a frame

    REWARD_TERMS: ClassVar[tuple[str, ...]] = ()
    COSTS: ClassVar[tuple[str, ...]] = ()  # the terms that are subtracted

    def __post_init__(self) -> None:
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        put("machine", machine_from_kwargs(self.machine))
        put("dt", check_float("dt", self.dt, 0.0, 1.0, low_open=True))
        put("pipe_safety", check_float("pipe_safety", self.pipe_safety, 0.0, 5.0))
        put("physics", check_choice("physics", self.physics, ("v0", "v1")))
        put("slope", check_float("slope", self.slope, 0.0, 0.3))
        if self.physics == "v0" and self.slope != 0.0:
            raise ArgumentError(f"slope must be 0 with physics 'v0', got {self.slope!r}")
        put("render_size", check_render_size("render_size", self.render_size))
        for name in self.REWARD_TERMS:
            put(name, check_weight(name, getattr(self, name), cost=name in self.COSTS))

    @property
    def m(self) -> Machine:
        return self.machine

    @property
    def weights(self) -> dict[str, float]:
        """``{term: weight}`` in the order of the task's reward terms."""
        return {name: getattr(self, name) for name in self.REWARD_TERMS}


@dataclass(frozen=True)
class ReachParams(ExcavatorParams):
    """:class:`ExcavatorParams` and the reach task's tolerances and weights."""

    tolerance_position: float = 0.05  # m
    tolerance_angle: float = 0.05  # rad
    progress: float = 1.0
    clearance: float = 1.0
    contact: float = 10.0
    time: float = 0.01
    success: float = 10.0
    closeness: float = 0.0
    closeness_scale: float = 0.5  # m (and rad, 1 m per rad)

    REWARD_TERMS = ("progress", "clearance", "contact", "time", "success", "closeness")
    COSTS = ("clearance", "contact", "time")

    def __post_init__(self) -> None:
        super().__post_init__()
        for name, high in (
            ("tolerance_position", 10.0),
            ("tolerance_angle", 10.0),
            ("closeness_scale", 100.0),
        ):
            value = check_float(name, getattr(self, name), 0.0, high, low_open=True)
            object.__setattr__(self, name, value)


@dataclass(frozen=True)
class DigParams(ExcavatorParams):
    """:class:`ExcavatorParams` and the dig task's volume and weights."""

    success_volume: float = 0.3  # m3
    delivered: float = 10.0
    fill: float = 2.0
    spill: float = 5.0
    clearance: float = 1.0
    contact: float = 10.0
    time: float = 0.01
    success: float = 10.0
    approach: float = 0.0

    REWARD_TERMS = (
        "delivered",
        "fill",
        "spill",
        "clearance",
        "contact",
        "time",
        "success",
        "approach",
    )
    COSTS = ("spill", "clearance", "contact", "time")

    def __post_init__(self) -> None:
        super().__post_init__()
        value = check_float("success_volume", self.success_volume, 0.0, 50.0, low_open=True)
        object.__setattr__(self, "success_volume", value)


PARAMS = {"reach": ReachParams, "dig": DigParams}


def params_for(task: str, kwargs: dict[str, Any] | None) -> ExcavatorParams:
    """The task's parameters from environment keyword arguments (``render_mode`` ignored)."""
    return params_from_kwargs(PARAMS[task], dict(kwargs or {}), ignore=("render_mode",))


def field_names(task: str) -> tuple[str, ...]:
    """The keyword arguments the task's environment accepts (besides ``render_mode``)."""
    return tuple(f.name for f in fields(PARAMS[task]))
