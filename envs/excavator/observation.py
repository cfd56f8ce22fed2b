"""The observation vector's layout, shared by the environments and the policies.

One flat float32 ``Box``; :func:`layout` names its slices, so a scripted
policy parses an observation by name (``obs[LAYOUT["tip"]]``) and never by
magic index. All positions are in the base frame M (x ahead, z up, origin on
the swing axis at ground level), in m; angles in rad.

===========  =====  ==========================================================
name         size   meaning
===========  =====  ==========================================================
q            4      joint angles swing, boom, stick, bucket (rad, DH)
qdot         4      joint rates (rad/s)
tip          3      bucket cutting-edge centre (m)
bucket       1      bucket angle ``beta = q2 + q3 + q4`` (rad)
fill         1      soil in the bucket (m3)
profile      24     ground height in the boom plane at 1.0, 1.4, ... 10.2 m
                    from the swing axis along azimuth ``q1`` (m)
target       4      (reach) target tip x, y, z (m) and bucket angle (rad)
target_error 4      (reach) target - tip (m) and target - bucket angle (rad, in
                    [-pi, pi]), as Reacher's fingertip - target
zone         5      (dig) zone near end x, y, far end x, y (m), marked depth (m)
truck_soil   1      (dig) soil delivered into the truck (m3)
truck        6      truck footprint centre x, y (m), yaw (rad), half length,
                    half width, rim height (m)
pipe         7      pipe centre-line end a x, y, z, end b x, y, z, radius (m)
===========  =====  ==========================================================
"""

from __future__ import annotations

import math

import numpy as np

from motiongym.envs.excavator.config import Machine

PROFILE_RADII = 1.0 + 0.4 * np.arange(24)  # (24,) m: 1.0 to 10.2 m, the machine's reach

_COMMON = (("q", 4), ("qdot", 4), ("tip", 3), ("bucket", 1), ("fill", 1), ("profile", 24))
_TASK = {"reach": (("target", 4), ("target_error", 4)), "dig": (("zone", 5), ("truck_soil", 1))}
_SCENE = (("truck", 6), ("pipe", 7))
TASKS = tuple(_TASK)


def layout(task: str) -> dict[str, slice]:
    """``{name: slice}`` of the observation of ``task`` ("reach" or "dig")."""
    if task not in _TASK:
        raise ValueError(f"unknown task {task!r}; valid: {', '.join(TASKS)}")
    out, start = {}, 0
    for name, size in (*_COMMON, *_TASK[task], *_SCENE):
        out[name] = slice(start, start + size)
        start += size
    return out


def bounds(task: str, m: Machine) -> tuple[np.ndarray, np.ndarray]:
    """Finite ``(low, high)`` float32 bounds of the observation of ``task``."""
    lay = layout(task)
    size = max(s.stop for s in lay.values())
    low = np.full(size, -30.0, dtype=np.float32)
    high = np.full(size, 30.0, dtype=np.float32)

    def put(name: str, lo, hi) -> None:
        low[lay[name]], high[lay[name]] = lo, hi

    put("q", m.q_min, m.q_max)
    put("qdot", [-r for r in m.rate_max], m.rate_max)
    put("bucket", -3 * math.pi, 3 * math.pi)
    put("fill", 0.0, m.bucket_capacity)
    put("profile", -10.0, 10.0)
    if task == "reach":
        put("target", [-30.0, -30.0, -30.0, -3 * math.pi], [30.0, 30.0, 30.0, 3 * math.pi])
        put("target_error", [-60.0, -60.0, -60.0, -math.pi], [60.0, 60.0, 60.0, math.pi])
    else:
        put("zone", [-30.0] * 4 + [0.0], [30.0] * 4 + [10.0])
        put("truck_soil", 0.0, 100.0)
    put(
        "truck",
        [-30.0, -30.0, -2 * math.pi, 0.0, 0.0, 0.0],
        [30.0, 30.0, 2 * math.pi, 10.0, 10.0, 10.0],
    )
    put("pipe", [-30.0] * 6 + [0.0], [30.0] * 6 + [5.0])
    return low, high
