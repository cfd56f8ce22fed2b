"""An independent continuous-time clearance check of the dual-arm cell, for the tests.

Shares no code with the package's geometry: its own forward kinematics of the
PUMA 560 from the published standard DH table (Corke & Armstrong-Helouvry,
"A search for consensus among model parameters reported for the PUMA 560
robot", ICRA 1994: d = 0.672*, 0, 0.15005, 0.4318, 0, 0 m; a = 0, 0.4318,
0.0203, 0, 0, 0 m; alpha = +90, 0, -90, +90, -90, 0 deg; *the shoulder height
of the Robotics Toolbox for Python), its own capsule-to-capsule distance
(closest points of two segments, clamped parameters, in the manner of Ericson,
"Real-Time Collision Detection", 5.1.9), and dense sampling in time of the
motion the environment executes: the joints move linearly between the
configurations the environment reports at consecutive steps (a pure delay
advances each arm by 0 or 1 whole sample per step, so a step's motion is the
straight joint-space move between its two end configurations).

The cell's bodies are restated here as the environment defines them (bases at
x = +-0.65 m, robot 1 turned by pi about z; five checked capsules per arm:
upper arm, forearm, wrist roll, wrist bend, gripper, each two end points in its
body frame ``B_k = F_{k-1} Rz(q_k)`` and a radius).
"""

from __future__ import annotations

import numpy as np

D = np.array([0.672, 0.0, 0.15005, 0.4318, 0.0, 0.0])
A = np.array([0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0])
ALPHA = np.deg2rad([90.0, 0.0, -90.0, 90.0, -90.0, 0.0])
BASES = ((0.65, np.pi), (-0.65, 0.0))  # (x, yaw) of robot 1 and robot 2
# Checked bodies k = 2..6: (start, end, radius) in the frame B_k, m.
CAPSULES = (
    ((0.0, 0.0, 0.0), (0.4318, 0.0, 0.0), 0.075),
    ((0.0203, 0.0, 0.15005), (0.0203, 0.33, 0.15005), 0.055),
    ((0.0, 0.0, 0.33), (0.0, 0.0, 0.40), 0.05),
    ((0.0, 0.0, -0.04), (0.0, 0.0, 0.04), 0.045),
    ((0.0, 0.0, 0.05), (0.0, 0.0, 0.20), 0.035),
)
_P = np.array([c[0] for c in CAPSULES])  # (5, 3)
_Q = np.array([c[1] for c in CAPSULES])
_R = np.array([c[2] for c in CAPSULES])


def _rot_z(theta: np.ndarray) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    out = np.zeros(theta.shape + (4, 4))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 2, 2] = out[..., 3, 3] = 1.0
    return out


def _dh_fixed(k: int) -> np.ndarray:
    """Tz(d_k) Tx(a_k) Rx(alpha_k)."""
    ca, sa = np.cos(ALPHA[k]), np.sin(ALPHA[k])
    return np.array([[1, 0, 0, A[k]], [0, ca, -sa, 0], [0, sa, ca, D[k]], [0, 0, 0, 1.0]])


def capsules(q: np.ndarray, robot: int) -> tuple[np.ndarray, np.ndarray]:
    """World end points (n, 5, 3) x 2 of the checked capsules at configurations (n, 6)."""
    x, yaw = BASES[robot]
    frame = _rot_z(np.full(len(q), yaw))
    frame[:, 0, 3] = x
    starts, ends = [], []
    for k in range(6):
        body = frame @ _rot_z(q[:, k])
        if k >= 1:
            rot, pos = body[:, :3, :3], body[:, :3, 3]
            starts.append(np.einsum("nij,j->ni", rot, _P[k - 1]) + pos)
            ends.append(np.einsum("nij,j->ni", rot, _Q[k - 1]) + pos)
        frame = body @ _dh_fixed(k)
    return np.stack(starts, 1), np.stack(ends, 1)


def segment_distance(p1, q1, p2, q2) -> np.ndarray:
    """Distance between segments [p1, q1] and [p2, q2], broadcast over leading axes."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.einsum("...k,...k", d1, d1)
    e = np.einsum("...k,...k", d2, d2)
    f = np.einsum("...k,...k", d2, r)
    c = np.einsum("...k,...k", d1, r)
    b = np.einsum("...k,...k", d1, d2)
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 1e-14, np.clip((b * f - c * e) / denom, 0.0, 1.0), 0.0)
        t = np.where(e > 1e-14, (b * s + f) / e, 0.0)
        # t outside [0, 1]: clamp it and recompute s for the clamped t.
        s = np.where(t < 0.0, np.clip(-c / np.where(a > 0, a, 1.0), 0.0, 1.0), s)
        s = np.where(t > 1.0, np.clip((b - c) / np.where(a > 0, a, 1.0), 0.0, 1.0), s)
    t = np.clip(t, 0.0, 1.0)
    gap = (p1 + s[..., None] * d1) - (p2 + t[..., None] * d2)
    return np.sqrt(np.einsum("...k,...k", gap, gap))


def clearance(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Least capsule-to-capsule distance between the arms (negative: penetration), (n,)."""
    s1, e1 = capsules(q1, 0)
    s2, e2 = capsules(q2, 1)
    d = segment_distance(s1[:, :, None], e1[:, :, None], s2[:, None], e2[:, None])
    return (d - _R[:, None] - _R[None, :]).min(axis=(1, 2))


def motion_clearance(q1: np.ndarray, q2: np.ndarray, sub: int = 40, refine: int = 50) -> float:
    """Least clearance over the motion through configurations (T + 1, 6) of each arm,
    ``sub`` instants per step, steps whose sampled clearance is within 5 mm of the least
    sampled again at ``sub * refine`` instants."""
    tau = np.arange(sub) / sub

    def dense(steps: np.ndarray, frac: np.ndarray) -> np.ndarray:
        a1, b1, a2, b2 = q1[steps], q1[steps + 1], q2[steps], q2[steps + 1]
        f = frac[None, :, None]
        c1 = (a1[:, None] + f * (b1 - a1)[:, None]).reshape(-1, 6)
        c2 = (a2[:, None] + f * (b2 - a2)[:, None]).reshape(-1, 6)
        return clearance(c1, c2).reshape(len(steps), len(frac))

    steps = np.arange(len(q1) - 1)
    coarse = np.concatenate([dense(steps, tau).min(axis=1)])
    least = min(float(coarse.min()), float(clearance(q1[-1:], q2[-1:])[0]))
    near = steps[coarse <= least + 5e-3]
    fine = np.arange(sub * refine + 1) / (sub * refine)
    for chunk in np.array_split(near, max(1, len(near) // 8)):
        if len(chunk):
            least = min(least, float(dense(chunk, fine).min()))
    return least
