"""Certified distance between two PUMA arms over a motion, not only at samples.

**The bound.** A point ``p`` of body ``k`` moves, when the joints move, with
velocity ``sum_j qdot_j z_j x (p - o_j)`` over the joints ``j <= k`` (``o_j``
a point of joint ``j``'s axis, ``z_j`` its unit direction), so its speed is at
most ``sum_j |qdot_j| |p - o_j|``. With ``rho[j, k]`` an upper bound on
``|p - o_j|`` over every point of body ``k``'s capsule segment and every
configuration, a motion whose joints vary by ``TV_j`` in total (their total
variation; ``|q_j(b) - q_j(a)|`` for a straight joint-space move) moves every
point of body ``k`` by at most ``delta_k = sum_j rho[j, k] TV_j`` (Schwarzer,
Saha & Latombe, "Adaptive dynamic collision checking for single and multiple
articulated robots in complex environments", IEEE T-RO 21(3), 2005, the same
bound). ``rho`` follows from the DH table alone (triangle inequality along
the chain: ``|o_{i+1} - o_i| = sqrt(d_i^2 + a_i^2)`` for consecutive frame
origins, plus the end point's norm in its own frame; the distance to a point
of a segment is largest at an end point), so it holds in every configuration.

Every configuration of a move is within half its variation of the move's
midpoint, so over two moves the pair distance satisfies
``d_ij >= d_ij(mid) - delta1_i / 2 - delta2_j / 2``: a move is *clear* when
that bound exceeds the margin for every pair, *colliding* when an evaluated
configuration is within the margin, and otherwise halved (the longer of the
two, or both together for simultaneous motion) until one of the two holds or
the halves move less than ``resolution`` (then reported colliding: a
conservative answer, never a missed contact). The answer is exact up to
``resolution`` (default 1 mm): a motion reported clear never comes within the
margin; one reported colliding comes within ``margin + resolution``.

Configurations between samples are the straight joint-space interpolation the
environment uses (:meth:`motiongym.envs.dual_arm.world.DualArmWorld.config`):
a motion is a span ``[p_a, p_b]`` of fractional sample indices.
"""

from __future__ import annotations

import math

import numpy as np

from motiongym.envs.dual_arm import model

RESOLUTION = 1e-3  # m


def _rho() -> np.ndarray:
    """(6, 5) bound on the distance from joint j's axis to checked body k's segment."""
    step = np.hypot(model.DH[:, 0], model.DH[:, 1])  # |o_{i+1} - o_i|, (6,)
    rho = np.zeros((6, 5))
    for col, body in enumerate(model.CHECKED):  # body k = 2..6, frame B_k at o_k
        start, end, _ = model.LINKS[body - 1]
        reach = max(math.dist(start, (0, 0, 0)), math.dist(end, (0, 0, 0)))
        for j in range(1, body + 1):  # joints 1..k move body k
            rho[j - 1, col] = sum(step[j - 1 : body - 1]) + reach
    return rho


RHO = _rho()


def configs(samples: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Joint angles (..., 6) at fractional sample indices ``p`` (...,), clamped to the path."""
    n = len(samples) - 1
    p = np.clip(np.asarray(p, float), 0.0, n)
    k = np.minimum(p.astype(np.int64), max(n - 1, 0))
    f = (p - k)[..., None]
    return samples[k] + f * (samples[np.minimum(k + 1, n)] - samples[k])


def variation(samples: np.ndarray, pa: np.ndarray, pb: np.ndarray) -> np.ndarray:
    """Total variation (..., 6) of each joint over the spans ``[pa, pb]`` of the path."""
    pa, pb = np.broadcast_arrays(np.asarray(pa, float), np.asarray(pb, float))
    out = np.zeros(pa.shape + (6,))
    slopes = np.abs(np.diff(samples, axis=0))  # (N, 6)
    n = len(slopes)
    lo, hi = np.clip(pa, 0.0, n), np.clip(pb, 0.0, n)
    # Whole and partial pieces: sum over pieces k of overlap([k, k+1], [lo, hi]) * slope_k.
    first = np.floor(lo).astype(np.int64)
    last = np.minimum(np.ceil(hi).astype(np.int64), n)
    for index in np.ndindex(pa.shape):
        for k in range(first[index], last[index]):
            overlap = min(hi[index], k + 1) - max(lo[index], k)
            if overlap > 0:
                out[index] += overlap * slopes[k]
    return out


def span_variation(slopes: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """:func:`variation` of one span ``[lo, hi]`` from the pieces' ``|dq|`` (N, 6), fast."""
    n = len(slopes)
    lo, hi = min(max(lo, 0.0), n), min(max(hi, 0.0), n)
    k0, k1 = int(lo), min(math.ceil(hi), n)
    if k1 <= k0:
        return np.zeros(6)
    if k1 - k0 == 1:
        return (hi - lo) * slopes[k0]
    out = (k0 + 1 - lo) * slopes[k0] + (hi - (k1 - 1)) * slopes[k1 - 1]
    if k1 - k0 > 2:
        out = out + slopes[k0 + 1 : k1 - 1].sum(axis=0)
    return out


def body_motion(tv: np.ndarray) -> np.ndarray:
    """(..., 5) how far any point of each checked body can move for variations (..., 6)."""
    return tv @ RHO


def _lower_bound(d: np.ndarray, move1: np.ndarray, move2: np.ndarray) -> np.ndarray:
    """min_ij d_ij - move1_i / 2 - move2_j / 2 over pairs: (...,) from (..., 5, 5), (..., 5)."""
    return (d - move1[..., :, None] / 2 - move2[..., None, :] / 2).min(axis=(-2, -1))


Box = tuple[float, float, float, float]  # robot 1's span, robot 2's span (fractional samples)


def _halving(
    samples1: np.ndarray,
    samples2: np.ndarray,
    boxes: list[Box],
    margin: float,
    resolution: float,
    split,
) -> np.ndarray:
    """Bound, then halve (``split``) every box the bound cannot clear, until decided.

    One verdict per given box, (n,) bool; the halves of box ``i`` answer for
    ``i`` (a box is decided colliding by any of its pieces, clear by all).
    """
    out = np.zeros(len(boxes), dtype=bool)
    todo = [(i, box) for i, box in enumerate(boxes)]
    while todo:
        owner = np.array([i for i, _ in todo])
        b = np.array([box for _, box in todo])  # (n, 4)
        q1 = configs(samples1, b[:, :2].mean(axis=1))
        q2 = configs(samples2, b[:, 2:].mean(axis=1))
        d = model.pair_distances(q1, q2)  # (n, 5, 5)
        out[owner[d.min(axis=(-2, -1)) <= margin]] = True
        m1 = body_motion(variation(samples1, b[:, 0], b[:, 1]))
        m2 = body_motion(variation(samples2, b[:, 2], b[:, 3]))
        todo = []
        for i in np.flatnonzero(_lower_bound(d, m1, m2) <= margin):
            if out[owner[i]]:
                continue  # decided
            w1, w2 = m1[i].max(), m2[i].max()
            if (w1 + w2) / 2 < resolution:
                out[owner[i]] = True  # within resolution of the margin: conservative
                continue
            todo += [(owner[i], half) for half in split(*b[i], w1, w2)]
        todo = [(i, box) for i, box in todo if not out[i]]
    return out


def _together(lo1: float, hi1: float, lo2: float, hi2: float, w1: float, w2: float) -> list:
    c1, c2 = (lo1 + hi1) / 2, (lo2 + hi2) / 2
    return [(lo1, c1, lo2, c2), (c1, hi1, c2, hi2)]


def _longer(lo1: float, hi1: float, lo2: float, hi2: float, w1: float, w2: float) -> list:
    if w1 >= w2:
        c = (lo1 + hi1) / 2
        return [(lo1, c, lo2, hi2), (c, hi1, lo2, hi2)]
    c = (lo2 + hi2) / 2
    return [(lo1, hi1, lo2, c), (lo1, hi1, c, hi2)]


def simultaneous_collide(
    samples1: np.ndarray,
    span1: tuple[float, float],
    samples2: np.ndarray,
    span2: tuple[float, float],
    margin: float,
    resolution: float = RESOLUTION,
) -> bool:
    """Do the arms come within ``margin`` while both move at once over one step?

    Robot r moves uniformly over ``span_r`` as time runs through the step (both
    together, as in one environment step): the two spans are halved together.
    """
    return bool(_halving(samples1, samples2, [(*span1, *span2)], margin, resolution, _together)[0])


def simultaneous_collide_many(
    samples1: np.ndarray,
    spans1: np.ndarray,
    samples2: np.ndarray,
    spans2: np.ndarray,
    margin: float,
    resolution: float = RESOLUTION,
) -> np.ndarray:
    """:func:`simultaneous_collide` of many steps at once: spans (n, 2) each -> (n,) bool,
    the same verdicts (each step's boxes are halved as alone), one bound per level."""
    boxes = [(*a, *b) for a, b in zip(np.asarray(spans1, float).tolist(),
                                      np.asarray(spans2, float).tolist(), strict=True)]  # fmt: skip
    return _halving(samples1, samples2, boxes, margin, resolution, _together)


def spans_collide(
    samples1: np.ndarray,
    span1: tuple[float, float],
    samples2: np.ndarray,
    span2: tuple[float, float],
    margin: float,
    resolution: float = RESOLUTION,
) -> bool:
    """Does any configuration of robot 1 over ``span1`` come within ``margin`` of any
    configuration of robot 2 over ``span2`` (each a span of fractional samples)?
    The span whose bodies move farther is halved first."""
    return bool(_halving(samples1, samples2, [(*span1, *span2)], margin, resolution, _longer)[0])
