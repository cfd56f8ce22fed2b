"""The observation vector's layout, shared by the environments and the policies.

One flat float32 ``Box`` described by a :class:`motiongym.envs.core.ObservationLayout`
per task (:func:`observation_layout`); a scripted policy parses an observation
by name (``obs[layout("dig")["tip"]]``) and never by magic index. All
positions are in the world frame O (x ahead of the machine at reset, z up,
origin where the swing axis meets the ground), in m; angles in rad. On level
ground (every v0 ID, and v1 with ``slope=0``) frame O is the base frame M.

Fields, in order (``profile`` ... ``pipe`` after the task's fields):

===========  =====  ==========================================================
name         size   meaning
===========  =====  ==========================================================
q            4      joint angles swing, boom, stick, bucket (rad, DH)
qdot         4      joint rates (rad/s)
tip          3      bucket cutting-edge centre (m)
bucket       1      bucket angle ``beta = q2 + q3 + q4`` (rad)
fill         1      soil in the bucket (m3; v1: loose volume)
profile      24     ground height in the boom plane at 1.0, 1.4, ... 10.2 m
                    from the swing axis along azimuth ``q1`` (m)
target       4      (reach) target tip x, y, z (m) and bucket angle (rad)
target_error 4      (reach) target - tip (m) and target - bucket angle (rad, in
                    [-pi, pi]), as Reacher's fingertip - target
zone         5      (dig) zone near end x, y, far end x, y (m), marked depth (m)
truck_soil   1      (dig) soil delivered into the truck (m3; v1: loose volume)
truck        6      truck footprint centre x, y (m), yaw (rad), half length,
                    half width, rim height (m)
pipe         7      pipe centre-line end a x, y, z, end b x, y, z, radius (m)
base         2      (v1 only) base roll, pitch (rad): the paper's H_M^O (eq. 1-2)
===========  =====  ==========================================================
"""

from __future__ import annotations

import functools
import math

import numpy as np

from motiongym.envs.core import ObservationLayout
from motiongym.envs.excavator.config import Machine

PROFILE_RADII = 1.0 + 0.4 * np.arange(24)  # (24,) m: 1.0 to 10.2 m, the machine's reach

_COMMON = (
    ("q", 4, "rad", "joint angles swing, boom, stick, bucket (DH)"),
    ("qdot", 4, "rad/s", "joint rates"),
    ("tip", 3, "m", "bucket cutting-edge centre"),
    ("bucket", 1, "rad", "bucket angle beta = q2 + q3 + q4"),
    ("fill", 1, "m3", "soil in the bucket"),
    ("profile", 24, "m", "ground height in the boom plane at 1.0, 1.4, ... 10.2 m"),
)
_TASK = {
    "reach": (
        ("target", 4, "m, rad", "target tip x, y, z and bucket angle"),
        ("target_error", 4, "m, rad", "target - tip and target - bucket angle"),
    ),
    "dig": (
        ("zone", 5, "m", "zone near end x, y, far end x, y, marked depth"),
        ("truck_soil", 1, "m3", "soil delivered into the truck"),
    ),
}
_SCENE = (
    ("truck", 6, "m, rad", "truck centre x, y, yaw, half length, half width, rim height"),
    ("pipe", 7, "m", "pipe end a x, y, z, end b x, y, z, radius"),
)
_V1 = (("base", 2, "rad", "base roll, pitch (paper eq. 1-2)"),)
TASKS = tuple(_TASK)
PHYSICS = ("v0", "v1")


@functools.lru_cache(maxsize=8)
def observation_layout(task: str, physics: str = "v0") -> ObservationLayout:
    """The :class:`ObservationLayout` of ``task`` ("reach" or "dig") under ``physics``."""
    if task not in _TASK:
        raise ValueError(f"task must be one of {', '.join(TASKS)}, got {task!r}")
    if physics not in PHYSICS:
        raise ValueError(f"physics must be one of {', '.join(PHYSICS)}, got {physics!r}")
    extra = _V1 if physics == "v1" else ()
    return ObservationLayout((*_COMMON, *_TASK[task], *_SCENE, *extra))


def layout(task: str, physics: str = "v0") -> dict[str, slice]:
    """``{name: slice}`` of the observation of ``task`` (the layout's slices)."""
    return observation_layout(task, physics).slices


def bounds(task: str, m: Machine, physics: str = "v0") -> tuple[np.ndarray, np.ndarray]:
    """Finite ``(low, high)`` float32 bounds of the observation of ``task``."""
    lay = observation_layout(task, physics)
    big = (-30.0, 30.0)
    limits = {
        "q": (m.q_min, m.q_max),
        "qdot": ([-r for r in m.rate_max], m.rate_max),
        "tip": big,
        "bucket": (-3 * math.pi, 3 * math.pi),
        "fill": (0.0, m.bucket_capacity),
        "profile": (-10.0, 10.0),
        "target": ([-30.0, -30.0, -30.0, -3 * math.pi], [30.0, 30.0, 30.0, 3 * math.pi]),
        "target_error": ([-60.0, -60.0, -60.0, -math.pi], [60.0, 60.0, 60.0, math.pi]),
        "zone": ([-30.0] * 4 + [0.0], [30.0] * 4 + [10.0]),
        "truck_soil": (0.0, 100.0),
        "truck": (
            [-30.0, -30.0, -2 * math.pi, 0.0, 0.0, 0.0],
            [30.0, 30.0, 2 * math.pi, 10.0, 10.0, 10.0],
        ),
        "pipe": ([-30.0] * 6 + [0.0], [30.0] * 6 + [5.0]),
        "base": (-0.5, 0.5),
    }
    return lay.bounds({f.name: limits[f.name] for f in lay.fields})
