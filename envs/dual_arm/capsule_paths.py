"""Capsules swept along whole sampled trajectories, and where two sweeps collide.

The task sampler's hot path (:func:`motiongym.envs.dual_arm.task.sample_pair`
runs it on every reset, often more than once): the 5 checked capsules of an
arm at every 20 ms sample of its trajectory, and the exact test "is
``d(R1, R2) <= margin``" (paper eqs. 1-2) at many pairs of instants. Same
numbers as :func:`.model.link_segments` and :func:`.model.segment_pair_distances`
(to rounding), in far fewer NumPy operations: arrays are laid out with the
samples last, so that every operation runs over all samples at once.

Kinematics (:func:`sweep_points`): the DH chain of :mod:`.model`, ``F_k =
B_k L_k`` with the body frame ``B_k = F_{k-1} Rz(q_k)`` and ``L_k = Tz(d_k)
Tx(a_k) Rx(alpha_k)``, kept as the origin ``p`` and the axes ``x``, ``y``,
``z`` (each (3, n)), with the pair ``x + i y`` as one complex array so that
``Rz(q)`` is one complex product: ``(x + i y) e^{-iq} = (c x + s y) + i (c y
- s x)``. ``L_k`` then only shifts the origin and, through ``Rx(alpha)``, mixes
``y`` and ``z`` (PUMA: alpha in {0, +-pi/2}; coefficients within 1e-12 of 0
or +-1 are taken exactly). A capsule end point, given in ``B_k``
(``model.LINKS``), is taken in ``B_k`` or, as ``L_k^{-1} e``, in ``F_k``,
whichever has fewer non-zero coordinates: for the PUMA one or none, so each
end point costs at most a product and a sum over all samples.

Collision (:func:`colliding_instants`, :func:`schedules_collide`), exact,
in three stages, each over all instants at once:

1. the arms' extents along x (the axis between the bases, paper eq. 3):
   an instant at which they are more than ``margin`` apart is clear (about
   two thirds of the instants of a sampled pair);
2. bounding spheres about the capsule centres, radius ``h + r`` (half length
   plus radius), clear a pair when ``|c_i - c_j| - (h_i + r_i + h_j + r_j) >
   margin``; and ``|c_i - c_j| <= r_i + r_j + margin`` proves a collision
   (the centres are points of the segments);
3. every remaining pair gets the exact segment distance
   (:func:`motiongym.envs.geometry.closest_points_between_segments`), all in
   one call.

Clearing bounds are tested 1e-9 m beyond the margin and the collision bound
1e-9 m inside it, so rounding never decides: the answer is the exact one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from motiongym.envs.dual_arm import model
from motiongym.envs.geometry import closest_points_between_segments

_SLACK = 1e-9  # m: the broad phase keeps pairs up to this much beyond the margin


def _snap(v: float) -> float:
    """``v``, with values within 1e-12 of 0, 1 or -1 made exact."""
    for exact in (0.0, 1.0, -1.0):
        if abs(v - exact) < 1e-12:
            return exact
    return v


# Per joint: (d, a, cos alpha, sin alpha).
_CHAIN = tuple(
    (float(d), float(a), _snap(math.cos(alpha)), _snap(math.sin(alpha))) for d, a, alpha in model.DH
)


def _end_point_plan() -> dict[int, list[tuple[int, int, str, tuple[float, float, float]]]]:
    """Per joint index k: the end points of body k + 1 as (capsule, end, frame, coords)."""
    plan: dict[int, list] = {}
    for i, body in enumerate(model.CHECKED):
        inv = np.linalg.inv(model._LINK[body - 1])
        ends = model.LINKS[body - 1][:2]  # (a, b): the row without its radius
        for end in range(2):
            in_b = tuple(float(v) for v in ends[end])
            in_f = tuple(_snap(float(v)) for v in (inv @ np.array([*in_b, 1.0]))[:3])
            nonzero_b, nonzero_f = sum(v != 0 for v in in_b), sum(v != 0 for v in in_f)
            frame, coords = ("B", in_b) if nonzero_b <= nonzero_f else ("F", in_f)
            plan.setdefault(body - 1, []).append((i, end, frame, coords))
    return plan


_PLAN = _end_point_plan()
_BASES = tuple(model.base_transform(r) for r in range(2))
_RSUM = (model.RADII[:, None] + model.RADII[None, :]).ravel()  # (25,)
_REACH = model._REACH.ravel()  # (25,)


def _terms(coefs: tuple[float, ...]) -> tuple[tuple[int, float], ...]:
    """The non-zero ``(index, coefficient)`` of ``coefs``."""
    return tuple((i, c) for i, c in enumerate(coefs) if c != 0.0)


def _sum(terms: tuple[tuple[int, float], ...], arrays: tuple) -> np.ndarray:
    """``sum c * arrays[i]`` over ``terms`` (unit coefficients without a product)."""
    out: np.ndarray | None = None
    for i, c in terms:
        term = arrays[i] if c == 1.0 else -arrays[i] if c == -1.0 else c * arrays[i]
        out = term if out is None else out + term
    assert out is not None, "no non-zero term"
    return out


# Per joint k: (d, a, rx, y' terms over (y, z), z' terms over (y, z), end points) with
# end points (end, capsule, in F_k?, terms over (x, y, z)) of body k + 1.
_STEPS = tuple(
    (
        d,
        a,
        not (sa == 0.0 and ca == 1.0),
        _terms((ca, sa)),
        _terms((-sa, ca)),
        tuple((end, i, frame == "F", _terms(coords)) for i, end, frame, coords in _PLAN.get(k, ())),
    )
    for k, (d, a, ca, sa) in enumerate(_CHAIN)
)


def sweep_points(q: np.ndarray, robot: int | np.ndarray) -> np.ndarray:
    """Capsule end points at joint samples ``q`` (n, 6), rad.

    Args:
        q: joint angles (n, 6), rad.
        robot: 0 or 1 (base frame, paper eq. 3), or one per sample (n,) to do
            samples of both arms in one batch.
    Returns:
        (2, 3, 5, n), m, world frame: [end a/b, xyz, capsule (order
        ``model.CHECKED``), sample].
    """
    qt = np.asarray(q, float).T  # (6, n)
    n = qt.shape[1]
    rot = np.empty((6, n), complex)  # cos q - i sin q
    np.cos(qt, out=rot.real)
    np.sin(-qt, out=rot.imag)
    if isinstance(robot, (int, np.integer)):
        base = _BASES[robot][:3, :, None]  # (3, 4, 1)
    else:
        base = np.stack(_BASES, axis=-1)[:3, :, robot]  # (3, 4, n)
    w = base[:, 0] + 1j * base[:, 1]  # x + i y, (3, 1 or n) then (3, n)
    z, p = base[:, 2], base[:, 3]
    out = np.empty((2, 3, 5, n))
    for k, (d, a, rx, y_terms, z_terms, ends) in enumerate(_STEPS):
        b = w * rot[k]  # axes of B_k: x + i y; z is z_{k-1}
        p_body, axes_body = p, (b.real, b.imag, z)
        if a:
            p = p + a * b.real
        if d:
            p = p + d * z
        if rx:  # Rx(alpha): y' = ca y + sa z, z' = ca z - sa y
            yz = (b.imag, z)
            w = np.empty((3, n), complex)
            w.real = b.real
            w.imag = _sum(y_terms, yz)
            z = _sum(z_terms, yz)
        else:
            w = b
        for end, i, in_f, terms in ends:
            origin, axes = (p, (w.real, w.imag, z)) if in_f else (p_body, axes_body)
            if terms:
                np.add(origin, _sum(terms, axes), out=out[end, :, i])
            else:
                out[end, :, i] = origin
    return out


def capsule_points(q: np.ndarray, robot: int) -> tuple[np.ndarray, np.ndarray]:
    """End points ``(a, b)`` of the 5 checked capsules, each (..., 5, 3), m, world
    frame, for joint angles ``q`` (..., 6): as ``model.link_segments``."""
    q = np.asarray(q, float)
    pts = sweep_points(q.reshape(-1, 6), robot)  # (2, 3, 5, n)
    a, b = (pts[e].transpose(2, 1, 0).reshape(q.shape[:-1] + (5, 3)) for e in range(2))
    return a, b


@dataclass(frozen=True)
class Sweep:
    """One arm's capsules at its samples ``0..N``: the slice ``start:stop`` of the
    sample axis of arrays computed for one or both arms at once.

    Attributes:
        batch: (2, 3, 5, n) end points, as :func:`sweep_points`, m.
        centre_batch: (3, 5, n) capsule centres, m.
        start, stop: this arm's samples in the batch (``stop - start = N + 1``).
        x_batch: (2, n) the arm's extent along x (least, greatest), m.
    """

    batch: np.ndarray
    centre_batch: np.ndarray
    start: int
    stop: int
    x_batch: np.ndarray  # (2, n): least and greatest x of the arm's capsules, m

    @staticmethod
    def of(q: np.ndarray, robot: int) -> Sweep:
        """The sweep of joint samples ``q`` (N + 1, 6) of robot 0 or 1."""
        pts = sweep_points(q, robot)
        return Sweep(pts, (pts[0] + pts[1]) * 0.5, 0, len(q), _x_extent(pts))

    @staticmethod
    def of_pair(q1: np.ndarray, q2: np.ndarray) -> tuple[Sweep, Sweep]:
        """``(Sweep.of(q1, 0), Sweep.of(q2, 1))`` in one batch."""
        n1, n = len(q1), len(q1) + len(q2)
        robot = np.zeros(n, np.int64)
        robot[n1:] = 1
        pts = sweep_points(np.concatenate([q1, q2]), robot)
        centres, x = (pts[0] + pts[1]) * 0.5, _x_extent(pts)
        return Sweep(pts, centres, 0, n1, x), Sweep(pts, centres, n1, n, x)

    @property
    def points(self) -> np.ndarray:
        """(2, 3, 5, N + 1) end points: [end a/b, xyz, capsule, sample], m."""
        return self.batch[..., self.start : self.stop]

    @property
    def centres(self) -> np.ndarray:
        """(3, 5, N + 1) capsule centres, m."""
        return self.centre_batch[..., self.start : self.stop]

    @property
    def n_samples(self) -> int:
        """N: index of the last sample."""
        return self.stop - self.start - 1

    @property
    def tip_z(self) -> np.ndarray:
        """Height of the gripper tip (the gripper capsule's far end), (N + 1,) m."""
        return self.batch[1, 2, 4, self.start : self.stop]

    def segments(self) -> tuple[np.ndarray, np.ndarray]:
        """End points ``(a, b)`` as (N + 1, 5, 3) each (``model.link_segments`` layout)."""
        pts = self.points
        return pts[0].transpose(2, 1, 0), pts[1].transpose(2, 1, 0)

    def gather(self, end: int, capsule: np.ndarray, row: np.ndarray) -> np.ndarray:
        """End points ``end`` (0: a, 1: b) of capsules ``capsule`` at samples ``row``,
        (c,) each -> (c, 3), laid out column by column (Fortran order), which
        :func:`closest_points_between_segments` runs through about twice as fast."""
        flat = self.batch[end].reshape(3, -1)  # (3, 5 * n), a view
        return np.take(flat, capsule * self.batch.shape[-1] + (row + self.start), axis=1).T


def _x_extent(points: np.ndarray) -> np.ndarray:
    """Least and greatest x (2, n) over the capsules of end points (2, 3, 5, n)."""
    x = points[:, 0]  # (2, 5, n)
    radius = model.RADII[:, None]
    return np.stack([(x - radius).min(axis=(0, 1)), (x + radius).max(axis=(0, 1))])


def _x_overlapping(
    s1: Sweep, rows1: np.ndarray, s2: Sweep, rows2: np.ndarray, margin: float
) -> np.ndarray:
    """Indices of the instants at which the arms' extents along x come within
    ``margin`` (1e-9 m beyond, so conservative); at the others every pair is clear."""
    x1 = np.take(s1.x_batch, rows1 + s1.start, axis=1)  # (2, m)
    x2 = np.take(s2.x_batch, rows2 + s2.start, axis=1)
    gap = margin + _SLACK
    return np.flatnonzero((x1[0] - x2[1] <= gap) & (x2[0] - x1[1] <= gap))


def _centre_distances(s1: Sweep, rows1: np.ndarray, s2: Sweep, rows2: np.ndarray) -> np.ndarray:
    """Squared centre distances (25, m) of all capsule pairs at instants ``(rows1, rows2)``."""
    c1 = np.take(s1.centre_batch, rows1 + s1.start, axis=2)  # (3, 5, m), C-contiguous
    c2 = np.take(s2.centre_batch, rows2 + s2.start, axis=2)
    diff = c1[:, :, None] - c2[:, None]  # (3, 5, 5, m)
    return np.einsum("cijm,cijm->ijm", diff, diff).reshape(25, len(rows1))


def _squared(bound: np.ndarray) -> np.ndarray:
    """``bound**2`` where ``bound >= 0``, else -1 (no squared distance is that small)."""
    return np.where(bound >= 0.0, bound * bound, -1.0)


def _exact_hits(
    s1: Sweep, rows1: np.ndarray, s2: Sweep, rows2: np.ndarray, cand: np.ndarray, margin: float
) -> np.ndarray:
    """Instants k (with repeats) of the candidates ``cand`` (flat ``pair * m + k``)
    whose exact distance is ``<= margin``."""
    pair, k = np.divmod(cand, len(rows1))
    i, j = np.divmod(pair, 5)
    r1, r2 = rows1[k], rows2[k]
    dist, _, _ = closest_points_between_segments(
        s1.gather(0, i, r1), s1.gather(1, i, r1), s2.gather(0, j, r2), s2.gather(1, j, r2)
    )  # (c,)
    return k[dist - _RSUM[pair] <= margin]


def colliding_instants(
    s1: Sweep, rows1: np.ndarray, s2: Sweep, rows2: np.ndarray, margin: float = 0.0
) -> np.ndarray:
    """Exactly where ``d(R1, R2) <= margin``: robot 1 at its sample ``rows1[k]``,
    robot 2 at ``rows2[k]`` (integer arrays of one length m). Returns (m,) bool."""
    out = np.zeros(len(rows1), dtype=bool)
    keep = _x_overlapping(s1, rows1, s2, rows2, margin)
    rows1, rows2 = rows1[keep], rows2[keep]
    d2 = _centre_distances(s1, rows1, s2, rows2)
    cand = np.flatnonzero(d2 <= _squared(_REACH + margin + _SLACK)[:, None])
    if len(cand):
        out[keep[_exact_hits(s1, rows1, s2, rows2, cand, margin)]] = True
    return out


def schedules_collide(
    s1: Sweep, s2: Sweep, schedules: list[tuple[np.ndarray, np.ndarray]], margin: float = 0.0
) -> list[bool]:
    """For each schedule ``(rows1, rows2)``: does ``d(R1, R2) <= margin`` at any of
    its instants? Exact; one broad phase and one exact call for all schedules.

    A schedule in which some pair of capsule centres is within ``r_i + r_j +
    margin`` (1e-9 m inside, so that rounding never decides) surely collides:
    the centres are points of the segments. Only the other schedules' pairs
    go to the exact distance.
    """
    rows1 = np.concatenate([r1 for r1, _ in schedules])
    rows2 = np.concatenate([r2 for _, r2 in schedules])
    owner = np.repeat(np.arange(len(schedules)), [len(r1) for r1, _ in schedules])  # (m,)
    keep = _x_overlapping(s1, rows1, s2, rows2, margin)
    rows1, rows2, owner = rows1[keep], rows2[keep], owner[keep]
    d2 = _centre_distances(s1, rows1, s2, rows2)
    collides = np.zeros(len(schedules), dtype=bool)
    collides[owner[np.any(d2 <= _squared(_RSUM + margin - _SLACK)[:, None], axis=0)]] = True
    near = (d2 <= _squared(_REACH + margin + _SLACK)[:, None]) & ~collides[owner]  # (25, m)
    cand = np.flatnonzero(near)
    if len(cand):
        collides[owner[_exact_hits(s1, rows1, s2, rows2, cand, margin)]] = True
    return collides.tolist()


def together_rows(n1: int, n2: int) -> tuple[np.ndarray, np.ndarray]:
    """Both start together: instant ``k`` pairs samples ``min(k, N_r)``, (max(N1, N2) + 1,)."""
    k = np.arange(max(n1, n2) + 1)
    return np.minimum(k, n1), np.minimum(k, n2)


def sequential_rows(n1: int, n2: int) -> tuple[np.ndarray, np.ndarray]:
    """One after the other: robot 1's path at robot 2's start, then robot 2's path at
    robot 1's end, (N1 + N2 + 2,)."""
    rows1 = np.concatenate([np.arange(n1 + 1), np.full(n2 + 1, n1)])
    rows2 = np.concatenate([np.zeros(n1 + 1, np.int64), np.arange(n2 + 1)])
    return rows1, rows2
