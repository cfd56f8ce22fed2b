"""Closest-point routines against dense sampling and hand-computed cases."""

from __future__ import annotations

import numpy as np
import pytest

from motiongym.envs.geometry import (
    closest_point_on_segment,
    closest_points_between_segments,
)


def _sampled_segment_distance(p0, p1, q0, q1, n=801):
    s = np.linspace(0.0, 1.0, n)
    a = p0 + s[:, None] * (p1 - p0)
    b = q0 + s[:, None] * (q1 - q0)
    return np.min(np.linalg.norm(a[:, None] - b[None], axis=-1))


def test_hand_computed_cases():
    d, on_p, on_q = closest_points_between_segments(
        np.array([0.0, 0, 0]),
        np.array([1.0, 0, 0]),
        np.array([0.5, 1, -1]),
        np.array([0.5, 1, 1]),
    )
    assert d == pytest.approx(1.0)
    np.testing.assert_allclose(on_p, [0.5, 0, 0])
    np.testing.assert_allclose(on_q, [0.5, 1, 0])
    # Parallel, overlapping segments one unit apart.
    d, _, _ = closest_points_between_segments(
        np.array([0.0, 0]), np.array([2.0, 0]), np.array([1.0, 1]), np.array([3.0, 1])
    )
    assert d == pytest.approx(1.0)
    d, q = closest_point_on_segment(np.array([3.0, 4]), np.array([0.0, 0]), np.array([1.0, 0]))
    assert d == pytest.approx(np.hypot(2, 4))
    np.testing.assert_allclose(q, [1.0, 0])


def test_random_segments_match_dense_sampling():
    rng = np.random.default_rng(0)
    pts = rng.uniform(-1, 1, size=(120, 4, 3))
    d, on_p, on_q = closest_points_between_segments(pts[:, 0], pts[:, 1], pts[:, 2], pts[:, 3])
    for i in range(len(pts)):
        sampled = _sampled_segment_distance(*pts[i])
        assert d[i] <= sampled + 1e-9
        assert d[i] == pytest.approx(sampled, abs=5e-3)
    np.testing.assert_allclose(np.linalg.norm(on_p - on_q, axis=-1), d)


def test_degenerate_segments_are_points():
    p = np.array([0.0, 0, 0])
    d, _, _ = closest_points_between_segments(p, p, np.array([1.0, -1, 0]), np.array([1.0, 1, 0]))
    assert d == pytest.approx(1.0)
    d, _, _ = closest_points_between_segments(np.array([1.0, -1, 0]), np.array([1.0, 1, 0]), p, p)
    assert d == pytest.approx(1.0)
    d, _, _ = closest_points_between_segments(p, p, p + 2, p + 2)
    assert d == pytest.approx(np.sqrt(12))
