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
