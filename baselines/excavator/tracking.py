"""Joint-rate tracking within the hydraulic limits, and IK with fallbacks.

Tracking: to move from ``q`` to ``q*`` in steps of ``dt`` with joint rates
limited to ``rate_max``, command the rate ``v = lambda (q* - q)`` along the
straight line in joint space (every joint arrives at the same time, at the
speed of the slowest one) with the largest ``lambda`` that keeps

* every rate within ``rate_max``: ``lambda |e_j| <= rate_max_j``;
* the last step exact (dead-beat): ``lambda <= 1 / dt``;
* with acceleration limits ``accel_max`` (rad/s2): every joint able to stop
  at the goal in steps of ``dt`` (``v^2 / (2 a) + v dt / 2 <= |e|``), and
  the rates moved from the current ones (the observed ``qdot``) toward
  those by the largest common fraction that changes none by more than
  ``accel_max_j dt`` (from rest, the joints start along the line);
* with a shared pump (``pump_share``: the fraction of the pump's flow a
  function draws at full rate), the demand ``sum_j |v_j| / rate_max_j
  share_j`` at most 1, so that the pump never scales the rates itself.

Actions are fractions of ``rate_max``, the environments' action convention.
Without acceleration limits this is ``a = (q* - q) / (rate_max dt)`` scaled
down by ``max(1, max |a|)``.

IK: :func:`solve_pose` runs the paper's Newton-Raphson (eq. 13) from the
given start with the swing pointed at the target and the bucket turned to the
target angle (the paper's error vector carries the bucket angle only through
``E(1,1) = c1 (cos beta - cos beta_d)`` and ``E(3,1) = sin beta - sin beta_d``:
near 90 deg of swing the first vanishes and the second cannot tell ``beta``
from ``pi - beta``, so a start far in bucket angle may not converge; the
aligned start removes that), then, if that fails, the
projected variant and the damped (Levenberg-Marquardt) one from the rest
pose: a policy needs an answer whenever one exists, and says so when none
does.
"""

from __future__ import annotations

import numpy as np

from motiongym.baselines.excavator.newton_raphson import IKResult, solve
from motiongym.envs.excavator.config import Machine
from motiongym.envs.excavator.kinematics import swing_for_target


def track(
    q: np.ndarray,
    q_goal: np.ndarray,
    m: Machine,
    dt: float,
    qdot: np.ndarray | None = None,
    accel_max: np.ndarray | None = None,
    pump_share: np.ndarray | None = None,
) -> np.ndarray:
    """Normalised joint-rate action (4,) toward ``q_goal`` (synchronised, dead-beat).

    ``accel_max`` (4,) rad/s2, with the current rates ``qdot`` (4,): brake in
    time for the goal and change no rate by more than ``accel_max dt``.
    ``pump_share`` (4,): keep the pump's demand at most 1.
    """
    rate_max = np.array(m.rate_max)
    error = np.asarray(q_goal, float) - np.asarray(q, float)
    raw = error / (rate_max * dt)
    scale = max(1.0, float(np.max(np.abs(raw))))
    if pump_share is not None:
        scale = max(scale, float(np.sum(np.abs(raw) * np.asarray(pump_share, float))))
    if accel_max is None:
        return (raw / scale).astype(np.float32)
    accel = np.asarray(accel_max, float)
    moving = np.abs(error) > 1e-12
    lam = 1.0 / (dt * scale)
    if np.any(moving):
        # Stopping from rate v at accel a in steps of dt takes v^2 / (2 a) + v dt / 2.
        a, e = accel[moving], np.abs(error[moving])
        stop = a * (np.sqrt(0.25 * dt * dt + 2.0 * e / a) - 0.5 * dt)
        lam = min(lam, float(np.min(stop / e)))
    rate = lam * error
    if qdot is not None:
        # Move from the current rates toward the wanted ones by the largest common
        # fraction the acceleration limits allow: from rest the joints start along
        # the straight line (a per-joint clip would bend the path).
        current = np.asarray(qdot, float)
        change = np.abs(rate - current)
        fraction = min(
            1.0,
            float(np.min(np.where(change > 1e-12, accel * dt / np.maximum(change, 1e-12), np.inf))),
        )
        rate = current + fraction * (rate - current)
    return np.clip(rate / rate_max, -1.0, 1.0).astype(np.float32)


def solve_pose(
    tip: np.ndarray,
    beta: float,
    m: Machine,
    q_start: np.ndarray | None = None,
    max_iterations: int = 30,
    base: np.ndarray | None = None,
) -> IKResult:
    """Joint angles for the tip pose, trying NR, projected NR and LM in turn.

    ``tip`` is in the reference frame O; ``base`` is ``H_M^O`` (eq. 1-2, the
    machine on a slope; default identity), ``beta`` is measured in frame M.
    """
    tip = np.asarray(tip, float)
    local = tip if base is None else np.linalg.solve(base, np.append(tip, 1.0))[:3]
    starts = []
    for q in (q_start, m.q_rest, m.q_ready):
        if q is None:
            continue
        q = np.array(q, float)
        q[0] = swing_for_target(local[0], local[1], m)
        q[3] = beta - q[1] - q[2]  # bucket already at the target angle
        starts.append(q)
    best = None
    for q0 in starts:
        for method, clamp in (("newton", False), ("newton", True), ("lm", True)):
            result = solve(
                tip,
                beta,
                m,
                q0=q0,
                base=base,
                method=method,
                clamp=clamp,
                max_iterations=max_iterations,
            )
            if result.converged:
                return result
            if best is None or result.position_error < best.position_error:
                best = result
    assert best is not None, "q_rest and q_ready always give starts"
    return best
