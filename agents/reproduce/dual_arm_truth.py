"""The 200-pair study of ``motiongym reproduce dual-arm`` against the exact delays.

The truth is :mod:`motiongym.baselines.dual_arm.exact_delay` (brute force over
every delay on the environment's own v1 check), which shares nothing with the
collision maps it judges.
"""

from __future__ import annotations

import numpy as np

from motiongym.baselines.dual_arm.exact_delay import free_delays, step_table


def truth_study(seeds: list[int], n_levels: int = 100) -> dict[str, object]:
    """Boundary following on the paper's map and on the swept map against the truth.

    Per pair: the true minimum pure delay on the v1 check, and for each map
    the delay boundary following finds, classified as equal, early (the pure
    delay collides on the v1 check), late (by how many samples) or failed
    (no delay found); planning times beside the brute force's.
    """
    import time

    from motiongym.baselines.dual_arm.boundary_following import boundary_following
    from motiongym.baselines.dual_arm.collision_map import CollisionMap
    from motiongym.envs.dual_arm import task

    rows = []
    for seed in seeds:
        traj1, traj2 = task.sample_pair(np.random.default_rng(seed), "colliding")
        start = time.perf_counter()
        table = step_table(traj1, traj2)
        free = free_delays(table, traj1.n_samples, traj2.n_samples)
        truth_time = time.perf_counter() - start
        found = np.flatnonzero(free)
        row: dict[str, object] = {
            "seed": seed,
            "truth": int(found[0]) if len(found) else None,
            "truth_s": truth_time,
        }
        for name, swept in (("samples_map", False), ("swept_map", True)):
            start = time.perf_counter()
            delay = boundary_following(
                CollisionMap.from_tasks(traj1, traj2, n_levels, 0.0, swept)
            ).delay
            row[f"{name}_s"] = time.perf_counter() - start
            row[name] = delay
            row[f"{name}_verdict"] = _verdict(delay, row["truth"], free)
        rows.append(row)
    summary: dict[str, object] = {"pairs": len(rows), "rows": rows}
    for name in ("samples_map", "swept_map"):
        verdicts = [str(r[f"{name}_verdict"]) for r in rows]
        summary[name] = {
            "equal": verdicts.count("equal"),
            "early": verdicts.count("early"),
            "failed": verdicts.count("failed"),
            "late_by": sorted(int(v.split()[1]) for v in verdicts if v.startswith("late")),
            "median_s": float(np.median([r[f"{name}_s"] for r in rows])),
            "max_s": float(np.max([r[f"{name}_s"] for r in rows])),
        }
    summary["truth_median_s"] = float(np.median([r["truth_s"] for r in rows]))
    return summary


def _verdict(delay: int | None, truth: int | None, free: np.ndarray) -> str:
    if delay is None:
        return "failed"
    if not free[delay]:
        return "early"  # collides on the v1 check
    return "equal" if delay == truth else f"late {delay - truth}"


def print_truth_study(summary: dict[str, object]) -> None:
    """The study's table: each map's delays against the brute force on the v1 check."""
    from rich.console import Console
    from rich.table import Table

    table = Table(
        title=f"Boundary following against the exact minimum delay (v1 check), "
        f"{summary['pairs']} colliding pairs"
    )
    for column in ("map", "equal", "early (collides)", "late: by samples", "failed", "median s"):
        table.add_column(column)
    for name, label in (("samples_map", "paper's cells (v0)"), ("swept_map", "swept cells (v1)")):
        row = summary[name]
        late = row["late_by"]
        spread = (
            f"{len(late)}: {min(late)}-{max(late)}, median {np.median(late):g}" if late else "0"
        )
        table.add_row(
            label,
            str(row["equal"]),
            str(row["early"]),
            spread,
            str(row["failed"]),
            f"{row['median_s']:.3f}",
        )
    Console(width=110).print(table)
    print(f"brute force over every delay: {summary['truth_median_s']:.2f} s a pair (median)")
