"""Closest points between points and segments, vectorised over leading axes.

Shared by every system that measures clearance between links (capsules about
a segment) and obstacles (spheres about a point, bars and pipes about a
segment). A capsule of radius r1 and one of radius r2 are apart by
``segment distance - r1 - r2``; a sphere likewise with its centre.

All functions broadcast over leading axes: points are ``(..., dim)`` arrays
(dim 2 or 3). Degenerate segments (zero length) are handled as points.
The segment-segment routine follows Ericson, *Real-Time Collision Detection*
(2005), section 5.1.9, with the branches written as ``np.where``.
"""

from __future__ import annotations

import numpy as np

_EPS = 1e-12


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

    Returns:
        ``(distance, on_p, on_q)``: shapes ``(...)``, ``(..., dim)``, ``(..., dim)``.
    """
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.sum(d1 * d1, axis=-1)
    e = np.sum(d2 * d2, axis=-1)
    f = np.sum(d2 * r, axis=-1)
    c = np.sum(d1 * r, axis=-1)
    b = np.sum(d1 * d2, axis=-1)
    denom = a * e - b * b
    p_is_point = a <= _EPS
    q_is_point = e <= _EPS
    safe_a = np.maximum(a, _EPS)
    safe_e = np.maximum(e, _EPS)
    # General case: s from the infinite lines, clamped; parallel lines take s = 0.
    s = np.where(
        denom > _EPS * np.maximum(a * e, _EPS),
        (b * f - c * e) / np.where(denom > 0, denom, 1.0),
        0.0,
    )
    s = np.clip(s, 0.0, 1.0)
    t = (b * s + f) / safe_e
    # t outside [0, 1]: clamp it and recompute s for the clamped t.
    s = np.where(t < 0.0, np.clip(-c / safe_a, 0.0, 1.0), s)
    s = np.where(t > 1.0, np.clip((b - c) / safe_a, 0.0, 1.0), s)
    t = np.clip(t, 0.0, 1.0)
    # Degenerate segments.
    s = np.where(p_is_point, 0.0, s)
    t = np.where(p_is_point, np.clip(f / safe_e, 0.0, 1.0), t)
    s = np.where(q_is_point & ~p_is_point, np.clip(-c / safe_a, 0.0, 1.0), s)
    t = np.where(q_is_point, 0.0, t)
    on_p = p0 + s[..., None] * d1
    on_q = q0 + t[..., None] * d2
    return np.linalg.norm(on_p - on_q, axis=-1), on_p, on_q
