"""Corner-Work Algorithm (paper section 3.3, Fig. 9-10).

After PSA, strips along walls and obstacles stay unswept (narrower than a
sweeping width, or behind corners). CWA, as the paper states it:

1. Scan the sweep map from top-right to bottom-left for an unswept cell.
2. Push it on a stack; trace the closed contour it belongs to into the
   obstacle map, marking those cells as handled.
3. Repeat until the whole map is scanned.
4. Pop a point, move to it and follow the obstacle's contour while sweeping.
5. Until the stack is empty.

Our reading (the choices are documented and tested):

- A cell is a leftover when it is neither swept nor a known obstacle and some
  configuration reachable in the known map covers it (a cell in a gap
  narrower than the robot can never be swept and is not a leftover).
- "The closed contour a cell belongs to" is the contour of the known
  obstacle (an 8-connected component of obstacle cells; the outer wall and
  everything touching it is one) nearest to the cell, within a robot width;
  all leftovers along that contour form one group. Leftovers farther from
  any obstacle are grouped by 8-connectivity. Scanning rows top to bottom
  and each row right to left, the first cell met of each group is its seed;
  seeds are pushed in scan order, so the last pushed is handled first.
- "Follow the contour while sweeping": from the seed on, the robot goes to
  the nearest configuration (grid distance in the known map) covering a
  leftover cell of the group, repeatedly, until the group is swept; along a
  strip the nearest next cell is the next one along the contour.
- Cells first seen during CWA can add leftovers; CWA is then run again on the
  updated sweep map (a new scan), until no leftover remains.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from motiongym.envs.sweeper import occupancy


def leftovers(occ: np.ndarray, swept: np.ndarray, reach: np.ndarray, w: int) -> np.ndarray:
    """``(H, W)`` bool: cells neither swept nor obstacle, covered by a reachable configuration."""
    return occupancy.footprint_union(reach, w) & ~swept & (occ != 1)


def scan_groups(
    targets: np.ndarray, obstacle: np.ndarray | None = None, reach: int = 1
) -> list[tuple[tuple[int, int], np.ndarray]]:
    """Steps 1-3: ``[(seed, cells)]`` in scan order (top-right to bottom-left).

    With ``obstacle`` (known obstacle cells), leftovers within ``reach`` cells
    of an obstacle belong to the contour of that obstacle (its 8-connected
    component): one entry per contour, as the paper traces "the closed
    contour" a leftover touches. Other leftovers (and all of them without
    ``obstacle``) are grouped by 8-connectivity. ``cells`` is an ``(n, 2)``
    array; the caller pushes the list in this order and pops from its end.
    """
    groups = np.zeros(targets.shape, np.int64)
    n_obst = 0
    if obstacle is not None and obstacle.any():
        obst_labels, n_obst = ndimage.label(obstacle, structure=np.ones((3, 3), bool))
        dist, (ir, ic) = ndimage.distance_transform_cdt(
            ~obstacle, metric="chessboard", return_indices=True
        )
        near = targets & (dist <= reach)
        groups[near] = obst_labels[ir[near], ic[near]]
    rest, n_rest = ndimage.label(targets & (groups == 0), structure=np.ones((3, 3), bool))
    groups[rest > 0] = rest[rest > 0] + n_obst
    n = n_obst + n_rest
    if not targets.any():
        return []
    h, wd = targets.shape
    order = groups[:, ::-1].ravel()  # scan order: row-major with columns reversed
    nz = np.flatnonzero(order)
    uniq, pos = np.unique(order[nz], return_index=True)
    seeds = sorted((int(nz[p]), int(k)) for k, p in zip(uniq, pos, strict=True))
    flat = groups.ravel()
    sort = np.argsort(flat, kind="stable")
    bounds = np.searchsorted(flat[sort], np.arange(n + 2))
    out = []
    for idx, k in seeds:
        r, cr = divmod(idx, wd)
        cells = sort[bounds[k] : bounds[k + 1]]
        out.append(((r, wd - 1 - cr), np.stack(np.divmod(cells, wd), axis=1)))
    return out


def nearest_cover(dist: np.ndarray, cells: np.ndarray, w: int) -> tuple[int, int] | None:
    """The reachable configuration nearest by ``dist`` whose footprint covers one of ``cells``.

    ``dist``: BFS distances over configurations (-1 unreachable); ``cells``:
    ``(n, 2)`` target cells. Ties go to the configuration covering more of them.
    """
    if len(cells) == 0:
        return None
    mark = np.zeros(dist.shape, np.int64)
    mark[cells[:, 0], cells[:, 1]] = 1
    # configurations (r, c) with r <= i < r + w: a box sum anchored at (r, c)
    count = occupancy.box_sum(mark, w)
    ok = (count > 0) & (dist >= 0)
    if not ok.any():
        return None
    d = np.where(ok, dist, np.iinfo(np.int64).max)
    best = d.min()
    tie = (d == best) * count
    k = int(np.argmax(tie))
    return divmod(k, dist.shape[1])
