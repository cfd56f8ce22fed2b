"""Excavator kinematics exactly as the paper: eq. 1-5 with Table 1.

* Base pose ``H_M^O`` (eq. 1-2): ``R(phi, theta, psi) = Rz(psi) Ry(theta) Rx(phi)``
  (roll ``phi``, pitch ``theta``, yaw ``psi``) and ``P = [X, Y, Z]``, the point
  where the swing axis meets the ground. The printed eq. 2 has entry (1,1)
  ``c(theta)c(phi)``; the product gives ``c(psi)c(theta)`` (typo fixed, tested).
* Link transforms (eq. 3), Craig's modified DH (the printed matrix has sign
  typos; the reference list cites Craig 2005)::

      T_i^{i-1} = [[c,     -s,     0,    a_{i-1}],
                   [s ca,  c ca,  -sa,  -sa d_i],
                   [s sa,  c sa,   ca,   ca d_i],
                   [0,     0,      0,    1]]

  with Table 1 read with Craig's indexing: ``(alpha0, a0, d1) = (0, -L0, d1)``
  swing, ``(pi/2, L1, d2)`` boom foot, ``(0, L2, 0)`` boom, ``(0, L3, 0)`` stick;
  the bucket tip lies at ``L4`` on the bucket frame's x axis.
* ``T_4^M = T_1^M T_2^1 T_3^2 T_4^3`` (eq. 4), ``H_4^O = H_M^O T_4^M`` (eq. 5).

Joint angles ``q = (theta1 swing, theta2 boom, theta3 stick, theta4 bucket)``.
With alpha1 = pi/2 the boom, stick and bucket turn about the same horizontal
axis, so the arm lies in the vertical "boom plane" at azimuth ``theta1``; a
positive ``theta2`` raises the boom and the bucket angle (the elevation of
the bucket's x axis above the horizontal, positive up) is
``beta = theta2 + theta3 + theta4``.

:func:`arm_points` is the same chain written out with scalar math (no
matrices), which is what an environment step uses; a test checks it
against the matrix product.
"""

from __future__ import annotations

import math

import numpy as np

from motiongym.envs.excavator.config import Machine


def base_rotation(phi: float, theta: float, psi: float) -> np.ndarray:
    """Eq. 2 with the (1,1) typo fixed: ``Rz(psi) Ry(theta) Rx(phi)``, shape (3, 3)."""
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    return np.array(
        [
            [cp * ct, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
            [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp],
            [-st, sf * ct, cf * ct],
        ]
    )


def base_pose(
    position: tuple[float, float, float] = (0.0, 0.0, 0.0),
    rpy: tuple[float, ...] = (0.0, 0.0, 0.0),  # roll, pitch, yaw
) -> np.ndarray:
    """``H_M^O`` (eq. 1): base frame in the reference frame, shape (4, 4)."""
    h = np.eye(4)
    h[:3, :3] = base_rotation(*rpy)
    h[:3, 3] = position
    return h


def dh_transform(alpha: float, a: float, d: float, theta: float) -> np.ndarray:
    """``T_i^{i-1}`` (eq. 3, Craig's modified DH), shape (4, 4)."""
    c, s = math.cos(theta), math.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array(
        [
            [c, -s, 0.0, a],
            [s * ca, c * ca, -sa, -sa * d],
            [s * sa, c * sa, ca, ca * d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def link_frames(q: np.ndarray, machine: Machine) -> list[np.ndarray]:
    """``[T_1^M, T_2^M, T_3^M, T_4^M, T_tip^M]`` (eq. 4 and its partial products)."""
    frames = []
    t = np.eye(4)
    for (alpha, a, d), theta in zip(machine.dh, q, strict=True):
        t = t @ dh_transform(alpha, a, d, theta)
        frames.append(t)
    tip = np.eye(4)
    tip[0, 3] = machine.L4
    frames.append(t @ tip)
    return frames


def forward(q: np.ndarray, machine: Machine, base: np.ndarray | None = None) -> np.ndarray:
    """Bucket-tip frame in the reference frame, ``H_M^O T_4^M T_tip^4`` (eq. 5), (4, 4).

    The tip frame is the bucket frame 4 moved ``L4`` along its x axis.
    """
    tip = link_frames(np.asarray(q, float), machine)[-1]
    return tip if base is None else base @ tip


def tip_frame(q: np.ndarray, m: Machine) -> np.ndarray:
    """:func:`forward` (base = identity) written out in closed form, (4, 4).

    ``x = [c1 c234, s1 c234, s234]``, ``z = [s1, -c1, 0]``, ``y = z x x``, the
    tip from :func:`arm_points`; the same matrix as the product of eq. 4
    (tested), at a fraction of the cost (the IK evaluates it every iteration).
    """
    q1, q2, q3, q4 = (float(v) for v in q)
    c1, s1 = math.cos(q1), math.sin(q1)
    a = q2 + q3 + q4
    c, s = math.cos(a), math.sin(a)
    tip = arm_points(q1, q2, q3, q4, m)[3]
    return np.array(
        [
            [c1 * c, -c1 * s, s1, tip[0]],
            [s1 * c, -s1 * s, -c1, tip[1]],
            [s, c, 0.0, tip[2]],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def bucket_angle(q: np.ndarray) -> float:
    """``beta = theta2 + theta3 + theta4``: elevation of the bucket x axis (rad)."""
    return float(q[1] + q[2] + q[3])


def arm_points(
    q1: float, q2: float, q3: float, q4: float, m: Machine
) -> tuple[tuple[float, float, float], ...]:
    """Boom foot, boom tip (stick pin), bucket pin and bucket tip in the base frame.

    Scalar form of the chain of eq. 4 (base frame M, level base): returns
    ``(foot, stick_pin, bucket_pin, tip)``, each ``(x, y, z)`` in m.
    """
    c1, s1 = math.cos(q1), math.sin(q1)
    a2 = q2
    a3 = q2 + q3
    a4 = a3 + q4
    fx = -m.L0 + c1 * m.L1 + s1 * m.d2
    fy = s1 * m.L1 - c1 * m.d2
    fz = m.d1
    r2 = m.L2 * math.cos(a2)
    z2 = m.L2 * math.sin(a2)
    r3 = r2 + m.L3 * math.cos(a3)
    z3 = z2 + m.L3 * math.sin(a3)
    r4 = r3 + m.L4 * math.cos(a4)
    z4 = z3 + m.L4 * math.sin(a4)
    return (
        (fx, fy, fz),
        (fx + c1 * r2, fy + s1 * r2, fz + z2),
        (fx + c1 * r3, fy + s1 * r3, fz + z3),
        (fx + c1 * r4, fy + s1 * r4, fz + z4),
    )


def tip_jacobian(q: np.ndarray, m: Machine) -> tuple[np.ndarray, np.ndarray]:
    """Analytic derivatives of the tip frame's x axis and position in frame M.

    Returns ``(dx_axis, dpos)``, each (3, 4): column j is the derivative of the
    bucket x axis ``[c1 c234, s1 c234, s234]`` and of the tip position
    ``[-L0 + c1 rho + s1 d2, s1 rho - c1 d2, d1 + zeta]`` with respect to
    ``q_j``, where ``rho = L1 + L2 c2 + L3 c23 + L4 c234`` and
    ``zeta = L2 s2 + L3 s23 + L4 s234``.
    """
    q1, q2, q3, q4 = (float(v) for v in q)
    c1, s1 = math.cos(q1), math.sin(q1)
    angles = (q2, q2 + q3, q2 + q3 + q4)
    lengths = (m.L2, m.L3, m.L4)
    rho = m.L1 + sum(length * math.cos(a) for length, a in zip(lengths, angles, strict=True))
    c234, s234 = math.cos(angles[2]), math.sin(angles[2])
    dx = np.zeros((3, 4))
    dp = np.zeros((3, 4))
    dx[:, 0] = (-s1 * c234, c1 * c234, 0.0)
    dp[:, 0] = (-s1 * rho + c1 * m.d2, c1 * rho + s1 * m.d2, 0.0)
    for j in range(1, 4):
        drho = -sum(lengths[k] * math.sin(angles[k]) for k in range(j - 1, 3))
        dzeta = sum(lengths[k] * math.cos(angles[k]) for k in range(j - 1, 3))
        dx[:, j] = (-c1 * s234, -s1 * s234, c234)
        dp[:, j] = (c1 * drho, s1 * drho, dzeta)
    return dx, dp


def swing_for_target(x: float, y: float, m: Machine) -> float:
    """Swing angle that puts the point ``(x, y)`` (frame M) in the boom plane.

    The boom plane is offset ``d2`` from the swing axis (at ``x = -L0``):
    ``theta1 = atan2(y, x + L0) + asin(d2 / r)``.
    """
    dx, dy = x + m.L0, y
    r = math.hypot(dx, dy)
    if r < abs(m.d2) or r == 0.0:
        return math.atan2(dy, dx)
    return math.atan2(dy, dx) + math.asin(m.d2 / r)


def desired_pose(
    tip: np.ndarray, beta: float, m: Machine, base: np.ndarray | None = None
) -> np.ndarray:
    """``H_d``: tip at ``tip`` (reference frame O) with bucket angle ``beta``, (4, 4).

    The bucket frame's axes follow the DH chain: ``x = [c1 cb, s1 cb, sb]``,
    ``z = [s1, -c1, 0]`` (the joint axis), ``y = z cross x``, with the swing
    ``theta1`` that puts the tip in the boom plane (:func:`swing_for_target`).
    """
    tip = np.asarray(tip, float)
    local = tip if base is None else np.linalg.solve(base, np.append(tip, 1.0))[:3]
    t1 = swing_for_target(local[0], local[1], m)
    c1, s1, cb, sb = math.cos(t1), math.sin(t1), math.cos(beta), math.sin(beta)
    x_axis = np.array([c1 * cb, s1 * cb, sb])
    z_axis = np.array([s1, -c1, 0.0])
    h = np.eye(4)
    h[:3, 0] = x_axis
    h[:3, 1] = np.cross(z_axis, x_axis)
    h[:3, 2] = z_axis
    h[:3, 3] = local
    return h if base is None else base @ h
