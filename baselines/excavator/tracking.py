"""Joint-rate tracking within the hydraulic limits, and IK with fallbacks.

Tracking: to move from ``q`` to ``q*`` in steps of ``dt`` with joint rates
limited to ``rate_max``, command ``a = (q* - q) / (rate_max dt)`` scaled
down by ``max(1, max |a|)``: every joint arrives at the same time (a
straight line in joint space) at the speed of the slowest one, and the last
step lands exactly (dead-beat). Actions are fractions of ``rate_max``, the
environments' action convention.

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


def track(q: np.ndarray, q_goal: np.ndarray, m: Machine, dt: float) -> np.ndarray:
    """Normalised joint-rate action (4,) toward ``q_goal`` (synchronised, dead-beat)."""
    raw = (np.asarray(q_goal, float) - np.asarray(q, float)) / (np.array(m.rate_max) * dt)
    scale = max(1.0, float(np.max(np.abs(raw))))
    return (raw / scale).astype(np.float32)


def solve_pose(
    tip: np.ndarray,
    beta: float,
    m: Machine,
    q_start: np.ndarray | None = None,
    max_iterations: int = 30,
) -> IKResult:
    """Joint angles for the tip pose, trying NR, projected NR and LM in turn."""
    tip = np.asarray(tip, float)
    starts = []
    for q in (q_start, m.q_rest, m.q_ready):
        if q is None:
            continue
        q = np.array(q, float)
        q[0] = swing_for_target(tip[0], tip[1], m)
        q[3] = beta - q[1] - q[2]  # bucket already at the target angle
        starts.append(q)
    best = None
    for q0 in starts:
        for method, clamp in (("newton", False), ("newton", True), ("lm", True)):
            result = solve(
                tip, beta, m, q0=q0, method=method, clamp=clamp, max_iterations=max_iterations
            )
            if result.converged:
                return result
            if best is None or result.position_error < best.position_error:
                best = result
    return best
