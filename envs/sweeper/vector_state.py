"""Batched state of N sweeper worlds, and the vector env's recycled output buffers.

:class:`BatchedGrids` holds, for every sub-environment ``i``, its maps in
row ``i`` of a few ``(N, L)`` arrays, ``L = Hp * Wp``: each map is padded by
``P = sensor_range`` obstacle cells on every side (as the single
environment pads it) and then, below and to the right, with more obstacle
cells up to the largest map seen so far (``Hp = Hmax + 2P``,
``Wp = Wmax + 2P``). Cell ``(y, x)`` of the map of sub-environment ``i`` is
flat entry ``i * L + (y + P) * Wp + (x + P)``. The robot's configuration
``(r, c)`` is kept as the *anchor* ``r * Wp + c``, which is also the
top-left cell of its sensing window in padded coordinates (the window starts
``R = P`` cells above and left of the footprint), so every cell a step
touches is the anchor plus a constant offset, precomputed per heading.

When a procedural map larger than every map before it arrives, the arrays
grow (rare: the generators' sides are bounded); the added cells lie beyond
every existing window, so growing changes nothing else.

:class:`ObservationPool` hands out the observation arrays of the vector env
(see its docstring); :func:`check_actions` validates a batch of actions and
:func:`spread_info` lays a partial reset's info out as SyncVectorEnv does.
"""

from __future__ import annotations

import sys
from collections import deque
from collections.abc import Sequence
from typing import Any

import numpy as np

from motiongym.envs.sweeper import occupancy
from motiongym.envs.sweeper.occupancy import DC, DR

COUNT = np.uint8(3)  # bits of a cell's state holding its sweep count (0, 1, 2 = twice or more)
KNOWN = np.uint8(4)  # bit of a cell's state: an obstacle the robot has sensed


class BatchedGrids:
    """Per-environment padded maps as ``(N, L)`` arrays, and the offsets into them."""

    def __init__(self, num_envs: int, w: int, R: int, K: int, shared: np.ndarray | None) -> None:
        self.N, self.w, self.P, self.S, self.K = num_envs, w, R, w + 2 * R, K
        self.shared = shared  # the fixed map of every sub-environment, stored once
        self.Hmax = self.Wmax = self.Hp = self.Wp = self.L = 0
        self.obst = np.zeros((0, 0), bool)  # (1 or N, L) obstacle
        self.block = np.zeros((0, 0), np.int32)  # (1 or N, L) coarse block of a cell, -1 outside
        self.map_base = np.zeros(num_envs, np.int64)  # (N,) row start in obst / block (flat)
        self.reach = np.zeros((num_envs, 0), bool)  # (N, L) reachable configuration at anchor
        self.cell = np.zeros((num_envs, 0), np.uint8)  # (N, L) sweep count | KNOWN
        if shared is not None:
            self.ensure(*shared.shape)

    # ------------------------------------------------------------------ layout
    def ensure(self, H: int, W: int) -> bool:
        """Make room for an ``H x W`` map; return True when the layout changed."""
        if H <= self.Hmax and W <= self.Wmax:
            return False
        Hmax, Wmax, P = max(H, self.Hmax), max(W, self.Wmax), self.P
        Hp, Wp = Hmax + 2 * P, Wmax + 2 * P
        N, oh, ow = self.N, self.Hp, self.Wp

        def grow(old: np.ndarray, fill: float | bool) -> np.ndarray:
            new = np.full((N, Hp, Wp), fill, old.dtype)
            if old.size:
                new[:, :oh, :ow] = old.reshape(N, oh, ow)
            return new.reshape(N, Hp * Wp)

        self.reach, self.cell = grow(self.reach, False), grow(self.cell, 0)
        self.Hmax, self.Wmax, self.Hp, self.Wp, self.L = Hmax, Wmax, Hp, Wp, Hp * Wp
        if self.shared is not None:
            self.obst = self._pad(self.shared).reshape(1, -1)
            self.block = self._blocks(*self.shared.shape).reshape(1, -1)
        else:
            self.obst, self.block = grow(self.obst, True), grow(self.block, -1)
            self.map_base = np.arange(N, dtype=np.int64) * self.L
        self._offsets()
        return True

    def _pad(self, obstacle: np.ndarray) -> np.ndarray:
        """``(Hp, Wp)`` bool: the map in the padded layout, obstacles around it."""
        H, W = obstacle.shape
        pad = np.ones((self.Hp, self.Wp), bool)
        pad[self.P : self.P + H, self.P : self.P + W] = obstacle
        return pad

    def _blocks(self, H: int, W: int) -> np.ndarray:
        """``(Hp, Wp)`` int32: the coarse block (row-major in ``K x K``) of each map cell.

        Blocks are ``ceil(H/K) x ceil(W/K)`` cells as in the single environment;
        -1 marks cells outside the map (padding), which the coarse maps ignore.
        """
        K, P = self.K, self.P
        bh, bw = -(-H // K), -(-W // K)
        out = np.full((self.Hp, self.Wp), -1, np.int32)
        out[P : P + H, P : P + W] = (np.arange(H) // bh)[:, None] * K + np.arange(W) // bw
        return out

    def _offsets(self) -> None:
        w, P, S, Wp = self.w, self.P, self.S, self.Wp
        self.delta = (DR * Wp + DC).astype(np.int64)  # (4,) anchor step per heading
        i, j = np.divmod(np.arange(S * S), S)
        self.win_off = (i * Wp + j).astype(np.int64)  # (S*S,) window cells, row-major
        fy, fx = np.divmod(np.arange(w * w), w)
        self.foot_off = ((fy + P) * Wp + fx + P).astype(np.int64)  # (w*w,) footprint
        enter, self.enter_win = [], []
        for k in range(4):  # cells entering the footprint on a move along heading k
            rr, cc = np.nonzero(occupancy.entering_mask(int(DR[k]), int(DC[k]), w))
            enter.append((rr + P) * Wp + cc + P)  # relative to the new anchor
            self.enter_win.append((rr + P, cc + P))  # where they sit in the (S, S) window
        self.enter_off = np.array(enter, np.int64)  # (4, w)
        full, last = np.arange(S), S - 1
        self.edge_off = np.array(  # (4, S) the window's leading edge per heading
            [full * Wp + last, full, full * Wp, last * Wp + full], np.int64
        )

    # ------------------------------------------------------------------- reset
    def load(self, i: int, obstacle: np.ndarray, reach_configs: np.ndarray) -> None:
        """Write sub-environment ``i``'s map; clear its sweep and sensing state."""
        H, W = obstacle.shape
        if self.shared is None:
            self.obst[i] = self._pad(obstacle).ravel()
            self.block[i] = self._blocks(H, W).ravel()
        reach = np.zeros((self.Hp, self.Wp), bool)
        reach[:H, :W] = reach_configs
        self.reach[i] = reach.ravel()
        self.cell[i] = 0


class ObservationPool:
    """The vector env's output observation arrays, recycled and patched.

    Every call hands out a set of ``(N, ...)`` arrays that no caller
    references any more (CPython reference counts: a caller's dict, a view
    or a tensor sharing the memory all hold a reference, so an array in use
    is never written). A recycled set is brought up to date by copying only
    what changed since it was last handed out: the window rows of the worlds
    that moved or were reset and the coarse-map entries that changed (a log
    of the last steps' changes); ``pose`` is rewritten whole. A set older
    than the log is copied whole. Without reference counts (not CPython)
    every call returns fresh arrays.

    So a returned observation stays valid as long as it is held, like a copy;
    the one thing it does not survive is being modified in place and then
    dropped (the next observations would carry the modification): copy an
    observation before editing it in place.
    """

    def __init__(self, space: Any, sets: int = 4, history: int = 16) -> None:
        self.space, self.max_sets = space, sets
        self.sets: list[tuple[dict[str, np.ndarray], list[int]]] = []  # arrays, [version]
        self.log: deque[tuple[int, Any]] = deque(maxlen=history)  # (version, changes)
        self.version = 0

    def record(self, changes: Any) -> None:
        """Log one update of the source state; ``None`` means everything changed."""
        self.version += 1
        self.log.append((self.version, changes))

    def take(self) -> tuple[dict[str, np.ndarray], list | None]:
        """A free set of arrays, and the logged changes it lacks (None: copy it whole)."""
        for arrays, stamp in self.sets:
            if _most_refs(arrays) <= _FREE:
                missing = [c for v, c in self.log if v > stamp[0]]
                complete = self.log and self.log[0][0] <= stamp[0] + 1
                stamp[0] = self.version
                if complete and all(c is not None for c in missing):
                    return arrays, missing
                return arrays, None
        arrays = {k: np.empty(sp.shape, sp.dtype) for k, sp in self.space.items()}
        if len(self.sets) < self.max_sets and hasattr(sys, "getrefcount"):
            self.sets.append((arrays, [self.version]))
        return arrays, None


def check_actions(actions: Any, N: int) -> np.ndarray:
    """``(N,)`` int64 actions: exactly what ``MultiDiscrete([3] * N).contains`` accepts
    (a list or an array of shape ``(N,)``, a dtype that casts safely to int64,
    values 0..2); anything else a ValueError naming the expected space."""
    a = np.array(actions) if isinstance(actions, Sequence) else actions
    expected = (
        f"an integer array of shape ({N},) in MultiDiscrete([3] * {N}): "
        "0 (forward), 1 (left) or 2 (right) per sub-environment"
    )
    if not isinstance(a, np.ndarray) or a.shape != (N,):
        raise ValueError(f"actions must be {expected}; got shape {np.shape(a)}")
    if not np.can_cast(a.dtype, np.int64):
        raise ValueError(f"actions must be {expected}; got dtype {a.dtype}")
    bad = (a < 0) | (a > 2)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"actions must be {expected}; sub-environment {k} got {a[k]}")
    return a.astype(np.int64, copy=False)


def shift_windows(
    old: np.ndarray, fill: np.ndarray, heading: np.ndarray, enter_win: list
) -> np.ndarray:
    """v0's windows after a one-cell move: ``(M, 2, S, S)`` [sensed, swept].

    ``old`` windows shift by the move along ``heading`` (sorted, ``(M,)``),
    the leading edge takes ``fill`` ``(M, 2, S)`` and the cells entering the
    footprint (``enter_win[k]``, window indices) become swept; nothing else
    in a window changes.
    """
    win = np.empty_like(old)
    bounds = np.searchsorted(heading, np.arange(5))
    for k in range(4):
        lo, hi = bounds[k], bounds[k + 1]
        if lo == hi:
            continue
        part, was, f = win[lo:hi], old[lo:hi], fill[lo:hi]
        if k == 0:  # east: new[i, j] = old[i, j + 1]
            part[..., :-1] = was[..., 1:]
            part[..., -1] = f
        elif k == 1:  # north: new[i, j] = old[i - 1, j]
            part[..., 1:, :] = was[..., :-1, :]
            part[..., 0, :] = f
        elif k == 2:  # west: new[i, j] = old[i, j - 1]
            part[..., 1:] = was[..., :-1]
            part[..., 0] = f
        else:  # south: new[i, j] = old[i + 1, j]
            part[..., :-1, :] = was[..., 1:, :]
            part[..., -1, :] = f
        rr, cc = enter_win[k]
        part[:, 1, rr, cc] = 1
    return win


def spread_info(info: dict, idx: np.ndarray, N: int) -> dict:
    """Info of worlds ``idx`` -> full ``(N,)`` arrays, zero and unmasked elsewhere."""
    out = {}
    for key, value in info.items():
        full = np.zeros((N, *value.shape[1:]), value.dtype)
        full[idx] = value
        if key.startswith("_"):
            full[:] = False
            full[idx] = True
        out[key] = full
    return out


def _most_refs(arrays: dict[str, np.ndarray]) -> int:
    """The largest reference count among ``arrays``' values (huge without refcounts)."""
    if not hasattr(sys, "getrefcount"):
        return 1 << 30
    return max(sys.getrefcount(a) for a in arrays.values())


_FREE = _most_refs({"unused": np.empty(0)})  # held by the dict alone
