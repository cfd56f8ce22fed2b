"""The excavator environments: reach a bucket pose, and one full dig cycle.

Both drive the 20 t backhoe of :mod:`.config` (kinematics of the paper,
:mod:`.kinematics`) with the machinery of :class:`.base.ExcavatorBase`; the
observation layout is in :mod:`.observation`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from motiongym.envs.excavator.base import ExcavatorBase
from motiongym.envs.excavator.config import Machine
from motiongym.envs.excavator.task import Scene, sample_dig_scene, sample_reach_scene

_COMMON_INFO = """
    Keyword arguments: ``machine`` (dict of :class:`Machine` overrides),
    ``dt`` (s), ``pipe_safety`` (m), the task's tolerances, the reward
    weights, ``render_mode`` ("rgb_array"), ``render_size`` (rows, columns).

    ``info`` (every step and reset): ``is_success``; ``cost`` (1.0 on a step
    where the pipe clearance is below ``pipe_safety``, 0.5 m by default: the
    hand-dig tolerance zone each side of a located utility, or where the arm
    touches the pipe or the truck); ``pipe_clearance``, ``truck_clearance``
    (m, surface to surface, exact below 1 m, a lower bound above);
    ``pipe_contact``, ``truck_contact`` (0/1); ``bucket_fill``,
    ``truck_soil``, ``spill`` (m3); ``elapsed`` (s); ``reward_<term>`` for
    every reward term (they sum to the reward).

    Termination: success, or contact with the pipe or the truck (clearance
    <= 0). Truncation: only by ``max_episode_steps`` (TimeLimit).

    Reset options: ``q0`` (4 joint angles, rad, clipped to the joint ranges)
    instead of the ready pose ``Machine.q_ready`` (bucket curled, 2 m up).
"""


class ExcavatorReachEnv(ExcavatorBase):
    """Bring the bucket tip to a target pose (the paper's problem).

    A 20 t backhoe (boom 5.7 m, stick 2.9 m, bucket 1.5 m) starts in its ready
    pose; each episode samples a reachable target (tip position and bucket
    angle ``beta``), the ground, a buried pipe and a truck from the seed.

    Action (4,), float32 in [-1, 1]: joint rates of swing, boom, stick and
    bucket as fractions of the hydraulic limits ``rate_max`` (1.15, 0.6, 0.7,
    1.0 rad/s); one step is ``dt`` = 0.1 s. The ground is not carved here.

    Observation (58,), float32: see :mod:`motiongym.envs.excavator.observation`
    (q 0-3, qdot 4-7, tip 8-10, bucket angle 11, fill 12, ground profile
    13-36, target 37-40 [x, y, z, beta], target - tip 41-44 [dx, dy, dz,
    dbeta], truck 45-50, pipe 51-57).

    Reward terms (weights are keyword arguments of the same name):
    ``progress`` = progress * (e_prev - e) with ``e = |tip - target| (m) +
    |beta - beta*| (rad, 1 m per rad)``; ``clearance`` = -clearance on a step
    with cost; ``contact`` = -contact on contact; ``time`` = -time per step;
    ``success`` = +success on success; ``closeness`` = closeness *
    exp(-e / closeness_scale) every step, 0 in the registered ID: a dense
    shaping that training configurations switch on (``progress`` telescopes,
    so a policy parked 0.6 m short loses only 0.6 in all). It is positive and
    bounded, so ending an episode by a contact never pays, and a weight below
    ``success`` / episode length keeps hovering worth less than arriving. Success: tip within
    ``tolerance_position`` (m) and bucket angle within ``tolerance_angle``
    (rad). Extra ``info``: ``position_error`` (m), ``angle_error`` (rad).
    """

    __doc__ += (
        _COMMON_INFO
        + """
    Version history: v0 (initial).
    """
    )

    TASK = "reach"
    CARVE = False
    REWARD_TERMS = ("progress", "clearance", "contact", "time", "success", "closeness")
    metadata = {
        **ExcavatorBase.metadata,
        "info_measures": {
            "is_success": "last",
            "cost": "sum",
            "position_error": "last",
            "angle_error": "last",
            "pipe_clearance": "min",
            "truck_clearance": "min",
            "elapsed": "last",
        },
    }

    def __init__(
        self,
        machine: dict | Machine | None = None,
        dt: float = 0.1,
        pipe_safety: float = 0.5,
        tolerance_position: float = 0.05,  # m
        tolerance_angle: float = 0.05,  # rad
        progress: float = 1.0,
        clearance: float = 1.0,
        contact: float = 10.0,
        time: float = 0.01,
        success: float = 10.0,
        closeness: float = 0.0,
        closeness_scale: float = 0.5,  # m (and rad, 1 m per rad)
        render_mode: str | None = None,
        render_size: tuple[int, int] = (480, 640),
    ) -> None:
        super().__init__(machine, dt, pipe_safety, render_mode, render_size)
        self.tolerance_position = float(tolerance_position)
        self.tolerance_angle = float(tolerance_angle)
        self.weights = dict(
            progress=progress,
            clearance=clearance,
            contact=contact,
            time=time,
            success=success,
            closeness=closeness,
        )
        self.closeness_scale = float(closeness_scale)

    def _sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_reach_scene(rng, self.m)

    def _errors(self) -> tuple[float, float]:
        t = self.scene.target
        pos = math.dist(self.tip, (t[0], t[1], t[2]))
        ang = abs(math.remainder(self.beta - t[3], 2 * math.pi))
        return pos, ang

    def _task_obs(self, buf: np.ndarray) -> None:
        t, tip = self.scene.target, self.tip
        i = self._error_index
        buf[i] = t[0] - tip[0]
        buf[i + 1] = t[1] - tip[1]
        buf[i + 2] = t[2] - tip[2]
        buf[i + 3] = math.remainder(t[3] - self.beta, 2 * math.pi)

    def _task_reset(self) -> None:
        self._error_index = self.layout["target_error"].start
        self._obs[self.layout["target"]] = self.scene.target
        pos, ang = self._errors()
        self._err = pos + ang

    def _task_step(self) -> tuple[dict[str, float], bool, dict[str, Any]]:
        w = self.weights
        pos, ang = self._errors()
        err = pos + ang
        success = pos < self.tolerance_position and ang < self.tolerance_angle
        contact = self.pipe_clear <= 0.0 or self.truck_clear <= 0.0
        costly = contact or self.pipe_clear < self.pipe_safety
        terms = {
            "progress": w["progress"] * (self._err - err),
            "clearance": -w["clearance"] if costly else 0.0,
            "contact": -w["contact"] if contact else 0.0,
            "time": -w["time"],
            "success": w["success"] if success else 0.0,
            "closeness": w["closeness"] * math.exp(-err / self.closeness_scale),
        }
        self._err = err
        return terms, success, {"position_error": pos, "angle_error": ang}

    def _info(self, terms: dict[str, float], success: bool) -> dict[str, Any]:
        info = super()._info(terms, success)
        pos, ang = self._errors()
        info.update(position_error=float(pos), angle_error=float(ang))
        return info


class ExcavatorEnv(ExcavatorBase):
    """One full dig cycle: dig in the marked zone, lift, swing, dump into the truck.

    The same machine as :class:`ExcavatorReachEnv` on ground that the bucket
    carves (:mod:`.soil`: height map, bucket fill up to 1.0 m3, resistance of
    the simplified fundamental earthmoving equation slowing the joints in
    soil). Each episode samples the ground, a dig zone (a strip one bucket
    wide along a ray, with a marked depth), a buried pipe (often right under
    the zone) and a truck body on one side.

    Action (4,), float32 in [-1, 1]: joint rates as fractions of ``rate_max``;
    ``dt`` = 0.1 s.

    Observation (56,), float32: q 0-3, qdot 4-7, tip 8-10, bucket angle 11,
    fill 12, ground profile 13-36 (in the boom plane), zone 37-41 [near x, y,
    far x, y, depth], truck soil 42, truck 43-48, pipe 49-55 (see
    :mod:`motiongym.envs.excavator.observation`).

    Reward terms (weights are keyword arguments of the same name):
    ``delivered`` = delivered * soil added to the truck (m3); ``fill`` = fill *
    change of the bucket fill (m3; a potential, it sums to zero over a
    completed cycle); ``spill`` = -spill * soil spilled (m3);
    ``clearance`` = -clearance on a step with cost; ``contact`` = -contact
    on contact; ``time`` = -time per step; ``success`` = +success on success;
    ``approach`` = approach * (|tip_prev - g| - |tip - g|), the step's
    progress (m) toward the subgoal g of :meth:`subgoal`, 0 in the registered
    ID: a dense shaping for training (configs) that draws the bucket into the
    middle of the zone at the marked depth while it holds less than the soil
    still owed to the truck, and 1 m over the truck bed's centre after. Both
    distances are to the current subgoal, so the term is a potential
    difference within each phase: it never pays to end an episode early or
    to hover.
    Success: at least ``success_volume`` m3 in the truck and the bucket empty
    (below 2 % of its capacity) - the cycle is over. Extra ``info``:
    ``dig_fill`` (m3, the largest bucket fill so far: the fill at the end of
    the dig); ``outside_zone`` (m3 dug outside the marked strip, which is the
    zone widened by 0.15 m on every side; reported, not penalised).
    """

    __doc__ += (
        _COMMON_INFO
        + """
    Version history: v0 (initial).
    """
    )

    TASK = "dig"
    CARVE = True
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
    metadata = {
        **ExcavatorBase.metadata,
        "info_measures": {
            "is_success": "last",
            "cost": "sum",
            "dig_fill": "max",
            "outside_zone": "last",
            "truck_soil": "last",
            "spill": "last",
            "pipe_contact": "max",
            "pipe_clearance": "min",
            "truck_clearance": "min",
            "elapsed": "last",
        },
    }

    def __init__(
        self,
        machine: dict | Machine | None = None,
        dt: float = 0.1,
        pipe_safety: float = 0.5,
        success_volume: float = 0.3,  # m3
        delivered: float = 10.0,
        fill: float = 2.0,
        spill: float = 5.0,
        clearance: float = 1.0,
        contact: float = 10.0,
        time: float = 0.01,
        success: float = 10.0,
        approach: float = 0.0,
        render_mode: str | None = None,
        render_size: tuple[int, int] = (480, 640),
    ) -> None:
        super().__init__(machine, dt, pipe_safety, render_mode, render_size)
        self.success_volume = float(success_volume)
        self.weights = dict(
            delivered=delivered,
            fill=fill,
            spill=spill,
            clearance=clearance,
            contact=contact,
            time=time,
            success=success,
            approach=approach,
        )

    def _sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_dig_scene(rng, self.m)

    def subgoal(self) -> tuple[float, float, float]:
        """The point the ``approach`` term draws the bucket tip to (m, frame M).

        While the bucket holds less than the soil still owed to the truck
        (``success_volume`` - truck soil): the middle of the dig zone, at the
        marked depth below the ground there at reset. After: 1 m above the
        centre of the truck's rim (where the bucket is emptied).
        """
        owed = self.success_volume - self.truck_soil
        if owed > 0.0 and self.fill < owed:
            return self._dig_goal
        t = self.scene.truck
        return (t.cx, t.cy, t.height + 1.0)

    def _task_reset(self) -> None:
        self._obs[self.layout["zone"]] = self.scene.zone.as_array()
        self._soil_index = self.layout["truck_soil"].start
        self._zone_mask = self.scene.zone.mask(0.5 * self.m.bucket_width)
        self.outside_zone = 0.0
        self._last = (self.fill, self.truck_soil, self.spill)
        self.dig_fill = 0.0
        zone = self.scene.zone
        r = 0.5 * (zone.r_near + zone.r_far)
        x, y = r * math.cos(zone.azimuth), r * math.sin(zone.azimuth)
        self._dig_goal = (x, y, self.terrain.height_at(x, y) - zone.depth)
        self._tip_prev = tuple(self.tip)

    def _on_cut(self, volume: float) -> None:
        i0, j0, cut = self.terrain.last_cut
        inside = self._zone_mask[i0 : i0 + cut.shape[0], j0 : j0 + cut.shape[1]]
        self.outside_zone += float(cut[~inside].sum()) * self.terrain.cell**2

    def _task_obs(self, buf: np.ndarray) -> None:
        buf[self._soil_index] = self.truck_soil

    def _task_step(self) -> tuple[dict[str, float], bool, dict[str, Any]]:
        w = self.weights
        fill0, truck0, spill0 = self._last
        self._last = (self.fill, self.truck_soil, self.spill)
        tip0, self._tip_prev = self._tip_prev, tuple(self.tip)
        goal = self.subgoal()
        self.dig_fill = max(self.dig_fill, self.fill)
        success = (
            self.truck_soil >= self.success_volume and self.fill < 0.02 * self.m.bucket_capacity
        )
        contact = self.pipe_clear <= 0.0 or self.truck_clear <= 0.0
        costly = contact or self.pipe_clear < self.pipe_safety
        terms = {
            "delivered": w["delivered"] * (self.truck_soil - truck0),
            "fill": w["fill"] * (self.fill - fill0),
            "spill": -w["spill"] * (self.spill - spill0),
            "clearance": -w["clearance"] if costly else 0.0,
            "contact": -w["contact"] if contact else 0.0,
            "time": -w["time"],
            "success": w["success"] if success else 0.0,
            "approach": w["approach"] * (math.dist(tip0, goal) - math.dist(self.tip, goal)),
        }
        return terms, success, {}

    def _info(self, terms: dict[str, float], success: bool) -> dict[str, Any]:
        info = super()._info(terms, success)
        info["dig_fill"] = float(self.dig_fill)
        info["outside_zone"] = float(self.outside_zone)
        return info
