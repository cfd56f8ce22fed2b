"""Batched state of N sweeper worlds: padded per-environment grids in flat arrays.

The :class:`BatchedGrids` holds, for every sub-environment ``i``, its maps in
row ``i`` of a few ``(N, L)`` arrays, ``L = Hp * Wp``: each map is padded by
``P = sensor_range`` obstacle cells on every side (as the single
environment pads it) and then, below and to the right, with more obstacle
cells up to the largest map seen so far (``Hp = Hmax + 2P``,
``Wp = Wmax + 2P``). Cell ``(y, x)`` of the map of sub-environment ``i`` is
flat entry ``i * L + (y + P) * Wp + (x + P)``. The robot's configuration
``(r, c)`` is kept as the *anchor* ``r * Wp + c``, which is also the
top-left cell of its sensing window in padded coordinates (the window starts
``R = P`` cells above and left of the footprint), so every cell the step
touches is the anchor plus a constant offset (precomputed per heading).

When a procedural map larger than every map before it arrives, the arrays
grow (rare: the generators' sides are bounded); the added cells are beyond
every existing window, so the grow is exact.
"""

from __future__ import annotations

import numpy as np

from motiongym.envs.sweeper import world
from motiongym.envs.sweeper.world import DC, DR


class BatchedGrids:
    """Per-environment padded maps as ``(N, L)`` arrays, and the offsets into them."""

    def __init__(self, num_envs: int, w: int, R: int, K: int, shared: np.ndarray | None) -> None:
        self.N, self.w, self.P, self.S, self.K = num_envs, w, R, w + 2 * R, K
        # shared: the fixed map of every sub-environment, stored once.
        self.shared = shared
        self.Hmax = self.Wmax = 0
        self.Hp = self.Wp = self.L = 0
        self.obst_b = np.zeros((0, 0), bool)  # (1 or N, L) obstacle
        self.reach = np.zeros((num_envs, 0), bool)  # (N, L) reachable config at anchor
        self.cnt = np.zeros((num_envs, 0), np.uint8)  # (N, L) sweep count, saturates at 2
        self.known = np.zeros((num_envs, 0), bool)  # (N, L) obstacle cells sensed
        self.block = np.zeros((0, 0), np.int32)  # (1 or N, L) coarse block of a cell, -1 outside
        self.obst_base = np.zeros(num_envs, np.int64)  # (N,) row start in obst_*, block (flat)
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

        def grow(old: np.ndarray, rows: int, fill: float | bool) -> np.ndarray:
            new = np.full((rows, Hp, Wp), fill, old.dtype)
            if old.size:
                new[:, :oh, :ow] = old.reshape(rows, oh, ow)
            return new.reshape(rows, Hp * Wp)

        self.reach = grow(self.reach, N, False)
        self.cnt = grow(self.cnt, N, 0)
        self.known = grow(self.known, N, False)
        self.Hmax, self.Wmax, self.Hp, self.Wp, self.L = Hmax, Wmax, Hp, Wp, Hp * Wp
        if self.shared is not None:
            self.obst_b = self._pad(self.shared).reshape(1, -1)
            self.block = self._blocks(*self.shared.shape).reshape(1, -1)
        else:
            self.obst_b = grow(self.obst_b, N, True)
            self.block = grow(self.block, N, -1)
            self.obst_base = np.arange(N, dtype=np.int64) * self.L
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
        enter = []
        for k in range(4):  # cells entering the footprint, relative to the new anchor
            rr, cc = np.nonzero(world.entering_mask(int(DR[k]), int(DC[k]), w))
            enter.append((rr + P) * Wp + cc + P)
        self.enter_off = np.array(enter, np.int64)  # (4, w)
        full, last = np.arange(S), S - 1
        self.edge_off = np.array(  # (4, S) leading edge of the window per heading
            [full * Wp + last, full, full * Wp, last * Wp + full], np.int64
        )
        fy, fx = np.divmod(np.arange(w * w), w)
        self.foot_off = ((fy + P) * Wp + fx + P).astype(np.int64)  # (w*w,) footprint
        # Where the entering cells sit in the (S, S) window, per heading: (4, w) each.
        self.enter_win = [
            np.nonzero(world.entering_mask(int(DR[k]), int(DC[k]), w)) for k in range(4)
        ]
        self.enter_win = [(rr + P, cc + P) for rr, cc in self.enter_win]

    # ------------------------------------------------------------------- reset
    def load(self, i: int, obstacle: np.ndarray, reach_configs: np.ndarray) -> None:
        """Write sub-environment ``i``'s map; clear its sweep and sensing maps."""
        H, W = obstacle.shape
        Hp, Wp = self.Hp, self.Wp
        if self.shared is None:
            self.obst_b[i] = self._pad(obstacle).ravel()
            self.block[i] = self._blocks(H, W).ravel()
        reach = np.zeros((Hp, Wp), bool)
        reach[:H, :W] = reach_configs
        self.reach[i] = reach.ravel()
        self.cnt[i] = 0
        self.known[i] = False
