"""Bucket-path generation for one dig cycle (the step the paper announces next).

The paper ends with "the next study will build the generation of the
bucket-tip path for digging"; this module is our version of it. A path is a
list of bucket poses (tip position in frame M, bucket angle ``beta``), each
turned into joint angles by the Newton-Raphson IK (eq. 9-13) at the policy.

Phases and bucket angles (``beta``: elevation of the pin-to-tip axis; the
bucket opening faces ``(sin beta, -cos beta)`` in the boom plane):

* approach: tip 2 m above the far end of the zone, bucket open
  (``beta = -1.4``, teeth down and slightly out);
* penetrate: down to the cut depth ``d`` 0.4 m inside the far end;
* drag: toward the machine at ``surface(r) - d`` in 0.25 m steps, the bucket
  turning to ``beta = -1.75`` (opening toward the machine);
* curl: bucket to ``beta_carry = -2.6`` (opening up) about its pin;
* lift: pin 0.5 m inwards and up until the tip is 0.8 m above the surface;
* carry: bucket pin over the truck's near half at the carry height
  ``rim + L4 + bucket radius + 0.3 m`` (the opened bucket then clears the rim);
* swing: the same pose at the truck's azimuth (only the swing joint moves);
* dump: bucket pin fixed, ``beta = -0.35`` (opening down: the soil pours).

Attitude: wherever the tip is in the soil, it moves with the bucket opening
ahead (opening normal . motion > 0): down and inwards while penetrating,
inwards while dragging, along the opening while curling about the pin
(curling turns the tip exactly along the opening normal). Nothing cuts heel
first or sideways (tested).

Pipe: the cut depth is the zone's marked depth, or less where the pipe runs
within reach of the strip in plan: then the bucket's lowest point (tip minus
the bucket radius) stays ``safety + 0.25 m`` above the pipe's top.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from motiongym.envs.excavator.config import Machine
from motiongym.envs.geometry import closest_points_between_segments

BETA_OPEN = -1.4
BETA_DRAG = -1.75
BETA_CARRY = -2.6
BETA_DUMP = -0.35
PIPE_MARGIN = 0.25  # m beyond the safety distance
DRAG_STEP = 0.25  # m
CURL_STEP = 0.25  # rad


@dataclass(frozen=True)
class Style:
    """How the bucket enters and leaves the soil (one per physics).

    ``penetration_angle``: None for the v0 entry (straight from 0.3 m above
    the far end to the cut depth 0.4 m inside it: a steep plunge), else the
    descent (rad below horizontal) of a ramp from the surface at the far end
    to the cut depth. ``beta_open``: bucket angle while entering.
    ``r_stop``: the drag ends no nearer the swing axis than this (m).
    ``curl_rise``: the pin rises this much per radian of curl (m/rad), in
    steps of ``CURL_STEP`` (0: one waypoint, the pin fixed).
    ``lift_inwards``: the pin moves this much toward the machine while lifting (m).
    """

    penetration_angle: float | None = None
    beta_open: float = -1.4
    r_stop: float = 0.0
    curl_rise: float = 0.0
    lift_inwards: float = 0.5


V0_STYLE = Style()
# Physics v1: a bucket's shell may not go deeper into the ground than it is, and
# only the edge moving within 60 deg of the opening cuts. Entering on a 25 deg
# ramp with the teeth turned out (beta -1.35: the opening 13 deg below the
# horizontal, short of pouring at 17 deg; the shell's underside 0.34 m above
# the edge and 0.49 m behind it, a 35 deg slope) keeps the shell over the ramp
# the edge has cut; the pin rises while the
# bucket curls (the shell swings down about the pin otherwise); the drag stops
# where the curled bucket (its tip 1 m nearer the machine) stays clear of the
# tracks' front (2.25 m) by 1 m.
V1_STYLE = Style(
    penetration_angle=math.radians(25.0),
    beta_open=-1.35,
    r_stop=4.3,
    curl_rise=0.9,
    lift_inwards=0.0,
)


@dataclass(frozen=True)
class Waypoint:
    """A bucket pose along the cycle."""

    phase: str
    tip: tuple[float, float, float]  # m, frame M
    beta: float  # rad


def allowed_depth(
    zone: np.ndarray, pipe: np.ndarray, m: Machine, safety: float, surface: float = 0.0
) -> float:
    """Deepest cut (m below ``surface``) that keeps the bucket clear of the pipe.

    Args:
        zone: ``[x_near, y_near, x_far, y_far, depth]`` (the observation's slice).
        pipe: ``[ax, ay, az, bx, by, bz, radius]``.
        m: the machine (bucket width and radius).
        safety: the pipe safety distance (m).
        surface: the ground height over the zone (m).
    """
    near, far = zone[0:2], zone[2:4]
    a, b, radius = pipe[0:2], pipe[3:5], float(pipe[6])
    plan, _, _ = closest_points_between_segments(near, far, a, b)
    r_bucket = m.link_radius[2]
    reach = float(plan) - 0.5 * m.bucket_width - r_bucket - radius
    if reach > safety + PIPE_MARGIN:
        return float(zone[4])
    top = max(float(pipe[2]), float(pipe[5])) + radius
    lowest_tip = top + r_bucket + safety + PIPE_MARGIN
    return float(max(min(zone[4], surface - lowest_tip), 0.0))


def dig_path(
    azimuth: float,
    r_near: float,
    r_far: float,
    depth: float,
    surface,
    style: Style = V0_STYLE,
) -> list[Waypoint]:
    """Approach, penetrate and drag waypoints along the ray at ``azimuth``.

    ``surface(r)`` gives the ground height at radius ``r`` on that ray (m).
    """
    c, s = math.cos(azimuth), math.sin(azimuth)
    b_open = style.beta_open

    def at(r: float, z: float) -> tuple[float, float, float]:
        return (c * r, s * r, z)

    path = [
        Waypoint("approach", at(r_far, surface(r_far) + 2.0), b_open),
        Waypoint("approach", at(r_far, surface(r_far) + 0.3), b_open),
    ]
    if style.penetration_angle is None:
        start = r_far - 0.4
        path.append(Waypoint("penetrate", at(start, surface(start) - depth), b_open))
    else:
        run = depth / math.tan(style.penetration_angle)
        start = r_far - run
        n = max(int(math.ceil(math.hypot(run, depth) / DRAG_STEP)), 1)
        for k in range(1, n + 1):
            r = r_far - run * k / n
            path.append(Waypoint("penetrate", at(r, surface(r) - depth * k / n), b_open))
    end = max(r_near, style.r_stop)
    n = max(int(math.ceil((start - end) / DRAG_STEP)), 1)
    for k in range(1, n + 1):
        r = start - (start - end) * k / n
        beta = b_open + (BETA_DRAG - b_open) * k / n
        path.append(Waypoint("drag", at(r, surface(r) - depth), beta))
    return path


def curl_lift_path(
    tip: np.ndarray,
    beta: float,
    surface_here: float,
    m: Machine,
    style: Style = V0_STYLE,
    up: tuple[float, float, float] = (0.0, 0.0, 1.0),
) -> list[Waypoint]:
    """Curl about the bucket pin, then lift the pin (``style``: inwards) and up.

    The pin (``tip - L4 [cos beta, sin beta]`` in the boom plane) rises
    ``style.curl_rise`` per radian while the bucket turns to ``beta_carry``
    (the policy clips joint goals to the joint ranges); then it moves
    ``style.lift_inwards`` toward the machine and up until the tip is 0.8 m
    above the surface. "Up" is ``up`` (unit, frame M): on a slope the world's
    vertical, along which the trench's walls stand (rising along the tilted
    frame's z would carry the bucket sideways into them).
    """
    x, y, z = (float(v) for v in tip)
    r = math.hypot(x, y)
    c, s = (x / r, y / r) if r > 1e-9 else (1.0, 0.0)
    pin = np.array([x, y, z]) - m.L4 * np.array(
        [c * math.cos(beta), s * math.cos(beta), math.sin(beta)]
    )
    up_v = np.asarray(up, float)

    def tip_at(p: np.ndarray, b: float) -> tuple[float, float, float]:
        return (
            float(p[0] + c * m.L4 * math.cos(b)),
            float(p[1] + s * m.L4 * math.cos(b)),
            float(p[2] + m.L4 * math.sin(b)),
        )

    turn = abs(BETA_CARRY - beta)
    n = max(int(math.ceil(turn / CURL_STEP)), 1) if style.curl_rise > 0.0 else 1
    curl = []
    for k in range(1, n + 1):
        b = beta + (BETA_CARRY - beta) * k / n
        curl.append(Waypoint("curl", tip_at(pin + style.curl_rise * turn * k / n * up_v, b), b))
    curled = pin + style.curl_rise * turn * up_v
    rise = max(0.5, surface_here + 0.8 - m.L4 * math.sin(BETA_CARRY) - curled[2]) / up_v[2]
    lift = curled + rise * up_v - style.lift_inwards * np.array([c, s, 0.0])
    return [*curl, Waypoint("lift", tip_at(lift, BETA_CARRY), BETA_CARRY)]


def carry_dump_path(
    dig_azimuth: float, truck: np.ndarray, m: Machine
) -> tuple[list[Waypoint], float]:
    """Carry (at the dig azimuth), swing (to the truck), dump; also the truck's azimuth.

    The bucket pin is placed 0.35 m inside the truck's centre radius, at
    ``rim + L4 + r_bucket + 0.3``; the tip follows from ``beta_carry``.
    """
    cx, cy, rim = float(truck[0]), float(truck[1]), float(truck[5])
    r_truck = math.hypot(cx, cy)
    azimuth = math.atan2(cy, cx)
    pin_r = r_truck - 0.35
    pin_z = rim + m.L4 + m.link_radius[2] + 0.3
    tip_r = pin_r + m.L4 * math.cos(BETA_CARRY)
    tip_z = pin_z + m.L4 * math.sin(BETA_CARRY)
    dump_r = pin_r + m.L4 * math.cos(BETA_DUMP)
    dump_z = pin_z + m.L4 * math.sin(BETA_DUMP)

    def at(phi: float, r: float, z: float) -> tuple[float, float, float]:
        return (math.cos(phi) * r, math.sin(phi) * r, z)

    return [
        Waypoint("carry", at(dig_azimuth, tip_r, tip_z), BETA_CARRY),
        Waypoint("swing", at(azimuth, tip_r, tip_z), BETA_CARRY),
        Waypoint("dump", at(azimuth, dump_r, dump_z), BETA_DUMP),
    ], azimuth
