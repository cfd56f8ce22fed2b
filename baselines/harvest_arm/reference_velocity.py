"""Reference velocities of the arm's points (paper eq. 8-11).

The arm is a chain of joint points ``X_0 .. X_L`` (base to gripper); link
``i`` is the segment ``X_i X_{i+1}`` with ``U = X_{i+1} - X_i`` and
``u = U / |U|``.

* Trajectory following (eq. 8), ``w_d = (v x u) x u = (v.u) u - v`` with
  ``v`` the unit direction of travel. The paper says the reference velocity of
  a turning link is perpendicular to it and that with eq. 8 the joints trace
  the gripper's trajectory (its Fig. 3). Both hold when ``w_d`` is read as the
  velocity of ``X_i`` *relative to the link's distal point* ``X_{i+1}``, with
  ``v`` the distal point's direction of travel and ``|V_i_ref|`` its speed:

      X_i_dot = X_{i+1}_dot + |X_{i+1}_dot| w_d = (X_{i+1}_dot . u) u,

  from the gripper (``X_L_dot``, its path velocity) down to the base. Each
  joint point then moves along its link towards the point ahead of it, the
  follow-the-leader motion that makes every joint run down the path the
  gripper has travelled. Its perpendicular part, relative to ``X_{i+1}``, is
  the printed ``w_d`` with the printed sign (:func:`trajectory_following`).
* Obstacle avoidance by the links (eq. 9-10). The paper writes the terms at
  the joint point ``X_i`` for obstacles that project onto link ``i``
  (eq. 9: ``0 <= C.U <= |U|^2``; eq. 10: the common perpendicular inside both
  segments, a test the OCR damaged). Acting only at ``X_i`` leaves most of a
  link unguarded (a branch crossing a link's far half barely moves ``X_i``),
  so we apply each term at the link's *closest point* to the obstacle
  (:func:`link_avoidance`): for a sphere the foot of the perpendicular
  (eq. 9's ``rho = |C| sin(C, U)`` when it lies on the link, the nearer end
  otherwise), for a bar the closest points of the two segments (eq. 10's
  common normal when interior to both). Direction: from the obstacle to that
  point (eq. 9's ``(C x u) x u`` normalised, eq. 10's ``C x U`` oriented off
  the bar); magnitude eq. 5 with the obstacle-avoidance row of Tables 1-2,
  ``rho`` the surface clearance. A point at fraction ``s`` of link ``i`` has
  the Jacobian ``(1 - s) J_i + s J_{i+1}`` (exact: the link is rigid), so the
  policy adds it to eq. 1 as one more weighted point.
* Combination (eq. 11): ``w = w_d + w_ob``, normalised only when ``|w| > 1``;
  ``X_dot = |V_ref| w`` (:func:`combine`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motiongym.baselines.harvest_arm.potential_field import (
    AVOIDANCE,
    FieldParameters,
    obstacle_magnitude,
)
from motiongym.envs.geometry import closest_points_between_segments

_EPS = 1e-12


def _unit_links(points: np.ndarray) -> np.ndarray:
    """Unit link directions ``u`` (L, dim)."""
    U = points[1:] - points[:-1]
    return U / np.maximum(np.linalg.norm(U, axis=-1), _EPS)[:, None]


def trajectory_following(points: np.ndarray, v: np.ndarray, sign: float = 1.0) -> np.ndarray:
    """Eq. 8's printed direction ``w_d = (v x u) x u`` for every link (L, dim).

    ``sign=-1`` flips it (a test shows the printed sign is the one that traces).
    """
    u = _unit_links(points)
    return sign * ((u @ v)[:, None] * u - v[None, :])


def follow_the_leader(points: np.ndarray, x_dot: np.ndarray, sign: float = 1.0) -> np.ndarray:
    """Eq. 8 as motion: reference velocities of every point (P, dim), gripper last.

    ``X_L_dot = x_dot``; ``X_i_dot = X_{i+1}_dot + |X_{i+1}_dot| w_d(v_{i+1}, u_i)``
    down to the base (see the module docstring).
    """
    u = _unit_links(points)
    out = np.zeros_like(points)
    out[-1] = x_dot
    for i in range(len(u) - 1, -1, -1):
        ahead = out[i + 1]
        speed = float(np.linalg.norm(ahead))
        if speed < _EPS:
            break
        v = ahead / speed
        w_d = (u[i] @ v) * u[i] - v
        out[i] = ahead + sign * speed * w_d
    return out


@dataclass(frozen=True)
class ControlPoints:
    """Points of the links near obstacles, each with its avoidance term.

    ``link`` (M,) the link index, ``s`` (M,) the fraction along it, ``w_ob``
    (M, dim) the unit-free avoidance term (eq. 9-10 direction times eq. 5
    magnitude), ``clearance`` (M,) m, ``is_bar`` (M,).
    """

    link: np.ndarray
    s: np.ndarray
    w_ob: np.ndarray
    clearance: np.ndarray
    is_bar: np.ndarray

    def __len__(self) -> int:
        return len(self.link)

    def jacobians(self, jacs: np.ndarray) -> np.ndarray:
        """Their positional Jacobians (M, dim, n) from the joint points' (P, dim, n)."""
        s = self.s[:, None, None]
        return (1.0 - s) * jacs[self.link] + s * jacs[self.link + 1]

    def interpolate(self, per_point: np.ndarray) -> np.ndarray:
        """A per-point quantity (P, dim) at the control points (M, dim)."""
        s = self.s[:, None]
        return (1.0 - s) * per_point[self.link] + s * per_point[self.link + 1]


def link_avoidance(
    points: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    radius: np.ndarray,
    is_bar: np.ndarray,
    link_radius: float = 0.0,
    params: FieldParameters = AVOIDANCE,
) -> ControlPoints:
    """Eq. 9 (spheres, ``a == b``) and eq. 10 (bars ``a``-``b``) at each link's closest point.

    One control point per (link, obstacle) pair whose surface clearance is
    below ``rho0``. The gripper's own link is included (its distal end is the
    gripper, held to its path by eq. 1's constraint).
    """
    dim = points.shape[1]
    if len(radius) == 0:
        return ControlPoints(
            np.zeros(0, int), np.zeros(0), np.zeros((0, dim)), np.zeros(0), np.zeros(0, bool)
        )
    p0, p1 = points[:-1, None, :], points[1:, None, :]  # (L, 1, dim)
    dist, on_link, on_obstacle = closest_points_between_segments(p0, p1, a[None], b[None])
    rho = dist - radius[None, :] - link_radius  # (L, K)
    link, k = np.nonzero(rho < params.rho0)
    d1 = (p1 - p0)[link, 0]  # (M, dim)
    s = np.einsum("md,md->m", on_link[link, k] - p0[link, 0], d1)
    s = np.clip(s / np.maximum(np.einsum("md,md->m", d1, d1), _EPS), 0.0, 1.0)
    away = on_link[link, k] - on_obstacle[link, k]  # from the obstacle to the link
    away = away / np.maximum(dist[link, k], _EPS)[:, None]
    mag = obstacle_magnitude(rho[link, k], params)
    return ControlPoints(link, s, mag[:, None] * away, rho[link, k], is_bar[k])


def combine(w_d: np.ndarray, w_ob: np.ndarray, speed: float) -> np.ndarray:
    """Eq. 11: ``|V_ref| (w_d + w_ob)``, the sum normalised where its norm exceeds 1."""
    w = w_d + w_ob
    norm = np.linalg.norm(w, axis=-1, keepdims=True)
    return speed * np.where(norm > 1.0, w / np.maximum(norm, _EPS), w)
