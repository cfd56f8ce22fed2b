"""The two excavator tasks: scene, success, reward terms, ``info`` and observation.

A task obeys :class:`motiongym.envs.core.Task`: it reads the world
(:class:`.world.ExcavatorWorld`, or :class:`.world_v1.ExcavatorWorldV1`)
and never changes it.

* ``sample(rng, options) -> Scene``: the scene of :mod:`.scenes` drawn from
  ``rng`` alone (:meth:`ExcavatorTask.sample_scene`), carrying the start
  pose: the reset option ``start`` (4 joint angles, rad) or
  ``Machine.q_ready``;
* ``begin(world) -> Outcome``: the observation's fields that stay for the
  episode (truck, pipe, v1's base, the target or the dig zone), the
  per-episode state, every reward term 0;
* ``evaluate(world, events) -> Outcome``: the reward terms of the step
  (weights: the parameters of the same names, :mod:`.params`), success, the
  cost (1.0 when the pipe clearance is below ``pipe_safety`` or on a
  contact), the ``info`` measures, termination (success or contact).
  ``events`` is None: what happened in the step is the world's state
  (``contact``, ``taken``, the clearances);
* ``observe(world)``: the observation of :mod:`.observation` (the changing
  fields written into the episode's buffer, a copy returned).

Each task owns ``observation_space``, ``reward_terms``, ``options``
(``start``) and ``deprecated_options`` (``q0``, the old name of ``start``);
``NAME`` (its observation layout) and ``CARVE`` (whether the ground is
worked) tell the environment which world to build.
"""

from __future__ import annotations

import dataclasses
import math
import struct
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces

from motiongym.envs.core import START, Deprecated, Outcome, check_shape, zero_terms
from motiongym.envs.excavator.observation import bounds, observation_layout
from motiongym.envs.excavator.params import DigParams, ExcavatorParams, ReachParams
from motiongym.envs.excavator.scenes import Scene, sample_dig_scene, sample_reach_scene

# Observation fields q ... fill written as float32 straight into the buffer: the
# same rounding as NumPy's cast, without converting a list.
_STATE = struct.Struct("=13f")
# target_error written the same way.
_ERROR = struct.Struct("=4f")


def check_start(name: str, value: Any) -> np.ndarray:
    """The reset option ``start``: 4 finite joint angles (rad; clipped to the ranges at reset)."""
    return check_shape(name, value, (4,))


class ExcavatorTask:
    """What both tasks share: options, observation buffer, cost and the common ``info``."""

    NAME: ClassVar[str]
    CARVE: ClassVar[bool]
    REWARD_TERMS: ClassVar[tuple[str, ...]]

    def __init__(self, params: ExcavatorParams) -> None:
        self.p = params
        self.w = params.weights
        self.m = params.machine
        self.layout = observation_layout(self.NAME, params.physics)
        assert self.layout["q"].start == 0 and self.layout["fill"].stop == _STATE.size // 4
        low, high = bounds(self.NAME, self.m, params.physics)
        self.observation_space: spaces.Space = spaces.Box(low, high, dtype=np.float32)
        self.reward_terms: tuple[str, ...] = self.REWARD_TERMS
        self.options: Mapping[str, Callable[[str, Any], Any]] = {START: check_start}
        self.deprecated_options = {"q0": Deprecated(START)}
        self._profile = self.layout["profile"]
        self._obs = np.zeros(self.layout.size, np.float32)

    # ------------------------------------------------------------------ the episode
    def sample_scene(self, rng: np.random.Generator) -> Scene:
        """The scene drawn from ``rng`` (without its start pose)."""
        raise NotImplementedError

    def sample(self, rng: np.random.Generator, options: Mapping[str, Any]) -> Scene:
        start = options.get(START)
        scene = self.sample_scene(rng)
        return dataclasses.replace(scene, start=self.m.q_ready if start is None else start)

    def begin(self, world: Any) -> Outcome:
        buf = self._obs = np.zeros(self.layout.size, np.float32)
        scene, lay = world.scene, self.layout
        buf[lay["truck"]] = scene.truck.as_array()
        buf[lay["pipe"]] = scene.pipe.as_array()
        if "base" in lay:
            buf[lay["base"]] = scene.base[:2]
        self._begin(world, buf)
        costly = world.contact or world.pipe_clear < self.p.pipe_safety
        cost = 1.0 if costly else 0.0
        return Outcome(zero_terms(self.REWARD_TERMS), False, cost, self.measures(world), False)

    def _begin(self, world: Any, buf: np.ndarray) -> None:
        """The task's static observation fields and per-episode state."""
        raise NotImplementedError

    def evaluate(self, world: Any, events: None) -> Outcome:
        """The step's outcome (``events`` is None: module docstring)."""
        raise NotImplementedError

    def observe(self, world: Any) -> np.ndarray:
        """The layout of :mod:`.observation`; inside the bounds by construction (tested).

        The static fields (task, truck, pipe, base) are written once by :meth:`begin`.
        """
        w, buf = world, self._obs
        # numpy declares the buffer protocol (__buffer__) to type checkers for Python >= 3.12 only
        _STATE.pack_into(buf, 0, *w.q, *w.qdot, *w.tip, w.beta, w.fill)  # type: ignore[arg-type]
        buf[self._profile] = w.profile()
        self._write(w, buf)
        return buf.copy()

    def _write(self, world: Any, buf: np.ndarray) -> None:
        """The task's changing observation fields."""
        raise NotImplementedError

    def measures(self, world: Any) -> dict[str, Any]:
        """The ``info`` measures: both tasks', the physics' and the task's own."""
        info = self._common_measures(world)
        info.update(self.task_measures(world))
        return info

    def _common_measures(self, w: Any) -> dict[str, Any]:
        """Both tasks' ``info`` measures and the physics' (:meth:`ExcavatorWorld.measures`)."""
        pipe, truck = w.pipe_clear, w.truck_clear
        info: dict[str, Any] = {
            "pipe_clearance": float(pipe),
            "truck_clearance": float(truck),
            "pipe_contact": 1.0 if pipe <= 0.0 else 0.0,
            "truck_contact": 1.0 if truck <= 0.0 else 0.0,
            "bucket_fill": float(w.fill),
            "truck_soil": float(w.truck_soil),
            "spill": float(w.spill),
            "elapsed": float(w.elapsed),
        }
        info.update(w.measures())
        return info

    def task_measures(self, world: Any) -> dict[str, Any]:
        """The task's own ``info`` keys."""
        raise NotImplementedError


class ReachTask(ExcavatorTask):
    """Bring the bucket tip to a sampled target pose (see :class:`ExcavatorReachEnv`)."""

    NAME = "reach"
    CARVE = False
    REWARD_TERMS = ReachParams.REWARD_TERMS

    p: ReachParams
    _errors: tuple[Any, Any, Any]  # (tip, beta, (pos, ang)) of the last errors() call

    def __init__(self, params: ReachParams) -> None:
        super().__init__(params)
        self._error_offset = 4 * self.layout["target_error"].start  # bytes into the buffer

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_reach_scene(rng, self.m, self.p.slope)

    def errors(self, world: Any) -> tuple[float, float]:
        """``(position error m, bucket angle error rad)`` of the tip against the target.

        Kept for the pose it was computed at (the step's reward and ``info`` both read it).
        """
        tip, beta = world.tip, world.beta
        memo = self._errors
        if memo[0] is tip and memo[1] == beta:
            return memo[2]
        t = self._target
        pos = math.dist(tip, t[:3])
        ang = abs(math.remainder(beta - t[3], 2 * math.pi))
        self._errors = (tip, beta, (pos, ang))
        return pos, ang

    def _begin(self, world: Any, buf: np.ndarray) -> None:
        buf[self.layout["target"]] = world.scene.target
        # The target as Python floats (the same doubles; NumPy scalars cost more per operation).
        self._target = tuple(float(x) for x in world.scene.target)
        self._errors = (None, None, None)
        pos, ang = self.errors(world)
        self._err = pos + ang

    def _write(self, world: Any, buf: np.ndarray) -> None:
        t, tip = self._target, world.tip
        # numpy declares the buffer protocol (__buffer__) to type checkers for Python >= 3.12 only
        _ERROR.pack_into(
            buf,  # type: ignore[arg-type]
            self._error_offset,
            t[0] - tip[0],
            t[1] - tip[1],
            t[2] - tip[2],
            math.remainder(t[3] - world.beta, 2 * math.pi),
        )

    def evaluate(self, world: Any, events: None) -> Outcome:
        w, p = self.w, self.p
        pos, ang = self.errors(world)
        err = pos + ang
        success = pos < p.tolerance_position and ang < p.tolerance_angle
        contact = world.contact
        costly = contact or world.pipe_clear < p.pipe_safety
        terms = {
            "progress": w["progress"] * (self._err - err),
            "clearance": -w["clearance"] if costly else 0.0,
            "contact": -w["contact"] if contact else 0.0,
            "time": -w["time"],
            "success": w["success"] if success else 0.0,
            "closeness": w["closeness"] * math.exp(-err / p.closeness_scale),
        }
        self._err = err
        info = self._common_measures(world)  # and task_measures, from the errors at hand:
        info["position_error"], info["angle_error"] = float(pos), float(ang)
        return Outcome(terms, success, 1.0 if costly else 0.0, info, success or contact)

    def task_measures(self, world: Any) -> dict[str, Any]:
        pos, ang = self.errors(world)
        return {"position_error": float(pos), "angle_error": float(ang)}


class DigTask(ExcavatorTask):
    """Dig in the marked zone and deliver to the truck (see :class:`ExcavatorEnv`)."""

    NAME = "dig"
    CARVE = True
    REWARD_TERMS = DigParams.REWARD_TERMS

    p: DigParams

    def __init__(self, params: DigParams) -> None:
        super().__init__(params)
        self._soil_index = self.layout["truck_soil"].start

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_dig_scene(rng, self.m, self.p.slope)

    def subgoal(self, world: Any) -> tuple[float, float, float]:
        """The point the ``approach`` term draws the bucket tip to (m, frame O).

        While the bucket holds less than the soil still owed to the truck
        (``success_volume`` - truck soil): the middle of the dig zone, at the
        marked depth below the ground there at reset. After: 1 m above the
        centre of the truck's rim (where the bucket is emptied).
        """
        owed = self.p.success_volume - world.truck_soil
        if owed > 0.0 and world.fill < owed:
            return self._dig_goal
        t = world.scene.truck
        return (t.cx, t.cy, t.height + 1.0)

    def _begin(self, world: Any, buf: np.ndarray) -> None:
        zone = world.scene.zone
        buf[self.layout["zone"]] = zone.as_array()
        self._zone_mask = zone.mask(0.5 * world.m.bucket_width)
        self.outside_zone = 0.0
        self._last = (world.fill, world.truck_soil, world.spill)
        self.dig_fill = 0.0
        r = 0.5 * (zone.r_near + zone.r_far)
        x, y = r * math.cos(zone.azimuth), r * math.sin(zone.azimuth)
        self._dig_goal = (x, y, world.terrain.height_at(x, y) - zone.depth)
        self._tip_prev = tuple(world.tip)

    def _write(self, world: Any, buf: np.ndarray) -> None:
        buf[self._soil_index] = world.truck_soil

    def evaluate(self, world: Any, events: None) -> Outcome:
        if world.taken > 0.0:
            i0, j0, cut = world.terrain.last_cut
            inside = self._zone_mask[i0 : i0 + cut.shape[0], j0 : j0 + cut.shape[1]]
            self.outside_zone += float(cut[~inside].sum()) * world.terrain.cell**2
        w, p = self.w, self.p
        fill0, truck0, spill0 = self._last
        self._last = (world.fill, world.truck_soil, world.spill)
        tip0, self._tip_prev = self._tip_prev, tuple(world.tip)
        goal = self.subgoal(world)
        self.dig_fill = max(self.dig_fill, world.fill)
        success = (
            world.truck_soil >= p.success_volume and world.fill < 0.02 * world.m.bucket_capacity
        )
        contact = world.contact
        costly = contact or world.pipe_clear < p.pipe_safety
        terms = {
            "delivered": w["delivered"] * (world.truck_soil - truck0),
            "fill": w["fill"] * (world.fill - fill0),
            "spill": -w["spill"] * (world.spill - spill0),
            "clearance": -w["clearance"] if costly else 0.0,
            "contact": -w["contact"] if contact else 0.0,
            "time": -w["time"],
            "success": w["success"] if success else 0.0,
            "approach": w["approach"] * (math.dist(tip0, goal) - math.dist(world.tip, goal)),
        }
        info = self._common_measures(world)  # and task_measures:
        info["dig_fill"], info["outside_zone"] = float(self.dig_fill), float(self.outside_zone)
        return Outcome(terms, success, 1.0 if costly else 0.0, info, success or contact)

    def task_measures(self, world: Any) -> dict[str, Any]:
        return {"dig_fill": float(self.dig_fill), "outside_zone": float(self.outside_zone)}


TASKS = {"reach": ReachTask, "dig": DigTask}
