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
- "The contour a cell belongs to" is the 8-connected group of leftover cells
  containing it: leftovers lie along walls and obstacles, so a group is the
  unswept strip hugging one contour. Scanning rows top to bottom and each
  row right to left, the first cell met of each group is its seed; seeds are
  pushed in scan order, so the last pushed (bottom-left) is handled first.
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

from motiongym.envs.sweeper import world


def leftovers(occ: np.ndarray, swept: np.ndarray, reach: np.ndarray, w: int) -> np.ndarray:
    """``(H, W)`` bool: cells neither swept nor obstacle, covered by a reachable configuration."""
    return world.footprint_union(reach, w) & ~swept & (occ != 1)


def scan_groups(targets: np.ndarray) -> list[tuple[tuple[int, int], np.ndarray]]:
    """Steps 1-3: ``[(seed, cells)]`` in scan order (top-right to bottom-left).

    ``cells`` is an ``(n, 2)`` array of the group's cells; the caller pushes
    the list in this order and pops from its end.
    """
    labels, n = ndimage.label(targets, structure=np.ones((3, 3), bool))
    if n == 0:
        return []
    h, wd = targets.shape
    # scan order: row-major with columns reversed
    order = labels[:, ::-1].ravel()
    first_idx = np.full(n + 1, -1, np.int64)
    nz = np.flatnonzero(order)
    lab = order[nz]
    uniq, pos = np.unique(lab, return_index=True)
    first_idx[uniq] = nz[pos]
    seeds = sorted((int(first_idx[k]), k) for k in range(1, n + 1))
    cells = ndimage.find_objects(labels)
    out = []
    for idx, k in seeds:
        r, cr = divmod(idx, wd)
        seed = (r, wd - 1 - cr)
        sl = cells[k - 1]
        rr, cc = np.nonzero(labels[sl] == k)
        out.append((seed, np.stack([rr + sl[0].start, cc + sl[1].start], axis=1)))
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
    count = world.box_sum(mark, w)
    ok = (count > 0) & (dist >= 0)
    if not ok.any():
        return None
    d = np.where(ok, dist, np.iinfo(np.int64).max)
    best = d.min()
    tie = (d == best) * count
    k = int(np.argmax(tie))
    return divmod(k, dist.shape[1])
