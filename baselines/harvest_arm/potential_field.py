"""Safe gripper path by an artificial potential field (paper eq. 2-7, RK4).

The gripper's reference velocity (eq. 7) is

    X_end_dot = |V_end_ref| v,   v = (v_d + sum_j v_ob_j) / |v_d + sum_j v_ob_j|

with the target term (eq. 4), pointing from the gripper to the fruit at
distance ``d``,

    |v_d| = 1 + eta_t (1/d - 1/d0) / d^2   if d <= d0,   1 otherwise,

and one obstacle term per obstacle (eq. 5), pointing away from it along the
shortest distance ``rho``,

    |v_ob| = eta (1/rho - 1/rho0) / rho^2   if rho <= rho0,   0 otherwise.

``eta`` is chosen by eq. 6 so that the term equals ``m`` at ``rho = k rho0``:
``eta (1/(k rho0) - 1/rho0) / (k rho0)^2 = m``. The parameters are the
paper's Tables 1-2 (the same in 2-D and 3-D).

The path is the integral of ``x_dot = X_end_dot(x)`` from the gripper's start
by classical 4th-order Runge-Kutta, until within ``tolerance`` of the fruit.

Choices where the paper is silent: ``rho`` is the *surface clearance*
(centre distance minus the obstacle's radius and the gripper link's radius;
the paper's obstacles are points and lines, for which the two agree), floored
at 1 mm; a bar's shortest distance is to the closest point of its segment.
Past the path's end the policy drives straight to the fruit, as the
paper's program always did.

The virtual plane. The paper applies eq. 2-3 "together with the virtual
plane concept" (section 3.1) and builds the reference velocities from "the
obstacle information inside the set virtual plane" (section 3.2); the text
that defined the plane did not survive. One statement that did fixes our
reading: ``m`` = 0.4-1 was chosen "so that obstacles are avoided at about
20-45 degrees"; ``atan(0.4)`` = 22 and ``atan(1)`` = 45 degrees, which is the
angle of ``v`` only when the obstacle term (``m`` at ``rho = k rho0``) is
*perpendicular* to the unit target term. So (``virtual_plane=True``) the
plane passes through the gripper normal to its direction to the fruit, each
obstacle acts through its projection onto that plane, and its term is the
unit direction in the plane away from the projection, with the eq. 5
magnitude of its true distance. An obstacle dead ahead (projection on the
gripper) is passed on a fixed side (2-D: +90 degrees; 3-D: ``n x z``). The
terms never oppose the target term, so ``v`` always has a positive part
towards the fruit: the path cannot stall in a local minimum.
``virtual_plane=False`` is the plain field of eq. 5 (terms along the shortest
distance), which stalls where an obstacle lies between gripper and fruit.

Local minima (an obstacle straight between gripper and fruit) are not
treated by the paper; :func:`plan_path`'s ``escape`` is our addition,
separately named and off in the paper's policy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from motiongym.envs.geometry import closest_point_on_segment


@dataclass(frozen=True)
class FieldParameters:
    """``rho0`` (m), ``m`` (-), ``k rho0`` (m) of one row of Tables 1-2."""

    rho0: float
    m: float
    k_rho0: float

    @property
    def eta(self) -> float:
        return eta_from_eq6(self.m, self.k_rho0, self.rho0)


TRAJECTORY = FieldParameters(rho0=0.2, m=0.6, k_rho0=0.1)  # Table 1, trajectory generation
TARGET = FieldParameters(rho0=0.4, m=1.0, k_rho0=0.2)  # Table 1, target direction
AVOIDANCE = FieldParameters(rho0=0.2, m=0.6, k_rho0=0.1)  # Table 1, obstacle avoidance

_RHO_FLOOR = 1e-3  # m


def eta_from_eq6(m: float, k_rho0: float, rho0: float) -> float:
    """Eq. 6 solved for eta: ``m (k rho0)^2 / (1/(k rho0) - 1/rho0)``."""
    if not 0.0 < k_rho0 < rho0:
        raise ValueError(f"need 0 < k*rho0 < rho0, got k*rho0={k_rho0}, rho0={rho0}")
    return m * k_rho0**2 / (1.0 / k_rho0 - 1.0 / rho0)


def obstacle_magnitude(rho: np.ndarray, params: FieldParameters = AVOIDANCE) -> np.ndarray:
    """Eq. 5: ``eta (1/rho - 1/rho0) / rho^2`` inside ``rho0``, else 0 (any shape)."""
    rho = np.maximum(np.asarray(rho, float), _RHO_FLOOR)
    value = params.eta * (1.0 / rho - 1.0 / params.rho0) / rho**2
    return np.where(rho <= params.rho0, value, 0.0)


def target_magnitude(d: float, params: FieldParameters = TARGET) -> float:
    """Eq. 4: ``1 + eta_t (1/d - 1/d0) / d^2`` inside ``d0``, else 1."""
    d = max(float(d), _RHO_FLOOR)
    if d > params.rho0:
        return 1.0
    return 1.0 + params.eta * (1.0 / d - 1.0 / params.rho0) / d**2


def field_direction(
    x: np.ndarray,
    fruit: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    radius: np.ndarray,
    gripper_radius: float = 0.0,
    trajectory: FieldParameters = TRAJECTORY,
    target: FieldParameters = TARGET,
    vortex: bool = False,
    virtual_plane: bool = True,
) -> np.ndarray:
    """Eq. 7's unit direction ``v`` at gripper position ``x`` (dim,).

    Obstacles are segments ``a``-``b`` (K, dim) of ``radius`` (K,); a sphere
    has ``a == b``. ``vortex`` turns each obstacle term 45 degrees from
    "away" towards the way around the obstacle to the fruit (our escape from
    local minima, see :func:`plan_path`). ``virtual_plane``: each obstacle
    term lies in the plane through ``x`` normal to the fruit direction (see
    the module docstring).
    """
    to_fruit = fruit - x
    d = float(np.linalg.norm(to_fruit))
    if d < 1e-12:
        return np.zeros_like(x)
    v = target_magnitude(d, target) * to_fruit / d
    if len(radius):
        dist, closest = closest_point_on_segment(x, a, b)  # (K,), (K, dim)
        rho = dist - radius - gripper_radius
        mag = obstacle_magnitude(rho, trajectory)  # (K,)
        away = (x - closest) / np.maximum(dist, 1e-12)[:, None]  # (K, dim)
        if virtual_plane:
            away = _in_plane(away, to_fruit / d)
        if vortex:
            away = _around(away, to_fruit / d)
        v = v + (mag[:, None] * away).sum(axis=0)
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-12 else np.zeros_like(x)


def _side(n: np.ndarray) -> np.ndarray:
    """A fixed unit direction perpendicular to unit ``n`` (dim,)."""
    if len(n) == 2:
        return np.array([-n[1], n[0]])
    axis = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    side = np.cross(n, axis)
    return side / np.linalg.norm(side)


def _in_plane(away: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Unit part of each ``away`` (K, dim) in the plane normal to unit ``n`` (the virtual plane)."""
    perp = away - (away @ n)[:, None] * n[None, :]  # (K, dim)
    norm = np.linalg.norm(perp, axis=1, keepdims=True)
    return np.where(norm > 1e-6, perp / np.maximum(norm, 1e-12), _side(n)[None, :])


def _around(away: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``(away + t) / |away + t|``, ``t`` the unit part of ``u`` across ``away`` (K, dim)."""
    t = u[None, :] - (away @ u)[:, None] * away  # (K, dim)
    norm = np.linalg.norm(t, axis=1)
    if away.shape[1] == 2:
        fixed = np.stack([-away[:, 1], away[:, 0]], axis=1)  # +90 degrees
    else:
        axis = np.where(np.abs(away[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
        fixed = np.cross(away, axis)
        fixed /= np.linalg.norm(fixed, axis=1, keepdims=True)
    t = np.where(norm[:, None] > 1e-6, t / np.maximum(norm, 1e-12)[:, None], fixed)
    out = away + t
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def plan_path(
    start: np.ndarray,
    fruit: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    radius: np.ndarray,
    speed: float = 0.2,
    step: float = 0.05,
    gripper_radius: float = 0.0,
    tolerance: float = 0.005,
    max_steps: int = 1000,
    escape: bool = True,
    virtual_plane: bool = True,
    report: dict | None = None,
) -> np.ndarray:
    """RK4 integral of eq. 7 from ``start`` to ``fruit``: path points (N, dim).

    ``speed`` is ``|V_end_ref|`` (m/s) and ``step`` the time step (s), so
    consecutive points are about ``speed * step`` apart. The last point is
    the fruit when the path arrives within ``tolerance``.

    A potential field has local minima (an obstacle straight between the
    gripper and the fruit, common in the plane) that the paper does not
    treat. Our addition, ``escape`` (the "vortex" escape): when the path
    stalls (less than 1 mm closer to the fruit over 50 steps), the stalled
    steps are dropped and the obstacle terms turn 45 degrees towards the way
    around each obstacle (``vortex``) until the path is 0.1 m closer to the
    fruit than where it stalled (at most 150 steps, 5 times); then eq. 7
    resumes. ``escape=False`` stops at the first stall (the policy then
    drives straight at the fruit, as the paper's program
    always did). ``virtual_plane``: see the module docstring. ``report``, if
    given, receives ``stalled`` (bool) and ``escapes`` (escapes used).
    """
    x = np.asarray(start, float).copy()
    fruit = np.asarray(fruit, float)

    def f(p: np.ndarray, vortex: bool) -> np.ndarray:
        return speed * field_direction(
            p, fruit, a, b, radius, gripper_radius, vortex=vortex, virtual_plane=virtual_plane
        )

    path = [x.copy()]
    h = step
    budget = 5 if escape else 0
    vortex, since, escapes, d_stall, vortex_steps = False, 0, budget, 0.0, 0
    stalled = False
    for _ in range(max_steps):
        d = float(np.linalg.norm(fruit - x))
        if d <= max(tolerance, speed * h):
            break
        if vortex:
            vortex_steps += 1
            if d < d_stall - 0.1 or vortex_steps > 150:
                vortex, since = False, 0
        k1 = f(x, vortex)
        k2 = f(x + 0.5 * h * k1, vortex)
        k3 = f(x + 0.5 * h * k2, vortex)
        k4 = f(x + h * k3, vortex)
        x = x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        path.append(x.copy())
        since += 1
        if (
            not vortex
            and since > 50
            and np.linalg.norm(fruit - path[-51]) - np.linalg.norm(fruit - x) < 1e-3
        ):  # stalled in a local minimum
            stalled = True
            if escapes == 0:
                break
            del path[-50:]
            x = path[-1].copy()
            vortex, escapes, vortex_steps = True, escapes - 1, 0
            d_stall = float(np.linalg.norm(fruit - x))
    if np.linalg.norm(fruit - x) <= max(tolerance, speed * h):
        path.append(fruit.copy())
    if report is not None:
        report["stalled"], report["escapes"] = stalled, budget - escapes
    return np.array(path)
