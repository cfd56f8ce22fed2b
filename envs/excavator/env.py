"""The excavator environments: reach a bucket pose, and one full dig cycle.

Each is a :class:`motiongym.envs.core.SystemEnv`: a world
(:class:`.world.ExcavatorWorld`, physics "v0", or
:class:`.world_v1.ExcavatorWorldV1`, physics "v1") and a task
(:mod:`.task`); the parameters are :mod:`.params`, the observation layout
:mod:`.observation`.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from motiongym.envs.actions import checked_box_action
from motiongym.envs.core import ArgumentError, SystemEnv
from motiongym.envs.excavator.config import Machine
from motiongym.envs.excavator.params import DigParams, ExcavatorParams, ReachParams
from motiongym.envs.excavator.task import DigTask, ExcavatorTask, ReachTask
from motiongym.envs.excavator.world import ExcavatorWorld
from motiongym.envs.layout import ObservationLayout

_COMMON_INFO = """
    Keyword arguments (:mod:`motiongym.envs.excavator.params`, every one
    checked at construction, limits in its table): ``machine`` (dict of
    :class:`Machine` overrides), ``dt`` (s), ``pipe_safety`` (m),
    ``physics`` ("v0" or "v1"), ``slope`` (rad, v1), the task's tolerances,
    the reward weights (magnitudes in [0, 1e6]: a cost term is subtracted),
    ``render_mode`` ("rgb_array", or "human": a window, see
    :mod:`motiongym.envs.rendering`), ``render_size`` (rows, columns of a
    frame, each in [16, 2048]; default (480, 640)).

    ``info`` (every step and reset): ``is_success``; ``cost`` (1.0 on a step
    where the pipe clearance is below ``pipe_safety``, 0.5 m by default: the
    hand-dig tolerance zone each side of a located utility, or where the arm
    touches the pipe or the truck); ``pipe_clearance``, ``truck_clearance``
    (m, surface to surface, exact below 1 m, a lower bound above);
    ``pipe_contact``, ``truck_contact`` (0/1); ``bucket_fill``,
    ``truck_soil``, ``spill`` (m3); ``elapsed`` (s); ``reward_<term>`` for
    every reward term (they sum to the reward). Physics v1 adds the keys of
    :meth:`ExcavatorWorldV1.measures`.

    Termination: success, or contact with the pipe or the truck (clearance
    <= 0; v1: or with the machine itself). Truncation: only by
    ``max_episode_steps`` (TimeLimit).

    Actions: exactly what the Box accepts, shape (4,), finite; values outside
    [-1, 1] are clipped (Gymnasium's Box convention); a wrong shape or a
    non-finite entry is a ``ValueError``. ``step()`` / ``render()`` before
    ``reset()``: ``RuntimeError``.

    Reset options: ``start`` (4 finite joint angles, rad, clipped to the
    joint ranges) instead of the ready pose ``Machine.q_ready`` (bucket
    curled, 2 m up); ``q0`` is its deprecated name (warns once).
"""

_FLOAT32 = np.dtype(np.float32)
_ACTION_SPACE = "Box(-1.0, 1.0, (4,), float32): swing, boom, stick, bucket rates"


def _checked_action(action: Any) -> list[float]:
    """The action as 4 floats: real numbers only (no complex, text or objects), shape
    (4,), finite; values outside [-1, 1] are clipped by the world (Box convention)."""
    if type(action) is np.ndarray and action.dtype == _FLOAT32 and action.shape == (4,):
        values = action.tolist()  # the space's own type: the checks below in short
        if math.isfinite(values[0] + values[1] + values[2] + values[3]):
            return values
    kind = np.asarray(action).dtype.kind if not isinstance(action, str) else "U"
    if kind not in "biuf":
        raise ArgumentError(f"action must be an array in {_ACTION_SPACE}, got {action!r}")
    return checked_box_action(action, (4,), _ACTION_SPACE).tolist()


class ExcavatorBase(SystemEnv):
    """Shared wiring; see :class:`ExcavatorReachEnv` and :class:`ExcavatorEnv`."""

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 10}
    Params: ClassVar[type[ExcavatorParams]] = ReachParams
    TASK: ClassVar[type[ExcavatorTask]] = ReachTask
    ACTION_MEANING = _ACTION_SPACE
    params: ExcavatorParams
    world: ExcavatorWorld
    task: ExcavatorTask
    # The fast check of an action (no call through the base's generic one).
    check_action = staticmethod(_checked_action)

    def make_world(self, params: ExcavatorParams) -> ExcavatorWorld:
        if params.physics == "v1":
            from motiongym.envs.excavator.world_v1 import ExcavatorWorldV1

            return ExcavatorWorldV1(params, carve=self.TASK.CARVE)
        return ExcavatorWorld(params, carve=self.TASK.CARVE)

    def make_task(self, params: ExcavatorParams) -> ExcavatorTask:
        return self.TASK(params)

    @property
    def m(self) -> Machine:
        """The machine (``params.machine``)."""
        return self.params.machine

    @property
    def dt(self) -> float:
        """The control period (s)."""
        return self.params.dt

    @property
    def layout(self) -> ObservationLayout:
        """The observation's layout (:func:`.observation.observation_layout`)."""
        return self.task.layout


class ExcavatorReachEnv(ExcavatorBase):
    """Bring the bucket tip to a target pose (the paper's problem).

    A 20 t backhoe (boom 5.7 m, stick 2.9 m, bucket 1.5 m) starts in its ready
    pose; each episode samples a reachable target (tip position and bucket
    angle ``beta``), the ground, a buried pipe and a truck from the seed.

    Action (4,), float32 in [-1, 1]: joint rates of swing, boom, stick and
    bucket as fractions of the hydraulic limits ``rate_max`` (1.15, 0.6, 0.7,
    1.0 rad/s); one step is ``dt`` = 0.1 s (v1: through the hydraulics of
    :mod:`.hydraulics`). The ground is not carved here (v1: the arm still
    cannot enter it).

    Observation (58,; v1 60,), float32: see
    :mod:`motiongym.envs.excavator.observation` (q 0-3, qdot 4-7, tip 8-10,
    bucket angle 11, fill 12, ground profile 13-36, target 37-40 [x, y, z,
    beta], target - tip 41-44 [dx, dy, dz, dbeta], truck 45-50, pipe 51-57;
    v1: base roll, pitch 58-59).

    Reward terms (weights are keyword arguments of the same name):
    ``progress`` = progress * (e_prev - e) with ``e = |tip - target| (m) +
    |beta - beta*| (rad, 1 m per rad)``; ``clearance`` = -clearance on a step
    with cost; ``contact`` = -contact on contact; ``time`` = -time per step;
    ``success`` = +success on success; ``closeness`` = closeness *
    exp(-e / closeness_scale) every step, 0 in the registered ID: a dense
    shaping that training configurations switch on (``progress`` telescopes,
    so a policy parked 0.6 m short loses only 0.6 in all). It is positive and
    bounded, so ending an episode by a contact never pays, and a weight below
    ``success`` / episode length keeps hovering worth less than arriving.
    Success: tip within ``tolerance_position`` (m) and bucket angle within
    ``tolerance_angle`` (rad). Extra ``info``: ``position_error`` (m),
    ``angle_error`` (rad).
    """

    __doc__ += (
        _COMMON_INFO
        + """
    Version history: v0 (initial); v1 (physics "v1": collision bodies that
    contain the machine, ground and self-collision, hydraulics with rate,
    acceleration and pump-flow limits, the base on a slope up to
    ``slope`` = 0.1 rad).
    """
    )

    Params = ReachParams
    TASK = ReachTask
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
        "info_units": {
            "is_success": "rate",
            "cost": "steps",
            "position_error": "m",
            "angle_error": "rad",
            "pipe_clearance": "m",
            "truck_clearance": "m",
            "elapsed": "s",
        },
    }


class ExcavatorEnv(ExcavatorBase):
    """One full dig cycle: dig in the marked zone, lift, swing, dump into the truck.

    The same machine as :class:`ExcavatorReachEnv` on ground that the bucket
    carves (:mod:`.soil`: height map, bucket fill up to 1.0 m3, resistance of
    the simplified fundamental earthmoving equation slowing the joints in
    soil; v1: :mod:`.digging`). Each episode samples the ground, a dig zone (a
    strip one bucket wide along a ray, with a marked depth), a buried pipe
    (often right under the zone) and a truck body on one side.

    Action (4,), float32 in [-1, 1]: joint rates as fractions of ``rate_max``;
    ``dt`` = 0.1 s.

    Observation (56,; v1 58,), float32: q 0-3, qdot 4-7, tip 8-10, bucket
    angle 11, fill 12, ground profile 13-36 (in the boom plane), zone 37-41
    [near x, y, far x, y, depth], truck soil 42, truck 43-48, pipe 49-55; v1:
    base roll, pitch 56-57 (see :mod:`motiongym.envs.excavator.observation`).

    Reward terms (weights are keyword arguments of the same name):
    ``delivered`` = delivered * soil added to the truck (m3); ``fill`` = fill *
    change of the bucket fill (m3; a potential, it sums to zero over a
    completed cycle); ``spill`` = -spill * soil spilled (m3);
    ``clearance`` = -clearance on a step with cost; ``contact`` = -contact
    on contact; ``time`` = -time per step; ``success`` = +success on success;
    ``approach`` = ``approach * (|tip_prev - g| - |tip - g|)``, the step's
    progress (m) toward the subgoal g of :meth:`DigTask.subgoal`, 0 in the
    registered ID: a dense shaping for training (configs) that draws the
    bucket into the middle of the zone at the marked depth while it holds
    less than the soil still owed to the truck, and 1 m over the truck bed's
    centre after. Both distances are to the current subgoal, so the term is a
    potential difference within each phase: it never pays to end an episode
    early or to hover.
    Success: at least ``success_volume`` m3 in the truck and the bucket empty
    (below 2 % of its capacity) - the cycle is over. Extra ``info``:
    ``dig_fill`` (m3, the largest bucket fill so far: the fill at the end of
    the dig); ``outside_zone`` (m3 dug outside the marked strip, which is the
    zone widened by 0.15 m on every side; reported, not penalised).
    """

    __doc__ += (
        _COMMON_INFO
        + """
    Version history: v0 (initial); v1 (physics "v1": cutting by the edge
    moving forward only, earthmoving-equation resistance that stops the
    machine, no part but the cutting edge below the ground, a full bucket
    pushing soil, a swell factor (fill and truck soil in loose m3), collision
    bodies that contain the machine, self-collision, hydraulics with rate,
    acceleration and pump-flow limits, the base on a slope up to ``slope`` =
    0.1 rad).
    """
    )

    Params = DigParams
    TASK = DigTask
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
        "info_units": {
            "is_success": "rate",
            "cost": "steps",
            "dig_fill": "m3",
            "outside_zone": "m3",
            "truck_soil": "m3",
            "spill": "m3",
            "pipe_contact": "rate",
            "pipe_clearance": "m",
            "truck_clearance": "m",
            "elapsed": "s",
        },
    }

    task: DigTask

    def subgoal(self) -> tuple[float, float, float]:
        """:meth:`DigTask.subgoal` of the current state."""
        return self.task.subgoal(self.world)
