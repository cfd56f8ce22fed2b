"""IK studies of the excavator reproduction (paper 002, eq. 9-13).

Random reachable poses from several starts, the arm near its singularity,
unreachable targets, a flipped-bucket target, and targets sampled in
Cartesian space (reasons, convergence of the solvable, wrong poses on both
bucket axes). Used by :mod:`.excavator`.
"""

from __future__ import annotations

import collections
import math
import time
from typing import Any

import numpy as np

from motiongym.baselines.excavator import newton_raphson as nr
from motiongym.envs.excavator.config import DEFAULT_MACHINE as M
from motiongym.envs.excavator.kinematics import (
    bucket_angle,
    desired_pose,
    forward,
    swing_for_target,
)


def random_poses(n: int, seed: int = 0) -> dict[str, Any]:
    """IK on ``n`` reachable poses for several start/method choices."""
    rng = np.random.default_rng(seed)
    qs = rng.uniform(M.q_min, M.q_max, size=(n, 4))
    variants: dict[str, dict[str, Any]] = {
        "newton_rest": dict(method="newton", align=False),
        "newton_rest_aligned": dict(method="newton", align=True, align_bucket=True),
        "newton_rest_swing_aligned": dict(method="newton", align=True),
        "newton_projected": dict(method="newton", align=True, clamp=True),
        "lm": dict(method="lm", align=True),
    }
    out = {}
    for name, v in variants.items():
        reasons: collections.Counter[str] = collections.Counter()
        iterations: list[int] = []
        wrong = 0
        start = time.perf_counter()
        for q in qs:
            h = forward(q, M)
            q0 = np.array(M.q_rest)
            if v["align"]:
                q0[0] = swing_for_target(h[0, 3], h[1, 3], M)
            if v.get("align_bucket"):
                q0[3] = bucket_angle(q) - q0[1] - q0[2]
            r = nr.solve(
                h[:3, 3], bucket_angle(q), M, q0=q0, method=v["method"], clamp=v.get("clamp", False)
            )
            reasons[r.reason] += 1
            if r.converged:
                iterations.append(r.iterations)
                h_d = desired_pose(h[:3, 3], bucket_angle(q), M)
                wrong += not _same_pose(forward(r.q, M), h_d)
        elapsed = time.perf_counter() - start
        out[name] = {
            "n": n,
            "converged_rate": reasons["converged"] / n,
            "reasons": dict(reasons),
            "iterations_median": float(np.median(iterations)) if iterations else None,
            "iterations_max": int(max(iterations)) if iterations else None,
            "wrong_pose_reported_converged": wrong,
            "ms_per_solve": 1e3 * elapsed / n,
        }
    return out


def near_singular(n: int, seed: int = 2) -> dict[str, Any]:
    """NR vs LM on poses with the stick within 0.005-0.1 rad of the boom line.

    Boom and stick aligned is the arm's singularity; the real stick range
    keeps 0.52 rad away from it, so this uses the machine with the stick's
    upper limit moved to 0 (a geometric study, not a reachable pose).
    """
    from motiongym.envs.excavator.config import Machine

    machine = Machine(q_max=(math.pi, M.q_max[1], 0.0, M.q_max[3]))
    rng = np.random.default_rng(seed)
    cases = []
    for _ in range(n):
        q = rng.uniform(machine.q_min, machine.q_max)
        q[2] = -rng.uniform(0.005, 0.1)
        cases.append(q)
    out = {}
    for method in ("newton", "lm"):
        reasons: collections.Counter[str] = collections.Counter()
        iterations: list[int] = []
        for q in cases:
            h = forward(q, machine)
            q0 = np.array(machine.q_rest)
            q0[0] = swing_for_target(h[0, 3], h[1, 3], machine)
            r = nr.solve(
                h[:3, 3], bucket_angle(q), machine, q0=q0, method=method, max_iterations=50
            )
            reasons[r.reason] += 1
            iterations += [r.iterations] if r.converged else []
        out[method] = {
            "n": n,
            "converged_rate": reasons["converged"] / n,
            "reasons": dict(reasons),
            "iterations_median": float(np.median(iterations)) if iterations else None,
        }
    return out


def unreachable(n: int, seed: int = 1) -> dict[str, Any]:
    """Targets beyond reach (1-4 m past the boom+stick annulus) or inside it."""
    rng = np.random.default_rng(seed)
    reasons: collections.Counter[str] = collections.Counter()
    false_success = 0
    for k in range(n):
        beta = rng.uniform(-math.pi, math.pi)
        azimuth = rng.uniform(-math.pi, math.pi)
        r = M.reach + rng.uniform(1.0, 4.0) if k % 2 == 0 else rng.uniform(0.0, 0.5)
        z = rng.uniform(-2.0, 2.0) if k % 2 == 0 else rng.uniform(6.0, 8.0)
        tip = np.array([r * math.cos(azimuth), r * math.sin(azimuth), z])
        result = nr.solve(tip, beta, M, max_iterations=50)
        reasons[result.reason] += 1
        false_success += result.converged
    return {"n": n, "reasons": dict(reasons), "reported_converged": false_success}


def _same_pose(h: np.ndarray, h_d: np.ndarray, tol: float = 1e-3) -> bool:
    """Tip within ``tol`` m and both bucket axes (x, z) within ``tol`` rad."""
    axes = [math.acos(min(float(h[:3, k] @ h_d[:3, k]), 1.0)) for k in (0, 2)]
    return bool(np.linalg.norm(h[:3, 3] - h_d[:3, 3]) < tol + 1e-9 and max(axes) < tol + 1e-9)


def cartesian_targets(n: int, seed: int) -> list[tuple[np.ndarray, float]]:
    """Tips uniform (by area) in a cylinder of radius 11 m about the swing axis, z in
    [-8, 11] m (the machine's whole envelope and beyond), beta uniform in [-pi, pi)."""
    rng = np.random.default_rng(seed)
    r = 11.0 * np.sqrt(rng.uniform(size=n))
    phi = rng.uniform(-math.pi, math.pi, size=n)
    z = rng.uniform(-8.0, 11.0, size=n)
    beta = rng.uniform(-math.pi, math.pi, size=n)
    return [
        (np.array([r[k] * math.cos(phi[k]), r[k] * math.sin(phi[k]), z[k]]), float(beta[k]))
        for k in range(n)
    ]


def cartesian_ik(n: int, seed: int = 12) -> dict[str, Any]:
    """IK on ``n`` targets sampled in Cartesian space (most of them unreachable).

    Starts: the paper's literal rest pose; the rest pose with the swing
    pointed at the target; the policies' fallback chain
    (:func:`~motiongym.baselines.excavator.tracking.solve_pose`). Per start:
    the reasons, the convergence rate over the targets with an in-limit
    solution (closed form), a "no solution" reason given where the closed form
    has one (must be 0), and poses reported converged whose tip or either
    bucket axis (matrix product of eq. 4) is off (must be 0).
    """
    from motiongym.baselines.excavator.tracking import solve_pose

    targets = cartesian_targets(n, seed)
    solvable = [nr.solution_exists(tip, beta, M) for tip, beta in targets]
    starts = {
        "newton_rest": lambda tip, beta: nr.solve(tip, beta, M),
        "newton_rest_swing_aligned": lambda tip, beta: nr.solve(
            tip, beta, M, q0=np.array((swing_for_target(tip[0], tip[1], M), *M.q_rest[1:]))
        ),
        "fallback_chain": lambda tip, beta: solve_pose(tip, beta, M),
    }
    out: dict[str, Any] = {"n": n, "seed": seed, "with_in_limit_solution": int(sum(solvable))}
    for name, solver in starts.items():
        reasons: collections.Counter[str] = collections.Counter()
        wrong, denied = 0, 0
        for (tip, beta), exists in zip(targets, solvable, strict=True):
            r = solver(tip, beta)
            reasons[r.reason] += 1
            denied += exists and r.reason in nr.NO_SOLUTION
            if r.converged:
                wrong += not _same_pose(forward(r.q, M), desired_pose(tip, beta, M))
        out[name] = {
            "reasons": dict(reasons),
            "converged_rate_of_solvable": reasons["converged"] / max(sum(solvable), 1),
            "no_solution_reason_with_in_limit_solution": int(denied),
            "wrong_pose_reported_converged": wrong,
        }
    return out


def issue_case() -> dict[str, Any]:
    """A flipped-bucket target (a review's case): ``solve([-0.028, 0.09, -3.665], -0.078)``
    from rest."""
    tip, beta = np.array([-0.028, 0.09, -3.665]), -0.078
    r = nr.solve(tip, beta, M)
    return {
        "converged": r.converged,
        "reason": r.reason,
        "q2+q3+q4": float(r.q[1:].sum()),
        "frame_rotation_error_rad": r.angle_error,
        "in_limit_solution_exists": r.solution_exists,
    }
