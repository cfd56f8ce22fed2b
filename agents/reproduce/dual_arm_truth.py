"""The study of ``motiongym reproduce dual-arm`` against the exact delays.

The truth is :mod:`motiongym.baselines.dual_arm.exact_delay` (brute force over
every delay on the environment's own v1 check, every step decided), which
uses neither the collision maps nor boundary following. Each delay is also
checked in continuous time on a fine grid independent of the v1 check's
motion bound (:func:`fine_collides`).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from motiongym.baselines.dual_arm.boundary_following import boundary_following
from motiongym.baselines.dual_arm.bracket import exact_delay_search
from motiongym.baselines.dual_arm.collision_map import CollisionMap
from motiongym.baselines.dual_arm.exact_delay import free_delays, step_table
from motiongym.baselines.dual_arm.step_check import StepCheck
from motiongym.envs.dual_arm import model, task

METHODS = {  # key -> label
    "paper_map": "BF, paper's cells (v0)",
    "upper_map": "BF, upper map alone",
    "lower_map": "BF, lower map alone",
    "exact": "BF + exact checks (v1 policy)",
}
FINE = 20  # configurations per 20 ms step in the continuous-time check


def fine_collides(traj1: task.Trajectory, traj2: task.Trajectory, delay: int) -> bool:
    """Does the pure delay come within 0 m at any of ``FINE`` instants of each step?"""
    n = max(traj1.n_samples, delay + traj2.n_samples)
    t = np.arange(n * FINE + 1) / FINE  # in samples
    q1 = traj1.at_time(t * task.DT)
    q2 = traj2.at_time(np.maximum(t - delay, 0.0) * task.DT)
    return bool((model.robot_distance(q1, q2) <= 0.0).any())


def _timed(plan) -> tuple[Any, float]:
    start = time.process_time()
    out = plan()
    return out, time.process_time() - start


def study_pair(seed: int, n_levels: int = 100) -> dict[str, Any]:
    """One pair: the truth, each method's delay and verdict, CPU times (s)."""
    traj1, traj2 = task.sample_pair(np.random.default_rng(seed), "colliding", check="swept")
    n1, n2 = traj1.n_samples, traj2.n_samples
    table, truth_s = _timed(lambda: step_table(traj1, traj2))
    free = free_delays(table, n1, n2)
    found = np.flatnonzero(free)
    row: dict[str, Any] = {"seed": seed, "truth": int(found[0]) if len(found) else None}
    row["truth_s"] = truth_s
    plan, row["exact_s"] = _timed(lambda: exact_delay_search(traj1, traj2, n_levels))
    row["exact"], row["lower_map"], row["checked"] = plan.delay, plan.lower, plan.checked
    row["reason"] = plan.reason
    row["lower_map_s"] = row["exact_s"]
    maps = (
        ("paper_map", lambda: CollisionMap.from_tasks(traj1, traj2, n_levels)),
        (
            "upper_map",
            lambda: CollisionMap.from_steps(StepCheck(traj1, traj2), traj2, n_levels, "upper"),
        ),
    )
    for key, make in maps:
        result, row[f"{key}_s"] = _timed(lambda make=make: boundary_following(make()))
        row[key] = result.delay
    for key in METHODS:
        row[f"{key}_verdict"] = _verdict(row[key], row["truth"], free)
    exact = row["exact"]
    row["exact_fine_collides"] = exact is not None and fine_collides(traj1, traj2, exact)
    return row


def _verdict(delay: int | None, truth: int | None, free: np.ndarray) -> str:
    if delay is None:
        return "failed" if truth is not None else "none exists"
    if not free[delay] or truth is None:  # (no truth: no delay is free)
        return "early"  # collides on the v1 check
    return "equal" if delay == truth else f"late {delay - truth}"


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Counts per method: equal, early, late (by how much), failed; CPU times."""
    summary: dict[str, Any] = {"pairs": len(rows), "rows": rows}
    for key in METHODS:
        verdicts = [str(r[f"{key}_verdict"]) for r in rows]
        times = [float(r[f"{key}_s"]) for r in rows]
        summary[key] = {
            "equal": verdicts.count("equal"),
            "early": verdicts.count("early"),
            "failed": verdicts.count("failed"),
            "late_by": sorted(int(v.split()[1]) for v in verdicts if v.startswith("late")),
            "median_s": float(np.median(times)),
            "max_s": float(np.max(times)),
        }
    summary["exact_fine_collisions"] = sum(bool(r["exact_fine_collides"]) for r in rows)
    summary["checked_max"] = max(int(r["checked"]) for r in rows)
    summary["truth_median_s"] = float(np.median([r["truth_s"] for r in rows]))
    summary["truth_max_s"] = float(np.max([r["truth_s"] for r in rows]))
    return summary


def truth_study(seeds: list[int], n_levels: int = 100) -> dict[str, Any]:
    """Every method against the truth on the pairs of ``seeds``; the at-rest pairs."""
    summary = summarise([study_pair(seed, n_levels) for seed in seeds])
    summary["at_rest"] = at_rest_study()
    return summary


def resolution_study(truth: dict[str, Any], levels=(50, 100, 200, 400)) -> dict[int, dict]:
    """The exact search at each ``N_l`` on the truth study's pairs: delay error against
    the truth, how often the lower map's delay is the truth itself, delays checked,
    CPU time."""
    rows = truth["rows"]
    out = {}
    for n_levels in levels:
        errors, tight, checked, times = [], [], [], []
        for row in rows:
            t1, t2 = task.sample_pair(
                np.random.default_rng(row["seed"]), "colliding", check="swept"
            )
            plan, seconds = _timed(lambda t1=t1, t2=t2, n=n_levels: exact_delay_search(t1, t2, n))
            errors.append(plan.delay - row["truth"])
            tight.append(plan.lower == row["truth"])
            checked.append(plan.checked)
            times.append(seconds)
        out[n_levels] = {
            "equal": int(sum(e == 0 for e in errors)),
            "late_max": int(max(errors)),
            "lower_is_truth": int(sum(tight)),
            "checked_mean": float(np.mean(checked)),
            "checked_max": int(max(checked)),
            "median_s": float(np.median(times)),
            "max_s": float(np.max(times)),
        }
    return out


def at_rest_pair(where: str) -> tuple[task.Trajectory, task.Trajectory]:
    """The paper case with both arms starting (``where="start"``) or ending ("end") where
    they are at 0.9 s, where the undelayed pair collides: no delay can help."""
    traj1, traj2 = task.paper_case()
    vias1, vias2 = traj1.vias.copy(), traj2.vias.copy()
    index = 0 if where == "start" else -1
    vias1[index], vias2[index] = traj1.at_time(np.array(0.9)), traj2.at_time(np.array(0.9))
    return (
        task.Trajectory(vias1, traj1.durations, 0),
        task.Trajectory(vias2, traj2.durations, 1),
    )


def at_rest_study() -> dict[str, Any]:
    """What the planner answers on the two at-rest pairs (a reason, never a delay)."""
    out = {}
    for where in ("start", "end"):
        plan = exact_delay_search(*at_rest_pair(where))
        out[where] = {"delay": plan.delay, "reason": plan.reason}
    return out


def _spread(late: list[int]) -> str:
    return f"{len(late)}: {min(late)}-{max(late)}, median {np.median(late):g}" if late else "0"


def print_truth_study(summary: dict[str, Any], resolution: dict[int, dict] | None) -> None:
    """The study's tables: each method against the brute force; the resolution."""
    from rich.console import Console
    from rich.table import Table

    table = Table(
        title=f"Boundary following (BF) against the exact minimum delay (v1 check), "
        f"{summary['pairs']} colliding pairs; CPU time per pair"
    )
    for column in ("method", "equal", "early (collides)", "late: n, by", "failed", "s median/max"):
        table.add_column(column)
    for key, label in METHODS.items():
        r = summary[key]
        times = f"{r['median_s']:.3f} / {r['max_s']:.3f}"
        counts = [str(r["equal"]), str(r["early"]), _spread(r["late_by"]), str(r["failed"])]
        table.add_row(label, *counts, times)
    brute = f"{summary['truth_median_s']:.3f} / {summary['truth_max_s']:.3f}"
    table.add_row("brute force (truth)", "-", "-", "-", "-", brute)
    console = Console(width=120)
    console.print(table)
    console.print(
        f"exact delays colliding on a {FINE}-instant grid per step: "
        f"{summary['exact_fine_collisions']}; most delays checked exactly: {summary['checked_max']}"
    )
    for where, answer in summary.get("at_rest", {}).items():
        console.print(
            f"arms colliding at rest ({where}): delay {answer['delay']}, {answer['reason']}"
        )
    if not resolution:
        return
    res = Table(title=f"Map resolution N_l (BF + exact checks), {summary['pairs']} pairs")
    for column in ("N_l", "equal", "late max", "d_lo = truth", "checked mean/max", "s median/max"):
        res.add_column(column)
    for n_levels, r in resolution.items():
        times = f"{r['median_s']:.3f} / {r['max_s']:.3f}"
        checked = f"{r['checked_mean']:.2f} / {r['checked_max']}"
        res.add_row(str(n_levels), str(r["equal"]), str(r["late_max"]),
                    str(r["lower_is_truth"]), checked, times)  # fmt: skip
    console.print(res)
