"""Closest points between points and segments, vectorised over leading axes.

Shared by every system that measures clearance between links (capsules about
a segment) and obstacles (spheres about a point, bars and pipes about a
segment). A capsule of radius r1 and one of radius r2 are apart by
``segment distance - r1 - r2``; a sphere likewise with its centre.

All functions broadcast over leading axes: points are ``(..., dim)`` arrays
(dim 2 or 3). Degenerate segments (zero length) are handled as points.
The segment-segment routine follows Ericson, *Real-Time Collision Detection*
(2005), section 5.1.9, with its branches folded into a few ``np.where``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

_EPS = 1e-12


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Row-wise dot product over the last axis."""
    return np.add.reduce(u * v, axis=-1)


def _unit(x: np.ndarray) -> np.ndarray:
    """``x`` clamped to [0, 1] (cheaper than ``np.clip`` on small arrays)."""
    return np.minimum(np.maximum(x, 0.0), 1.0)


def closest_point_on_segment(
    p: np.ndarray, a: np.ndarray, b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Closest point of segment ``ab`` to point ``p``.

    Returns:
        ``(distance, closest)``: shapes ``(...)`` and ``(..., dim)``.
    """
    p, a, b = np.asarray(p, float), np.asarray(a, float), np.asarray(b, float)
    ab = b - a
    denom = np.sum(ab * ab, axis=-1)
    t = np.sum((p - a) * ab, axis=-1) / np.maximum(denom, _EPS)
    t = np.clip(np.where(denom > _EPS, t, 0.0), 0.0, 1.0)
    closest = a + t[..., None] * ab
    return np.linalg.norm(p - closest, axis=-1), closest


def closest_points_between_segments(
    p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest points of segments ``p0p1`` and ``q0q1``.

    Ericson's clamped solution, with the degenerate cases folded into it
    (hot paths call this on a handful of segments, where NumPy's per-call
    overhead dominates, so it is kept to few operations): the infinite lines'
    parameter ``s`` (for parallel lines, the point of ``p`` nearest ``q0``),
    ``t`` from ``s``, and where ``t`` must be clamped, ``s`` again from the
    clamped ``t``. A zero-length segment has ``d = 0``, so its terms vanish
    and the same formulas give its closest points.

    Returns:
        ``(distance, on_p, on_q)``: shapes ``(...)``, ``(..., dim)``, ``(..., dim)``.
    """
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.maximum(_dot(d1, d1), _EPS)
    e = np.maximum(_dot(d2, d2), _EPS)
    b = _dot(d1, d2)
    c = _dot(d1, r)
    f = _dot(d2, r)
    denom = a * e - b * b
    parallel = denom <= _EPS * a * e
    s = _unit(np.where(parallel, -c * e, b * f - c * e) / np.where(parallel, a * e, denom))
    t = (b * s + f) / e
    clamped = _unit(t)
    s = np.where(t == clamped, s, _unit((b * clamped - c) / a))
    on_p = p0 + s[..., None] * d1
    on_q = q0 + clamped[..., None] * d2
    diff = on_p - on_q
    return np.sqrt(_dot(diff, diff)), on_p, on_q


def segment_distance(
    p0: Sequence[float], p1: Sequence[float], q0: Sequence[float], q1: Sequence[float]
) -> float:
    """Distance between the segments ``p0 p1`` and ``q0 q1`` (3D), scalar math.

    :func:`closest_points_between_segments` for one pair, in plain floats
    (Ericson 2005, section 5.1.9, degenerate cases folded in): NumPy's
    per-call overhead dominates where a step measures a handful of segments.
    Equal to it to rounding (tested).
    """
    d1 = (p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2])
    d2 = (q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2])
    r = (p0[0] - q0[0], p0[1] - q0[1], p0[2] - q0[2])
    a = max(d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2], _EPS)
    e = max(d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2], _EPS)
    b = d1[0] * d2[0] + d1[1] * d2[1] + d1[2] * d2[2]
    c = d1[0] * r[0] + d1[1] * r[1] + d1[2] * r[2]
    f = d2[0] * r[0] + d2[1] * r[1] + d2[2] * r[2]
    denom = a * e - b * b
    if denom <= _EPS * a * e:  # parallel: the point of p nearest q0
        s = -c * e / (a * e)
    else:
        s = (b * f - c * e) / denom
    s = min(max(s, 0.0), 1.0)
    t = (b * s + f) / e
    clamped = min(max(t, 0.0), 1.0)
    if t != clamped:
        s = min(max((b * clamped - c) / a, 0.0), 1.0)
    x = r[0] + s * d1[0] - clamped * d2[0]
    y = r[1] + s * d1[1] - clamped * d2[1]
    z = r[2] + s * d1[2] - clamped * d2[2]
    return math.sqrt(x * x + y * y + z * z)
