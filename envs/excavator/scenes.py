"""Scenario sampling: ground, dig zone, reach target, pipe and truck.

Everything is drawn from the generator passed in (the environment's
``np_random``, seeded by ``reset(seed=...)``). Frame M: x ahead of the
machine, z up, the swing axis at the origin, the ground near z = 0.

* Ground: a 25 m x 22 m height map (0.1 m cells) around the machine: z = 0
  on the levelled pad (within 5 m of the swing axis), beyond it two gentle
  random undulations of at most 0.15 m in total.
* Dig zone: a strip one bucket width wide along a ray at azimuth
  ``[-35, 35] deg``, from ``r_far`` in ``[7.0, 8.5] m`` inwards over
  ``[2.5, 3.5] m``, to a marked depth ``[0.5, 1.0] m`` below the surface.
* Pipe: a 16 m straight pipe of radius 0.15 m, horizontal at a centre depth
  of ``[1.8, 3.0] m``, crossing the dig zone's ray at ``[r_near - 1, r_far + 2] m``
  at a random angle (so it is often right under the zone).
* Truck: a 5.0 m x 2.4 m body with its rim 2.8 m above the ground, on the
  left or right side at azimuth ``+-[75, 110] deg``, footprint centre at
  ``[5.5, 7.0] m`` from the swing axis, long axis tangential ``+-15 deg``.
* Reach target: the tip pose of joint angles drawn inside the joint ranges
  (so it is reachable), swing within ``+-60 deg``, tip between 0 and 2.5 m
  above the ground and at least 4 m out, the whole arm above ground, with
  the pipe at least 1 m below the tip and the arm at least 1 m from the truck.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from motiongym.envs.excavator.config import Machine
from motiongym.envs.excavator.kinematics import arm_points, base_rotation
from motiongym.envs.excavator.obstacles import Pipe, Truck, truck_clearance

GRID_ORIGIN = (-11.0, -11.0)  # m
GRID_SHAPE = (250, 220)  # cells
GRID_CELL = 0.1  # m
PAD_RADIUS = 5.0  # m


ZONE_MARGIN = 0.15  # m: the marked strip is this much wider and longer than the nominal one


@dataclass(frozen=True)
class DigZone:
    """A strip along the ray at ``azimuth`` from ``r_near`` to ``r_far`` (m), dug ``depth`` deep."""

    azimuth: float
    r_near: float
    r_far: float
    depth: float

    def mask(self, half_width: float) -> np.ndarray:
        """Cells (``GRID_SHAPE``) whose centre lies in the strip, ``ZONE_MARGIN`` around it.

        The strip spans ``[r_near, r_far]`` along the ray and ``half_width``
        each side of it (the bucket's half width).
        """
        c, s = math.cos(self.azimuth), math.sin(self.azimuth)
        near, far = self.r_near - ZONE_MARGIN, self.r_far + ZONE_MARGIN
        side = half_width + ZONE_MARGIN
        # Only the cells of the strip's bounding box (one cell wider) are tested.
        xs = [c * r - s * t for r in (near, far) for t in (-side, side)]
        ys = [s * r + c * t for r in (near, far) for t in (-side, side)]
        i0, i1 = _cell_range(min(xs), max(xs), GRID_ORIGIN[0], GRID_SHAPE[0])
        j0, j1 = _cell_range(min(ys), max(ys), GRID_ORIGIN[1], GRID_SHAPE[1])
        x, y = CELL_XS[i0:i1, None], CELL_YS[None, j0:j1]
        along = c * x + s * y
        across = -s * x + c * y
        inside = np.zeros(GRID_SHAPE, dtype=bool)
        inside[i0:i1, j0:j1] = (along >= near) & (along <= far) & (np.abs(across) <= side)
        return inside

    def as_array(self) -> np.ndarray:
        """``[x_near, y_near, x_far, y_far, depth]``, shape (5,)."""
        c, s = math.cos(self.azimuth), math.sin(self.azimuth)
        return np.array(
            [c * self.r_near, s * self.r_near, c * self.r_far, s * self.r_far, self.depth]
        )


@dataclass
class Scene:
    heights: np.ndarray  # (nx, ny) m
    pipe: Pipe
    truck: Truck
    zone: DigZone | None = None
    target: np.ndarray | None = None  # (4,) tip x, y, z (m) and bucket angle (rad)
    base: tuple[float, float, float] = (0.0, 0.0, 0.0)  # roll, pitch, yaw (rad): H_M^O
    # (4,) joint angles at reset (rad, clipped to the joint ranges); None: Machine.q_ready
    start: np.ndarray | tuple[float, ...] | None = None


def sample_base(rng: np.random.Generator, slope: float) -> tuple[float, float, float]:
    """Base roll and pitch uniform in ``[-slope, slope]`` (no draw on level ground)."""
    if slope == 0.0:
        return (0.0, 0.0, 0.0)
    roll, pitch = rng.uniform(-slope, slope, size=2)
    return (float(roll), float(pitch), 0.0)


def ground_plane(base: tuple[float, float, float]) -> tuple[float, float]:
    """``(gx, gy)`` of the ground plane ``z = gx x + gy y`` under a base turned by ``base``.

    The tracks stand on the plane through the origin whose normal is the
    base's z axis ``R e_z`` (eq. 2): ``z = -(n_x x + n_y y) / n_z``.
    """
    r = base_rotation(*base)
    return -r[0, 2] / r[2, 2], -r[1, 2] / r[2, 2]


def _tilt(scene_parts: tuple, base: tuple[float, float, float]):
    """Heights, pipe and truck of a level scene laid on the base's ground plane.

    Heights and the pipe's ends rise by the plane's height under them; the
    truck stands on the plane at its centre (``floor``), its rim as high above it.
    Parts given as None stay None.
    """
    heights, pipe, truck = scene_parts
    if base == (0.0, 0.0, 0.0):
        return heights, pipe, truck
    gx, gy = ground_plane(base)
    if heights is not None:
        heights = heights + gx * CELL_XS[:, None] + gy * CELL_YS[None, :]
    if pipe is not None:
        a, b = pipe.a, pipe.b
        pipe = Pipe(
            a=(a[0], a[1], a[2] + gx * a[0] + gy * a[1]),
            b=(b[0], b[1], b[2] + gx * b[0] + gy * b[1]),
            radius=pipe.radius,
        )
    if truck is not None:
        floor = gx * truck.cx + gy * truck.cy
        truck = dataclasses.replace(truck, floor=floor, height=truck.height + floor)
    return heights, pipe, truck


CELL_XS = GRID_ORIGIN[0] + (np.arange(GRID_SHAPE[0]) + 0.5) * GRID_CELL  # (nx,) cell centres
CELL_YS = GRID_ORIGIN[1] + (np.arange(GRID_SHAPE[1]) + 0.5) * GRID_CELL  # (ny,)
# Undulations fade in from the pad's edge over 1 m.
_FADE = np.clip((np.hypot(CELL_XS[:, None], CELL_YS[None, :]) - PAD_RADIUS) / 1.0, 0.0, 1.0)


def _cell_range(lo: float, hi: float, origin: float, n: int) -> tuple[int, int]:
    """Indices ``[i0, i1)`` of the cells overlapping ``[lo, hi]`` (m), one more each side."""
    i0 = math.floor((lo - origin) / GRID_CELL) - 1
    i1 = math.floor((hi - origin) / GRID_CELL) + 2
    return min(max(i0, 0), n), min(max(i1, 0), n)


def sample_heights(rng: np.random.Generator) -> np.ndarray:
    """Initial ground heights, shape ``GRID_SHAPE``.

    Two plane waves ``amp sin(k (cos d x + sin d y) + phase)``, each
    ``amp (sin A cos B + cos A sin B)`` (separable in x, y): both waves are
    one matrix product ``(nx, 4) @ (4, ny)``.
    """
    columns, rows = [], []
    for _ in range(2):
        k = rng.uniform(0.3, 0.8)
        direction = rng.uniform(0.0, 2 * math.pi)
        phase = rng.uniform(0.0, 2 * math.pi)
        amp = rng.uniform(0.0, 0.075)
        a = k * math.cos(direction) * CELL_XS + phase  # (nx,)
        b = k * math.sin(direction) * CELL_YS  # (ny,)
        columns += [amp * np.sin(a), amp * np.cos(a)]
        rows += [np.cos(b), np.sin(b)]
    return (np.column_stack(columns) @ np.vstack(rows)) * _FADE


def sample_truck(rng: np.random.Generator) -> Truck:
    side = 1.0 if rng.random() < 0.5 else -1.0
    azimuth = side * math.radians(rng.uniform(75.0, 110.0))
    radius = rng.uniform(5.5, 7.0)
    yaw = azimuth + math.pi / 2 + math.radians(rng.uniform(-15.0, 15.0))
    return Truck(
        cx=radius * math.cos(azimuth),
        cy=radius * math.sin(azimuth),
        yaw=yaw,
        half_length=2.5,
        half_width=1.2,
        height=2.8,
    )


def sample_pipe(rng: np.random.Generator, azimuth: float, r_lo: float, r_hi: float) -> Pipe:
    r = rng.uniform(r_lo, r_hi)
    cx, cy = r * math.cos(azimuth), r * math.sin(azimuth)
    direction = rng.uniform(0.0, math.pi)
    half = 8.0
    dx, dy = half * math.cos(direction), half * math.sin(direction)
    z = -rng.uniform(1.8, 3.0)
    return Pipe(a=(cx - dx, cy - dy, z), b=(cx + dx, cy + dy, z), radius=0.15)


def sample_dig_scene(rng: np.random.Generator, m: Machine, slope: float = 0.0) -> Scene:
    """Ground, dig zone, pipe and truck for one dig cycle (on a slope: see :func:`_tilt`)."""
    base = sample_base(rng, slope)
    heights = sample_heights(rng)
    azimuth = math.radians(rng.uniform(-35.0, 35.0))
    r_far = rng.uniform(7.0, 8.5)
    length = rng.uniform(2.5, 3.5)
    zone = DigZone(azimuth, r_far - length, r_far, rng.uniform(0.5, 1.0))
    pipe = sample_pipe(rng, azimuth, zone.r_near - 1.0, zone.r_far + 2.0)
    truck = sample_truck(rng)
    heights, pipe, truck = _tilt((heights, pipe, truck), base)
    return Scene(heights, pipe, truck, zone=zone, base=base)


def sample_reach_scene(rng: np.random.Generator, m: Machine, slope: float = 0.0) -> Scene:
    """Ground, reachable target pose, pipe and truck for a reach (on a slope: :func:`_tilt`).

    On a slope the target's tip is in frame O and its angle is the bucket
    angle in the machine's frame M (``q2 + q3 + q4``).
    """
    base = sample_base(rng, slope)
    heights = sample_heights(rng)
    truck = sample_truck(rng)
    level = base == (0.0, 0.0, 0.0)
    if not level:
        heights, _, truck = _tilt((heights, None, truck), base)
        rotation = base_rotation(*base)
    lo = np.array(m.q_min) + 0.05
    hi = np.array(m.q_max) - 0.05
    lo[0], hi[0] = -math.pi / 3, math.pi / 3
    # rng.uniform(lo, hi) is lo + (hi - lo) * u for 4 draws u of rng.random: the same
    # numbers and the same stream, without its per-call array checks (most candidates fail).
    (l1, l2, l3, l4), (w1, w2, w3, w4) = lo.tolist(), (hi - lo).tolist()
    ix = lambda x: min(max(int((x - GRID_ORIGIN[0]) / GRID_CELL), 0), GRID_SHAPE[0] - 1)  # noqa: E731
    iy = lambda y: min(max(int((y - GRID_ORIGIN[1]) / GRID_CELL), 0), GRID_SHAPE[1] - 1)  # noqa: E731
    for _ in range(10_000):
        u1, u2, u3, u4 = rng.random(4).tolist()
        q1, q2, q3, q4 = l1 + w1 * u1, l2 + w2 * u2, l3 + w3 * u3, l4 + w4 * u4
        pts = arm_points(q1, q2, q3, q4, m)
        tip = pts[-1] if level else tuple(rotation @ pts[-1])
        ground = heights[ix(tip[0]), iy(tip[1])]
        if math.hypot(tip[0], tip[1]) < 4.0 or not 0.0 <= tip[2] - ground <= 2.5:
            continue  # (most candidates: the other points are turned only past this test)
        if not level:
            pts = (*(tuple(rotation @ p) for p in pts[:-1]), tip)
        if any(p[2] < heights[ix(p[0]), iy(p[1])] + 0.3 for p in pts[1:3]):
            continue
        if truck_clearance(pts, m.link_radius, truck) < 1.0:
            continue
        break
    else:  # pragma: no cover - no candidate of 10,000 accepted
        raise RuntimeError("could not sample a reachable target")
    azimuth = math.atan2(tip[1], tip[0])
    r_tip = math.hypot(tip[0], tip[1])
    pipe = sample_pipe(rng, azimuth, r_tip - 3.0, r_tip + 3.0)
    if level:
        depth = min(pipe.a[2], tip[2] - 1.0 - pipe.radius)
        pipe = Pipe(a=(*pipe.a[:2], depth), b=(*pipe.b[:2], depth), radius=pipe.radius)
    else:  # laid on the plane, then lowered until all of it is 1 m below the tip
        _, pipe, _ = _tilt((None, pipe, None), base)
        drop = max(pipe.a[2], pipe.b[2]) - (tip[2] - 1.0 - pipe.radius)
        if drop > 0.0:
            a, b = pipe.a, pipe.b
            pipe = Pipe((a[0], a[1], a[2] - drop), (b[0], b[1], b[2] - drop), pipe.radius)
    target = np.array([tip[0], tip[1], tip[2], q2 + q3 + q4])
    return Scene(heights, pipe, truck, target=target, base=base)
