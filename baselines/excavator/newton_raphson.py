"""Newton-Raphson inverse kinematics of the excavator (paper eq. 9-13).

The paper's section 4 (the error and the Jacobian, eq. 6-8) is missing from
the text; we reconstruct it as follows:

* error matrix ``E = H(q) - H_d`` with ``H(q) = H_M^O T_4^M T_tip^4`` the
  bucket-tip frame (eq. 5) and ``H_d`` the desired one
  (:func:`motiongym.envs.excavator.kinematics.desired_pose`);
* error vector of five entries (eq. 9), 1-based as in the paper::

      V = [E(1,1), E(3,1), E(1,4), E(2,4), E(3,4)]

  two entries of the bucket's x axis (they fix the bucket angle) and the
  three of the tip position;
* ``V = J dq`` (eq. 10) with ``J = dV/dq`` (5 x 4), analytic
  (:func:`jacobian`) or by central differences (:func:`jacobian_numeric`);
* ``J* = (J^T J)^-1 J^T`` (eq. 11), ``dq = J* V`` (eq. 12) and the iteration
  ``q_{k+1} = q_k - J*_k V_k`` (eq. 13).

:func:`solve` runs eq. 13 (``method="newton"``) or its damped
Levenberg-Marquardt variant (``method="lm"``: ``dq = (J^T J + lambda I)^-1 J^T V``
with Marquardt's rule, lambda / 10 after an improving step, x 10 and the step
refused otherwise).

Convergence is judged on the whole pose, not on ``V``: the tip position
error below ``tol_position`` (m) and the rotation between the reached and
the desired bucket frames (the angle of ``R_d^T R``, so both bucket axes:
the pin-to-tip axis ``x`` and the joint axis ``z``) below ``tol_angle``
(rad), with the joint angles (wrapped to (-pi, pi]) inside the limits. The
paper's ``V`` carries only two entries of the ``x`` axis: it also vanishes
with the swing turned half a turn and the bucket flipped over
(``q2 + q3 + q4 = -pi - beta``, the same ``x`` axis with ``z`` reversed),
which this check rejects. A wrong pose is never reported as converged.

A failure says why, in two families (:data:`NO_SOLUTION`,
:data:`FROM_START`), the first decided by the closed form
(:func:`analytic_solutions`, both stick branches):

* no in-limit solution exists (``IKResult.solution_exists`` False):
  ``"out_of_reach"`` (no joint angles at all give the pose: the bucket pin is
  outside the boom+stick annulus) or ``"joint_limits"`` (the pose exists only
  outside the joint ranges);
* an in-limit solution exists, the iteration did not reach it from this start
  (``solution_exists`` True): ``"outside_limits"`` (it converged to the pose
  with a joint outside its range), ``"flipped"`` (``V`` vanished with the
  bucket frame turned about its ``x`` axis, see above), ``"singular"``
  (``J^T J`` became singular, condition number above 1e12) or
  ``"max_iterations"`` (the budget ran out).

``H(q)`` is evaluated with the closed form of eq. 4
(:func:`~motiongym.envs.excavator.kinematics.tip_frame`, equal to the matrix
product, tested); the final pose is checked with the matrix product itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from motiongym.envs.excavator.config import Machine
from motiongym.envs.excavator.kinematics import (
    desired_pose,
    forward,
    swing_for_target,
    tip_frame,
    tip_jacobian,
)

METHODS = ("newton", "lm")
# The paper's case (section 5): bucket angle pi/8, tip at [15, 0, 0] in the
# paper's units. Its Fig. 3 (the dimensions) is not in the text, so we put a
# ground-level target on the x axis at 0.8 of our machine's maximum
# ground-level reach (8.04 m: the far part of a trench stroke) and read the
# bucket angle as a depression of pi/8 (tip 22.5 deg below the bucket pin,
# beta = -pi/8): with beta = +pi/8 the bucket would have to open 96 deg past
# the stick line, beyond the rotation range of a real bucket (the solver then
# reports "joint_limits", tested).
PAPER_REACH_FRACTION = 0.8
PAPER_BETA = -math.pi / 8
JACOBIANS = ("analytic", "numeric")
_SINGULAR_COND = 1e12
NO_SOLUTION = ("out_of_reach", "joint_limits")
FROM_START = ("outside_limits", "flipped", "singular", "max_iterations")
REASONS = ("converged", *NO_SOLUTION, *FROM_START)


@dataclass
class IKResult:
    """Outcome of one solve."""

    q: np.ndarray  # (4,) joint angles, wrapped to (-pi, pi]
    converged: bool
    reason: str  # one of REASONS
    iterations: int  # iterations run
    errors: np.ndarray  # (iterations + 1, 5) V before each iteration and after the last
    position_error: float  # m
    angle_error: float  # rad, rotation between the reached and the desired bucket frames
    solution_exists: bool  # an in-limit solution exists (closed form; True when converged)


def paper_target(m: Machine) -> tuple[np.ndarray, float]:
    """The paper's case for machine ``m``: ``(tip (3,), beta)``, see :data:`PAPER_BETA`."""
    return np.array([PAPER_REACH_FRACTION * m.reach, 0.0, 0.0]), PAPER_BETA


def _frame(q: np.ndarray, m: Machine, base: np.ndarray | None) -> np.ndarray:
    """``H(q)`` (eq. 5): the closed form of eq. 4, times the base pose if any."""
    h = tip_frame(q, m)
    return h if base is None else base @ h


def _residual(q, h_d, m, base) -> tuple[np.ndarray, np.ndarray]:
    h = _frame(q, m, base)
    e = h - h_d
    return np.array([e[0, 0], e[2, 0], e[0, 3], e[1, 3], e[2, 3]]), h


def error_vector(q: np.ndarray, h_d: np.ndarray, m: Machine, base: np.ndarray | None = None):
    """``V`` of eq. 9 at ``q`` for the desired tip frame ``h_d``, shape (5,)."""
    return _residual(q, h_d, m, base)[0]


def _pose_errors(h: np.ndarray, h_d: np.ndarray) -> tuple[float, float]:
    """Tip position error (m) and the rotation angle of ``R_d^T R`` (rad, both axes)."""
    pos = float(np.linalg.norm(h[:3, 3] - h_d[:3, 3]))
    cos_angle = 0.5 * (float(np.sum(h[:3, :3] * h_d[:3, :3])) - 1.0)
    return pos, math.acos(min(max(cos_angle, -1.0), 1.0))


def _axis_error(h: np.ndarray, h_d: np.ndarray) -> float:
    """Angle between the reached and the desired pin-to-tip (``x``) axes (rad)."""
    return math.acos(min(max(float(h[:3, 0] @ h_d[:3, 0]), -1.0), 1.0))


def jacobian(q: np.ndarray, m: Machine, base: np.ndarray | None = None) -> np.ndarray:
    """Analytic ``J = dV/dq`` (eq. 10), shape (5, 4). ``H_d`` is constant, so it drops out."""
    dx, dp = tip_jacobian(q, m)  # (3, 4) each, frame M
    if base is not None:
        dx, dp = base[:3, :3] @ dx, base[:3, :3] @ dp
    return np.stack([dx[0], dx[2], dp[0], dp[1], dp[2]])


def jacobian_numeric(
    q: np.ndarray,
    h_d: np.ndarray,
    m: Machine,
    base: np.ndarray | None = None,
    step: float = 1e-6,
) -> np.ndarray:
    """``J`` by central differences of :func:`error_vector`, shape (5, 4)."""
    q = np.asarray(q, float)
    cols = []
    for j in range(4):
        dq = np.zeros(4)
        dq[j] = step
        cols.append(
            (error_vector(q + dq, h_d, m, base) - error_vector(q - dq, h_d, m, base)) / (2 * step)
        )
    return np.stack(cols, axis=1)


def wrap(q: np.ndarray) -> np.ndarray:
    """Angles wrapped to (-pi, pi]."""
    return np.pi - np.mod(np.pi - np.asarray(q, float), 2 * np.pi)


def within_limits(q: np.ndarray, m: Machine, margin: float = 1e-9) -> bool:
    """Whether wrapped ``q`` lies inside the joint ranges."""
    q = wrap(q)
    return bool(np.all(q >= np.array(m.q_min) - margin) and np.all(q <= np.array(m.q_max) + margin))


def analytic_solutions(
    tip: np.ndarray, beta: float, m: Machine, base: np.ndarray | None = None
) -> list[np.ndarray]:
    """Closed-form solutions of the same problem (both stick branches), no limits applied.

    Used to diagnose failures (reach vs limits) and as a test oracle: with the
    swing from :func:`swing_for_target`, the bucket pin lies ``L4`` back along
    the bucket axis, and boom + stick form a 2R arm to it (law of cosines).
    """
    h_d = desired_pose(tip, beta, m, base)
    local = h_d[:3, 3] if base is None else np.linalg.solve(base, np.append(tip, 1.0))[:3]
    t1 = swing_for_target(local[0], local[1], m)
    c1, s1 = math.cos(t1), math.sin(t1)
    foot = np.array([-m.L0 + c1 * m.L1 + s1 * m.d2, s1 * m.L1 - c1 * m.d2, m.d1])
    pin = local - m.L4 * np.array([c1 * math.cos(beta), s1 * math.cos(beta), math.sin(beta)])
    rel = pin - foot
    r, z = c1 * rel[0] + s1 * rel[1], rel[2]
    dist2 = r * r + z * z
    c3 = (dist2 - m.L2**2 - m.L3**2) / (2 * m.L2 * m.L3)
    if abs(c3) > 1.0:
        return []
    out = []
    for sign in (-1.0, 1.0):
        t3 = sign * math.acos(c3)
        t2 = math.atan2(z, r) - math.atan2(m.L3 * math.sin(t3), m.L2 + m.L3 * math.cos(t3))
        out.append(wrap(np.array([t1, t2, t3, beta - t2 - t3])))
    return out


def solution_exists(tip, beta, m: Machine, base: np.ndarray | None = None) -> bool:
    """Whether an in-limit solution exists (closed form, :func:`analytic_solutions`)."""
    return any(within_limits(s, m) for s in analytic_solutions(tip, beta, m, base))


def _diagnose(tip, beta, m, base, h, h_d, tols, singular: bool) -> tuple[str, bool]:
    """``(reason, solution_exists)`` of a failed solve, see the module docstring."""
    solutions = analytic_solutions(tip, beta, m, base)
    if not solutions:
        return "out_of_reach", False
    if not any(within_limits(s, m) for s in solutions):
        return "joint_limits", False
    pos, ang = _pose_errors(h, h_d)
    if pos < tols[0] and ang < tols[1]:
        return "outside_limits", True
    if pos < tols[0] and _axis_error(h, h_d) < tols[1]:
        return "flipped", True
    return ("singular" if singular else "max_iterations"), True


def pose_errors(q: np.ndarray, h_d: np.ndarray, m: Machine, base=None) -> tuple[float, float]:
    """Tip position error (m) and bucket-frame rotation error (rad, both axes) at ``q``."""
    return _pose_errors(forward(q, m, base), h_d)


def solve(
    tip: np.ndarray,
    beta: float,
    m: Machine,
    q0: np.ndarray | None = None,
    base: np.ndarray | None = None,
    max_iterations: int = 20,
    tol_position: float = 1e-3,
    tol_angle: float = 1e-3,
    method: str = "newton",
    jacobian_mode: str = "analytic",
    stop_early: bool = True,
    damping: float = 1e-3,
    clamp: bool = False,
) -> IKResult:
    """Joint angles putting the bucket tip at ``tip`` with bucket angle ``beta``.

    Args:
        tip: desired tip position in the reference frame O (m), shape (3,).
        beta: desired bucket angle (rad), elevation of the bucket axis.
        m: the machine.
        q0: start (default: the machine's rest pose, as in the paper).
        base: ``H_M^O`` (default identity: base frame = reference frame).
        max_iterations: iteration budget (the paper runs 20).
        tol_position, tol_angle: convergence tolerances (m; rad, the bucket frame's rotation).
        method: "newton" (eq. 13) or "lm" (damped).
        jacobian_mode: "analytic" or "numeric" (central differences).
        stop_early: stop as soon as the tolerances are met (else run them all).
        damping: initial lambda of the "lm" method.
        clamp: project every iterate onto the joint ranges of boom, stick and
            bucket (a projected Newton step; not in the paper, off by default).
    """
    if method not in METHODS:
        raise ValueError(f"unknown IK method {method!r}; valid: {', '.join(METHODS)}")
    if jacobian_mode not in JACOBIANS:
        raise ValueError(f"unknown Jacobian mode {jacobian_mode!r}; valid: {', '.join(JACOBIANS)}")
    tip = np.asarray(tip, float)
    if tip.shape != (3,) or not np.all(np.isfinite(tip)) or not math.isfinite(beta):
        raise ValueError(f"tip must be 3 finite numbers and beta finite, got {tip!r}, {beta!r}")
    h_d = desired_pose(tip, beta, m, base)
    q = np.array(m.q_rest if q0 is None else q0, float)
    v, h = _residual(q, h_d, m, base)
    errors = [v]
    lam = damping
    lo, hi = np.array(m.q_min[1:]), np.array(m.q_max[1:])
    singular = False
    k = 0
    for k in range(1, max_iterations + 1):
        jac = (
            jacobian(q, m, base)
            if jacobian_mode == "analytic"
            else jacobian_numeric(q, h_d, m, base)
        )
        jtj = jac.T @ jac  # (4, 4)
        if method == "newton":
            eig = np.linalg.eigvalsh(jtj)  # ascending, J^T J is symmetric
            if eig[0] <= eig[-1] / _SINGULAR_COND:
                singular = True
                k -= 1
                break
            q = q - np.linalg.solve(jtj, jac.T @ v)  # eq. 11-13
            v, h = _residual(q, h_d, m, base)
        else:
            while True:
                q_try = q - np.linalg.solve(jtj + lam * np.eye(4), jac.T @ v)
                v_try, h_try = _residual(q_try, h_d, m, base)
                if v_try @ v_try < v @ v or lam > 1e8:
                    q, v, h, lam = q_try, v_try, h_try, max(lam / 10.0, 1e-12)
                    break
                lam *= 10.0
        if clamp:
            q[1:] = np.clip(q[1:], lo, hi)
            v, h = _residual(q, h_d, m, base)
        errors.append(v)
        if stop_early:
            pos, ang = _pose_errors(h, h_d)
            if pos < tol_position and ang < tol_angle:
                break
    q = wrap(q)
    h = forward(q, m, base)
    pos, ang = _pose_errors(h, h_d)
    if pos < tol_position and ang < tol_angle and within_limits(q, m):
        reason, exists = "converged", True
    else:
        tols = (tol_position, tol_angle)
        reason, exists = _diagnose(tip, beta, m, base, h, h_d, tols, singular)
    return IKResult(q, reason == "converged", reason, k, np.array(errors), pos, ang, exists)


def solve_paper_case() -> IKResult:
    """The paper's case on the default machine, from the rest pose (a benchmark hook).

    20 Newton-Raphson iterations of eq. 13 would be the paper's protocol; this
    stops at the tolerances (6 iterations) as a solver in use does.
    """
    from motiongym.envs.excavator.config import DEFAULT_MACHINE

    tip, beta = paper_target(DEFAULT_MACHINE)
    return solve(tip, beta, DEFAULT_MACHINE)
