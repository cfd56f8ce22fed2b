"""Joint rates of a redundant arm: weighted pseudo-inverse with a null-space term (eq. 1).

    theta_dot = J* X_dot + (I - J* Jn) S1^-1 S2
    J*  = S1^-1 Jn^T (Jn S1^-1 Jn^T)^-1
    S1  = sum_i 2 k_i Ji^T Ji,    S2 = sum_i 2 k_i Ji^T X_i_dot

``Jn`` (dim, n) is the gripper's positional Jacobian, ``Ji`` (dim, n) that of
joint point ``i`` (zero columns for joints beyond it), ``X_i_dot`` its
reference velocity and ``k_i > 0`` its weight. This is the exact solution of

    minimise sum_i k_i |Ji theta_dot - X_i_dot|^2   subject to   Jn theta_dot = X_dot

(Lagrange: ``S1 theta_dot - S2 + Jn^T lambda = 0``). Robustness, our choices:

* ``S1`` is singular when a joint moves none of the weighted points; we add
  ``reg * trace(S1) / n`` to its diagonal (``reg = 1e-9`` by default; the
  policy uses 1e-3, see :data:`..policy.JOINT_DAMPING`). The
  policy also weights the gripper itself (its reference velocity is
  ``X_dot``), which changes nothing in the constrained solution.
* Near a singular ``Jn``, ``M = Jn S1^-1 Jn^T`` loses rank; we damp it,
  ``(M + mu^2 I)^-1`` with ``mu^2 = max(0, eps lambda_max - lambda_min)``
  (``eps = 1e-3``): zero away from singular poses (the constraint then holds
  exactly), growing smoothly as the smallest eigenvalue vanishes.
* Limits: a joint whose rate would cross its range within ``dt`` is held at
  the rate that reaches the limit and the rest re-solved without it; finally
  all rates are scaled by one factor so that none exceeds its speed limit
  (direction kept).
* :func:`relaxed_rates` (not the paper's; the policies' ``critical_clearance``
  option): the same cost without the constraint, the gripper one more
  weighted point. Where a link is about to touch an obstacle, the null space
  of ``Jn`` may hold no motion that takes it away; dropping the constraint
  lets the avoidance term move the gripper off its path.
"""

from __future__ import annotations

import numpy as np


def _normal_equations(
    jacs: np.ndarray, refs: np.ndarray, weights: np.ndarray, reg: float
) -> tuple[np.ndarray, np.ndarray]:
    """``S1`` (n, n) with its ``reg * trace(S1) / n`` diagonal, and ``S2`` (n,)."""
    n = jacs.shape[2]
    s1 = 2.0 * np.einsum("m,mdi,mdj->ij", weights, jacs, jacs)
    s2 = 2.0 * np.einsum("m,mdi,md->i", weights, jacs, refs)
    return s1 + (reg * max(np.trace(s1) / n, 1e-12)) * np.eye(n), s2


def _within_speeds(rates: np.ndarray, speeds: np.ndarray) -> np.ndarray:
    """``rates`` scaled by one factor so that none exceeds its speed limit."""
    return rates * min(1.0, float(np.min(speeds / np.maximum(np.abs(rates), 1e-12))))


def weighted_rates(
    jn: np.ndarray,
    x_dot: np.ndarray,
    jacs: np.ndarray,
    refs: np.ndarray,
    weights: np.ndarray,
    reg: float = 1e-9,
    eps: float = 1e-3,
) -> np.ndarray:
    """Eq. 1 without limits: theta_dot (n,).

    Args:
        jn: gripper Jacobian (dim, n); x_dot: gripper velocity (dim,).
        jacs: joint-point Jacobians (M, dim, n); refs: their reference
            velocities (M, dim); weights: ``k_i`` (M,).
    """
    s1, s2 = _normal_equations(jacs, refs, weights, reg)
    a_jt = np.linalg.solve(s1, jn.T)  # S1^-1 Jn^T (n, dim)
    a_s2 = np.linalg.solve(s1, s2)  # S1^-1 S2 (n,)
    m = jn @ a_jt  # (dim, dim)
    m = 0.5 * (m + m.T)
    lam = np.linalg.eigvalsh(m)
    mu2 = max(0.0, eps * lam[-1] - lam[0])
    j_star = a_jt @ np.linalg.inv(m + mu2 * np.eye(len(m)))  # (n, dim)
    return j_star @ x_dot + a_s2 - j_star @ (jn @ a_s2)


def limited_rates(
    jn: np.ndarray,
    x_dot: np.ndarray,
    jacs: np.ndarray,
    refs: np.ndarray,
    weights: np.ndarray,
    q: np.ndarray,
    limits: np.ndarray,
    speeds: np.ndarray,
    dt: float,
    reg: float = 1e-9,
) -> np.ndarray:
    """Eq. 1 within joint ranges ``+-limits`` (n,) and speed limits (n,): theta_dot (n,).

    ``reg`` as in :func:`weighted_rates`.
    """
    n = len(q)
    low = (-limits - q) / dt  # rates that reach a limit within dt
    high = (limits - q) / dt
    free = np.ones(n, dtype=bool)
    held = np.zeros(n)
    rates = np.zeros(n)
    for _ in range(n):
        if not free.any():
            break
        x_rest = x_dot - jn[:, ~free] @ held[~free]
        ref_rest = refs - jacs[:, :, ~free] @ held[~free]
        sol = weighted_rates(jn[:, free], x_rest, jacs[:, :, free], ref_rest, weights, reg)
        rates = held.copy()
        rates[free] = sol
        scaled = _within_speeds(rates, speeds)
        over = free & ((scaled < low) | (scaled > high))
        if not over.any():
            return scaled
        held[over] = np.clip(scaled[over], low[over], high[over])
        free &= ~over
    return _within_speeds(np.clip(rates, low, high), speeds)


def relaxed_rates(
    jacs: np.ndarray,
    refs: np.ndarray,
    weights: np.ndarray,
    q: np.ndarray,
    limits: np.ndarray,
    speeds: np.ndarray,
    dt: float,
    reg: float = 1e-9,
) -> np.ndarray:
    """``argmin sum_i k_i |Ji theta_dot - X_i_dot|^2`` (no gripper constraint): theta_dot (n,).

    ``jacs`` (M, dim, n), ``refs`` (M, dim), ``weights`` (M,) as in
    :func:`weighted_rates`, the gripper among them; ``reg`` as there. The
    rates are clipped to those that reach a joint limit within ``dt`` and then
    scaled by one factor to the speed limits.
    """
    s1, s2 = _normal_equations(jacs, refs, weights, reg)
    rates = np.clip(np.linalg.solve(s1, s2), (-limits - q) / dt, (limits - q) / dt)
    return _within_speeds(rates, speeds)
