"""Reference velocities of the joint points (paper eq. 8-11).

The arm is a chain of joint points ``X_0 .. X_L`` (base to gripper); link
``i`` is the segment ``X_i X_{i+1}`` with ``U = X_{i+1} - X_i`` and
``u = U / |U|``; ``v`` is the unit direction of the gripper's travel. As the
paper writes them, every term of link ``i`` is the reference velocity
``X_i_dot`` of its *proximal* joint point ``X_i`` (the gripper ``X_L`` is
bound to its path by eq. 1, the base ``X_0`` does not move).

* Trajectory following (eq. 8): ``w_d = (v x u) x u = -(v - (v.u) u)``, the
  printed sign. At ``X_i`` it turns link ``i`` towards the direction of
  travel (the proximal end moves against ``v``'s perpendicular part while
  the distal end goes with the gripper), so each link lines up with the
  path and the joints trace the gripper's trajectory (paper Fig. 3). The
  spec asked for the sign that makes the joints follow the path: it is the
  printed one applied at ``X_i``; the opposite sign traces worse (tested).
* Point obstacle (eq. 9): ``C = Ob_j - X_i``; the term acts when the
  obstacle projects onto the link (``0 <= C.U <= |U|^2``) and its distance
  ``rho = |C| sin(C, U)`` to the link's line is below ``rho0``. Direction
  ``(C x u) x u`` normalised, i.e. perpendicular to the link, away from the
  obstacle; magnitude eq. 5 with the obstacle-avoidance row of Tables 1-2.
* Bar obstacle (eq. 10): direction the common normal of link and bar,
  ``(C x U) / |C x U|``, oriented away from the bar, ``rho`` the distance
  along it. The printed applicability test (two sign products of
  ``C_1, C_2, C_3``) is OCR-damaged; we implement its meaning, "the common
  perpendicular falls inside both segments": the closest points of the two
  segments are interior to both, and then the common normal is the
  direction between them (which also serves in 2-D).
* Combination (eq. 11): ``w = w_d + sum_j w_ob_j``, normalised only when
  ``|w| > 1``; ``X_i_dot = |V_i_ref| w``.

Where the paper is silent: ``rho`` is the surface clearance (line or
segment distance minus the link and obstacle radii); ``|V_i_ref|`` is the
gripper's reference speed for every point. Two extensions, off by default
(the ``potential-field-extended`` policy turns them on): ``both_ends`` gives
a link's obstacle terms to its distal point as well (except the gripper),
and ``interior_only=False`` lets the terms act on obstacles beyond the
link's ends.
"""

from __future__ import annotations

import numpy as np

from motiongym.baselines.harvest_arm.potential_field import (
    AVOIDANCE,
    FieldParameters,
    obstacle_magnitude,
)
from motiongym.envs.geometry import closest_points_between_segments

_EPS = 1e-12


def _links(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Link vectors U (L, dim), lengths (L,), unit u (L, dim)."""
    U = points[1:] - points[:-1]
    length = np.linalg.norm(U, axis=-1)
    return U, length, U / np.maximum(length, _EPS)[:, None]


def _to_points(per_link: np.ndarray, both_ends: bool = False) -> np.ndarray:
    """Give each link's term to its proximal point (and distal): (L, dim) -> (P, dim)."""
    L, dim = per_link.shape
    out = np.zeros((L + 1, dim))
    out[:L] += per_link  # proximal points: the paper's X_i
    if both_ends:
        out[1:L] += per_link[: L - 1]  # distal points, except the gripper
    return out


def trajectory_following(points: np.ndarray, v: np.ndarray, sign: float = 1.0) -> np.ndarray:
    """Eq. 8 direction ``w_d = (v x u) x u`` at every point (P, dim); zero at the gripper.

    ``sign=-1`` flips it (for the test that the printed sign is the one
    that traces the path).
    """
    _, _, u = _links(points)
    w = (u @ v)[:, None] * u - v[None, :]  # (L, dim): (v x u) x u = (v.u) u - v
    out = np.zeros_like(points)
    out[:-1] = sign * w  # X_i, the proximal point of link i
    return out


def point_obstacle_terms(
    points: np.ndarray,
    centres: np.ndarray,
    radius: np.ndarray,
    link_radius: float = 0.0,
    params: FieldParameters = AVOIDANCE,
    interior_only: bool = True,
    both_ends: bool = False,
) -> np.ndarray:
    """Eq. 9 terms ``w_ob`` of sphere obstacles (K, dim), summed per point: (P, dim).

    ``interior_only=False`` also acts on obstacles beyond the link's ends,
    with the distance and direction to the link's closest point (an
    extension; the paper's test is ``0 <= C.U <= |U|^2``).
    """
    if len(centres) == 0:
        return np.zeros_like(points)
    U, length, u = _links(points)
    C = centres[None, :, :] - points[:-1, None, :]  # (L, K, dim)
    along = np.einsum("lkd,ld->lk", C, U)  # C.U
    perp = C - np.einsum("lkd,ld->lk", C, u)[..., None] * u[:, None, :]  # (L, K, dim)
    dist = np.linalg.norm(perp, axis=-1)  # distance to the link's line
    rho = dist - radius[None, :] - link_radius
    inside = (along >= 0.0) & (along <= length[:, None] ** 2)
    if not interior_only:
        t = np.clip(along / np.maximum(length[:, None] ** 2, _EPS), 0.0, 1.0)  # (L, K)
        perp = C - t[..., None] * U[:, None, :]  # to the closest point of the segment
        dist = np.linalg.norm(perp, axis=-1)
        rho = dist - radius[None, :] - link_radius
        inside = np.ones_like(inside)
    inside &= rho < params.rho0
    mag = np.where(inside, obstacle_magnitude(rho, params), 0.0)  # (L, K)
    away = -perp / np.maximum(dist, _EPS)[..., None]  # ((C x u) x u) normalised
    return _to_points((mag[..., None] * away).sum(axis=1), both_ends)


def bar_obstacle_terms(
    points: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    radius: np.ndarray,
    link_radius: float = 0.0,
    params: FieldParameters = AVOIDANCE,
    interior_only: bool = True,
    both_ends: bool = False,
) -> np.ndarray:
    """Eq. 10 terms ``w_obl`` of bar obstacles ``a``-``b`` (K, dim), per point: (P, dim).

    ``interior_only=False`` also acts when a closest point is a segment's
    end (an extension of the paper's applicability test).
    """
    if len(a) == 0:
        return np.zeros_like(points)
    p0, p1 = points[:-1, None, :], points[1:, None, :]  # (L, 1, dim)
    dist, on_link, on_bar = closest_points_between_segments(p0, p1, a[None], b[None])  # (L, K)
    d1, d2 = p1 - p0, (b - a)[None]
    s = np.einsum("lkd,lkd->lk", on_link - p0, np.broadcast_to(d1, on_link.shape))
    s = s / np.maximum(np.sum(d1 * d1, axis=-1), _EPS)
    t = np.einsum("lkd,lkd->lk", on_bar - a[None], np.broadcast_to(d2, on_bar.shape))
    t = t / np.maximum(np.sum(d2 * d2, axis=-1), _EPS)
    interior = (s > 1e-9) & (s < 1 - 1e-9) & (t > 1e-9) & (t < 1 - 1e-9)
    if not interior_only:
        interior = np.ones_like(interior)
    rho = dist - radius[None, :] - link_radius
    mag = np.where(interior & (rho < params.rho0), obstacle_magnitude(rho, params), 0.0)
    away = (on_link - on_bar) / np.maximum(dist, _EPS)[..., None]  # common normal, off the bar
    return _to_points((mag[..., None] * away).sum(axis=1), both_ends)


def combine(w_d: np.ndarray, w_ob: np.ndarray, speed: float) -> np.ndarray:
    """Eq. 11: ``|V_ref| (w_d + w_ob)``, the sum normalised where its norm exceeds 1."""
    w = w_d + w_ob
    norm = np.linalg.norm(w, axis=-1, keepdims=True)
    return speed * np.where(norm > 1.0, w / np.maximum(norm, _EPS), w)
