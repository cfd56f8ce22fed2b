"""The two excavator tasks: scenario, success, reward terms and task observation.

A task reads the world (:class:`.world.ExcavatorWorld`) and never changes it.
Each has ``NAME`` (its observation layout), ``CARVE`` (whether the ground is
worked), ``REWARD_TERMS``, ``sample_scene(rng)``, ``reset(world)`` (static
observation fields and per-episode state), ``step(world)`` -> ``(terms,
success, measures)``, ``write(world, buf)`` (the changing task fields of the
observation) and ``measures(world)`` (the task's ``info`` keys).
"""

from __future__ import annotations

import math
import struct
from typing import Any

import numpy as np

from motiongym.envs.excavator.params import DigParams, ReachParams
from motiongym.envs.excavator.scenes import Scene, sample_dig_scene, sample_reach_scene

# target_error written as float32 straight into the observation (NumPy's rounding).
_ERROR = struct.Struct("=4f")


class ReachTask:
    """Bring the bucket tip to a sampled target pose (see :class:`ExcavatorReachEnv`)."""

    NAME = "reach"
    CARVE = False
    REWARD_TERMS = ReachParams.REWARD_TERMS

    _errors: tuple[Any, Any, Any]  # (tip, beta, (pos, ang)) of the last errors() call

    def __init__(self, params: ReachParams, layout) -> None:
        self.p = params
        self.w = params.weights
        self.layout = layout
        self._error_offset = 4 * layout["target_error"].start  # bytes into the float32 buffer

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_reach_scene(rng, self.p.machine, self.p.slope)

    def errors(self, world) -> tuple[float, float]:
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

    def reset(self, world, buf: np.ndarray) -> None:
        buf[self.layout["target"]] = world.scene.target
        # The target as Python floats (the same doubles; NumPy scalars cost more per operation).
        self._target = tuple(float(x) for x in world.scene.target)
        self._errors = (None, None, None)
        pos, ang = self.errors(world)
        self._err = pos + ang

    def write(self, world, buf: np.ndarray) -> None:
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

    def step(self, world) -> tuple[dict[str, float], bool]:
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
        return terms, success

    def measures(self, world) -> dict[str, Any]:
        pos, ang = self.errors(world)
        return {"position_error": float(pos), "angle_error": float(ang)}


class DigTask:
    """Dig in the marked zone and deliver to the truck (see :class:`ExcavatorEnv`)."""

    NAME = "dig"
    CARVE = True
    REWARD_TERMS = DigParams.REWARD_TERMS

    def __init__(self, params: DigParams, layout) -> None:
        self.p = params
        self.w = params.weights
        self.layout = layout
        self._soil_index = layout["truck_soil"].start

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_dig_scene(rng, self.p.machine, self.p.slope)

    def subgoal(self, world) -> tuple[float, float, float]:
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

    def reset(self, world, buf: np.ndarray) -> None:
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

    def write(self, world, buf: np.ndarray) -> None:
        buf[self._soil_index] = world.truck_soil

    def step(self, world) -> tuple[dict[str, float], bool]:
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
        return terms, success

    def measures(self, world) -> dict[str, Any]:
        return {"dig_fill": float(self.dig_fill), "outside_zone": float(self.outside_zone)}


TASKS = {"reach": ReachTask, "dig": DigTask}
