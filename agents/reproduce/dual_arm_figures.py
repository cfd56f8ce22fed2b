"""Figures of the dual-arm cell: the collision map with the boundary-following trace
(paper Fig. 8-9) and distance over time (Fig. 7, 10). Matplotlib, any backend."""

from __future__ import annotations

from typing import Any

import numpy as np

from motiongym.baselines.dual_arm.boundary_following import BoundaryResult
from motiongym.baselines.dual_arm.collision_map import CollisionMap
from motiongym.envs.dual_arm.task import DT


def plot_collision_map(
    cmap: CollisionMap,
    result: BoundaryResult | None = None,
    delays: dict[str, int] | None = None,
    ax: Any = None,
    width: int | None = None,
) -> Any:
    """Draw the full map (collision cells dark), the TLVST curve undelayed and
    delayed, and boundary following's trace, candidates and departure point.

    Args:
        cmap: the map (its full occupancy is computed here if not yet known).
        result: a boundary-following result to overlay.
        delays: extra delayed curves to draw, ``{label: delay in samples}``.
        ax: a matplotlib axes (a new figure if None).
        width: columns to show (default ``N1 + N2 + 1``).
    Returns:
        The axes.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(9, 4.5))
    occ = cmap.full()
    width = width or cmap.n1 + cmap.n2 + 1
    cols = np.minimum(np.arange(width), cmap.n1)
    ax.imshow(
        occ[cols].T,
        origin="lower",
        cmap="Greys",
        vmin=0,
        vmax=1.6,
        aspect="auto",
        extent=(-0.5, width - 0.5, -0.5, cmap.n_levels + 0.5),
        interpolation="nearest",
    )
    curves = {"TLVST (no delay)": 0}
    if result is not None and result.delay is not None:
        curves[f"TLVST delayed {result.delay} samples"] = result.delay
    curves.update(delays or {})
    for (label, delay), style in zip(curves.items(), ("C0-", "C2-", "C1--", "C4:"), strict=False):
        s1s, s2s = cmap.curve(delay)
        ax.plot(s1s, s2s, style, lw=1.4, label=label)
    if result is not None:
        trace = np.array([(x, y) for x, y, mode in result.trace if mode == "b"])
        if len(trace):
            ax.plot(trace[:, 0], trace[:, 1], "r.", ms=3, label="boundary following")
        if result.candidates:
            cand = np.array(result.candidates)
            ax.plot(cand[:, 0], cand[:, 1], "o", mfc="none", mec="orange", ms=4, label="candidates")
        if result.departure is not None:
            x, y = result.departure
            ax.plot([x], [y], "r*", ms=12, label=f"dp = ({x}, {y})")
            k1 = x - result.delay if result.delay is not None else int(cmap.first_col[y])
            ax.annotate(
                f"TD = ({x} - {k1}) x {DT:g} s = {(x - k1) * DT:.2f} s",
                xy=(x, y),
                xytext=(x + 5, y + 12),
                arrowprops={"arrowstyle": "->"},
            )
    ax.set_xlabel("s1: robot 1 sample (20 ms)")
    ax.set_ylabel(f"s2: robot 2 travelled length / (L_T / {cmap.n_levels})")
    ax.set_xlim(-0.5, width - 0.5)
    ax.set_ylim(-0.5, cmap.n_levels + 0.5)
    ax.legend(loc="lower right", fontsize=7)
    return ax


def plot_distance(ax: Any, times: np.ndarray, distance: np.ndarray, title: str) -> Any:
    """``d(R1, R2)`` over time with the zero line (paper Fig. 7 and 10)."""
    ax.plot(times, distance, "C0-")
    ax.axhline(0.0, color="k", lw=0.8)
    below = distance <= 0
    if below.any():
        ax.fill_between(times, distance, 0, where=below, color="C3", alpha=0.4, label="collision")
        ax.legend(fontsize=7)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("d(R1, R2) [m]")
    ax.set_title(title, fontsize=9)
    return ax
