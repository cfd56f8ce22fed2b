"""Reproduction of the dual-arm paper (time delay by boundary following), section IV.

1. The paper case (our own pick-and-place pair, ``pairs="paper"``: the paper's
   Fig. 6 trajectories are not in the text): the undelayed distance crossing
   zero (Fig. 7), the collision map with boundary following's trace and the
   departure point (Fig. 8-9), the delay found, the distance after the delay
   (Fig. 10), the time saved against sequential operation; printed beside
   the paper's 0.76-1.16 s, TD = 0.7 s and 1.22 s. The schedule is also run in
   ``DualArmCell-v0`` (the environment's own distances) as a check.
2. The study: ``n`` colliding pairs sampled as the environment samples them
   (seeds ``SEED0 + i``): boundary following's delay against the exhaustive
   minimum on the full map (every disagreement listed with its cause), its
   cells evaluated against the full map's (median ratio) and planning time,
   and the makespans of sequential, delay and minimum-makespan schedules.
   Each schedule's distance is re-evaluated exactly at every 20 ms sample of
   the motion (no map discretisation) to count collisions the map missed.
3. The truth study (:mod:`.dual_arm_truth`, 200 pairs): boundary following on
   each kind of map, and v1's exact search, against the brute force over
   delays on ``DualArmCell-v1``'s check and a 20-instant grid per step
   (equal / early / late by how much / failed, CPU time beside the brute
   force's); the map resolution ``N_l`` in {50, 100, 200, 400} on the same
   pairs; two pairs whose arms collide at rest.
"""

from __future__ import annotations

import json
import pathlib
import time
from typing import Any

import numpy as np

from motiongym.agents.reproduce.dual_arm_truth import (
    print_truth_study,
    resolution_study,
    truth_study,
)
from motiongym.baselines.dual_arm import schedules
from motiongym.baselines.dual_arm.boundary_following import BoundaryResult, boundary_following
from motiongym.baselines.dual_arm.collision_map import CollisionMap
from motiongym.envs.dual_arm import model, task

PAPER = {
    "collision_interval_s": (0.76, 1.16),
    "delay_s": 0.7,
    "departure_k2_k1": (66, 31),
    "time_saved_s": 1.22,
    "planning_time_s": 90.0,  # SUN SPARC workstation
}
SEED0 = 20_000
N_LEVELS = 100


def schedule_distance(
    traj1: task.Trajectory, traj2: task.Trajectory, advances: np.ndarray
) -> np.ndarray:
    """Exact ``d(R1, R2)`` at every step of robot 2's schedule, robot 1 nominal."""
    p1, p2 = schedules.sample_indices(advances, traj1.n_samples, traj2.n_samples)
    return model.robot_distance(traj1.samples()[p1], traj2.samples()[p2])


def _explain(cmap: CollisionMap, result: BoundaryResult, exhaustive: int | None) -> str:
    """Why boundary following and the exhaustive scan disagree on one case."""
    if result.delay is None:
        return f"boundary following failed: {result.reason}"
    if exhaustive is None:
        return "the exhaustive scan found no collision-free delay"
    occ = cmap.full()
    s1s, s2s = cmap.curve(exhaustive)
    touching = [
        (int(x), int(y))
        for x, y in zip(s1s, s2s, strict=True)
        if x > 0 and occ[min(x - 1, cmap.n1), y]
    ]
    visited = {(x, y) for x, y, _ in result.trace}
    if touching and not any(q in visited for q in touching):
        return (
            f"dp {result.departure} was the first candidate whose curve runs free "
            f"(delay {result.delay}); the minimal curve (delay {exhaustive}) touches the "
            f"region at {touching[0]}, further along the boundary, never reached"
        )
    return f"dp {result.departure} gives delay {result.delay}; minimal curve touches {touching[:2]}"


def paper_case(out_dir: pathlib.Path) -> dict[str, Any]:
    """Section IV's experiment on our paper case; writes the figures."""
    traj1, traj2 = task.paper_case()
    t_und = np.arange(max(traj1.n_samples, traj2.n_samples) + 1) * task.DT
    d_und = task.undelayed_distance(traj1, traj2)
    hit = t_und[d_und <= 0]
    times = []
    for _ in range(5):  # fresh lazy map each time: the method's own cost
        start = time.perf_counter()
        cmap = CollisionMap.from_tasks(traj1, traj2, N_LEVELS)
        result = boundary_following(cmap)
        times.append(time.perf_counter() - start)
    full = CollisionMap.from_tasks(traj1, traj2, N_LEVELS)
    exhaustive = schedules.exhaustive_min_delay(full)
    best = schedules.min_makespan(full)
    assert result.delay is not None and result.departure is not None, result.reason
    assert best is not None  # the paper case has a schedule
    delayed = schedules.delay_schedule(full, result.delay)
    sequential = schedules.sequential(full)
    d_delayed = schedule_distance(traj1, traj2, delayed.advances)
    t_delayed = np.arange(len(d_delayed)) * task.DT
    k2, s2 = result.departure
    k1 = k2 - result.delay  # the undelayed curve's column at dp
    env_check = _run_in_env("boundary-following")
    out = {
        "collision_interval_s": [float(hit[0]), float(hit[-1])],
        "delay_samples": result.delay,
        "delay_s": result.delay * task.DT,
        "departure": [k2, s2],
        "departure_k2_k1": [k2, k1],
        "exhaustive_delay_samples": exhaustive,
        "evaluated_cells": result.evaluated,
        "full_map_cells": full.full_count,
        "evaluated_ratio": result.evaluated / full.full_count,
        "planning_time_s": float(np.median(times)),
        "min_distance_after_delay_m": float(d_delayed.min()),
        "makespan_s": {
            "robot_1_alone": traj1.duration,
            "robot_2_alone": traj2.duration,
            "sequential": sequential.makespan * task.DT,
            "delay": delayed.makespan * task.DT,
            "min_makespan": best.makespan * task.DT,
        },
        "time_saved_s": (sequential.makespan - delayed.makespan) * task.DT,
        "env": env_check,
    }
    _paper_figures(out_dir, full, result, t_und, d_und, t_delayed, d_delayed, best)
    return out


def _run_in_env(policy_name: str, seeds=(0,), task_mode: str = "paper") -> dict[str, Any]:
    """Run a scripted policy in ``DualArmCell-v0`` (robot 2 driven, the paper's setting)."""
    import gymnasium as gym

    import motiongym  # noqa: F401
    from motiongym.agents.evaluation.episodes import run_episode
    from motiongym.baselines import make_policy

    env_id = "motiongym/DualArmCell-v0"
    env = gym.make(env_id, control="robot_2", pairs=task_mode)
    policy = make_policy(env_id, policy_name, env.observation_space, env.action_space, {})
    success, spans, min_d, replans = [], [], np.inf, 0
    for seed in seeds:
        result = run_episode(env, policy, int(seed))  # distance: the episode's minimum
        min_d = min(min_d, result["distance"])
        success.append(bool(result["is_success"]))
        spans.append(result["makespan"])
        replans += policy.diagnostics()["replans"] > 0
    return {
        "is_success": bool(all(success)),
        "success_rate": float(np.mean(success)),
        "makespan_s": float(np.mean(spans)),
        "min_distance_m": float(min_d),
        "episodes_replanned": int(replans),
    }


def _paper_figures(out_dir, cmap, result, t_und, d_und, t_del, d_del, best) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from motiongym.agents.reproduce.dual_arm_figures import plot_collision_map, plot_distance

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.2))
    plot_distance(axes[0], t_und, d_und, "Fig. 7: distance, both start together")
    plot_distance(axes[1], t_del, d_del, f"Fig. 10: robot 2 delayed {result.delay * task.DT:.2f} s")
    fig.tight_layout()
    fig.savefig(out_dir / "dual_arm_distance.png", dpi=120)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(10, 5))
    plot_collision_map(cmap, result, ax=ax)
    p1, p2 = schedules.sample_indices(best.advances, cmap.n1, cmap.n2)
    ax.step(np.arange(len(p2)), cmap.tl[p2], "m-", where="post", lw=1, label="min makespan")
    ax.legend(loc="lower right", fontsize=7)
    ax.set_title("Fig. 8-9: collision map and boundary following (paper case)")
    fig.tight_layout()
    fig.savefig(out_dir / "dual_arm_collision_map.png", dpi=120)
    plt.close(fig)


def study(n_pairs: int) -> dict[str, Any]:
    """Boundary following against the exhaustive scan on ``n_pairs`` colliding pairs."""
    rows: list[dict[str, Any]] = []
    seeds = [SEED0 + i for i in range(n_pairs)]
    in_env = {
        name: _run_in_env(name, seeds, "colliding")
        for name in ("boundary-following", "min-makespan")
    }
    for i in range(n_pairs):
        traj1, traj2 = task.sample_pair(np.random.default_rng(SEED0 + i), "colliding")
        lazy = CollisionMap.from_tasks(traj1, traj2, N_LEVELS)
        start = time.perf_counter()
        result = boundary_following(lazy)
        elapsed = time.perf_counter() - start
        enter = boundary_following(CollisionMap.from_tasks(traj1, traj2, N_LEVELS), shift="enter")
        full = CollisionMap.from_tasks(traj1, traj2, N_LEVELS)
        exhaustive = schedules.exhaustive_min_delay(full)
        best = schedules.min_makespan(full)
        bf_sched = (
            schedules.delay_schedule(full, result.delay) if result.delay is not None else None
        )
        assert exhaustive is not None, f"pair {SEED0 + i}: no collision-free delay"
        ex_sched = schedules.delay_schedule(full, exhaustive)
        assert best is not None
        row: dict[str, Any] = {
            "seed": SEED0 + i,
            "bf_delay": result.delay,
            "exhaustive_delay": exhaustive,
            "bf_enter_delay": enter.delay,
            "evaluated": result.evaluated,
            "full": full.full_count,
            "time_s": elapsed,
            "rounds": result.rounds,
            "makespan": {
                "sequential": schedules.sequential(full).makespan,
                "boundary_following": bf_sched.makespan if bf_sched else None,
                "exhaustive_delay": ex_sched.makespan,
                "min_makespan": best.makespan,
            },
            "exact_collision": {
                "boundary_following": bf_sched is not None
                and schedules.collides_at_samples(traj1, traj2, bf_sched.advances),
                "exhaustive_delay": schedules.collides_at_samples(traj1, traj2, ex_sched.advances),
                "min_makespan": schedules.collides_at_samples(traj1, traj2, best.advances),
            },
        }
        if result.delay != exhaustive:
            row["explanation"] = _explain(full, result, exhaustive)
        rows.append(row)
    solved = [r for r in rows if r["bf_delay"] is not None]
    agree = [r for r in solved if r["bf_delay"] == r["exhaustive_delay"]]
    spans = {k: np.array([r["makespan"][k] for r in solved]) * task.DT for k in rows[0]["makespan"]}
    return {
        "pairs": n_pairs,
        "solved": len(solved),
        "agree": len(agree),
        "agree_enter_reading": sum(r["bf_enter_delay"] == r["exhaustive_delay"] for r in rows),
        "bf_never_below_exhaustive": all(r["bf_delay"] >= r["exhaustive_delay"] for r in solved),
        "disagreements": [
            {k: r[k] for k in ("seed", "bf_delay", "exhaustive_delay", "explanation")}
            for r in rows
            if r["bf_delay"] != r["exhaustive_delay"]
        ],
        "median_evaluated_ratio": float(np.median([r["evaluated"] / r["full"] for r in rows])),
        "max_evaluated_ratio": float(np.max([r["evaluated"] / r["full"] for r in rows])),
        "median_time_s": float(np.median([r["time_s"] for r in rows])),
        "max_time_s": float(np.max([r["time_s"] for r in rows])),
        "mean_makespan_s": {k: float(v.mean()) for k, v in spans.items()},
        "exact_collisions": {
            k: int(sum(r["exact_collision"][k] for r in rows)) for k in rows[0]["exact_collision"]
        },
        "in_env": in_env,
        "rows": rows,
    }


def _study_figure(out_dir: pathlib.Path, res: dict[str, Any]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in res["rows"] if r["bf_delay"] is not None]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4))
    ex = np.array([r["exhaustive_delay"] for r in rows]) * task.DT
    bf = np.array([r["bf_delay"] for r in rows]) * task.DT
    axes[0].plot(ex, bf, "o", ms=3)
    axes[0].plot([0, ex.max()], [0, ex.max()], "k-", lw=0.6)
    axes[0].set(xlabel="exhaustive minimum delay [s]", ylabel="boundary following [s]")
    axes[1].hist([r["evaluated"] / r["full"] for r in res["rows"]], bins=20)
    axes[1].axvline(0.2, color="r", lw=0.8)
    axes[1].set(xlabel="cells evaluated / full map", ylabel="pairs")
    names = list(res["mean_makespan_s"])
    data = [[r["makespan"][k] * task.DT for r in rows] for k in names]
    axes[2].boxplot(data, tick_labels=[n.replace("_", "\n") for n in names])
    axes[2].set_ylabel("makespan [s]")
    fig.tight_layout()
    fig.savefig(out_dir / "dual_arm_study.png", dpi=120)
    plt.close(fig)


def _print(case: dict[str, Any], res: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    t = Table(title="Dual-arm cell: paper case (ours vs paper)")
    for col in ("quantity", "ours", "paper"):
        t.add_column(col)
    ci, k = case["collision_interval_s"], case["departure_k2_k1"]
    t.add_row("undelayed collision interval", f"{ci[0]:.2f}-{ci[1]:.2f} s", "0.76-1.16 s")
    t.add_row("delay TD (boundary following)", f"{case['delay_s']:.2f} s", "0.70 s")
    t.add_row("TD = (k2 - k1) x 0.02 s", f"({k[0]} - {k[1]})", "(66 - 31)")
    t.add_row(
        "exhaustive minimum delay", f"{case['exhaustive_delay_samples'] * task.DT:.2f} s", "-"
    )
    t.add_row("time saved vs sequential", f"{case['time_saved_s']:.2f} s", "1.22 s")
    t.add_row(
        "min distance after delay", f"{case['min_distance_after_delay_m'] * 1e3:.1f} mm", "> 0"
    )
    t.add_row(
        "cells evaluated / full map",
        f"{case['evaluated_cells']} / {case['full_map_cells']} ({case['evaluated_ratio']:.1%})",
        "-",
    )
    t.add_row("planning time", f"{case['planning_time_s'] * 1e3:.1f} ms", "90 s (SPARC)")
    m = case["makespan_s"]
    t.add_row(
        "makespan seq / delay / min",
        f"{m['sequential']:.2f} / {m['delay']:.2f} / {m['min_makespan']:.2f} s",
        "-",
    )
    t.add_row("in DualArmCell-v0", f"success={case['env']['is_success']}", "-")
    s = Table(title=f"Study: {res['pairs']} sampled colliding pairs")
    s.add_column("quantity")
    s.add_column("value")
    s.add_row("solved by boundary following", f"{res['solved']} / {res['pairs']}")
    s.add_row("delay == exhaustive minimum", f"{res['agree']} / {res['solved']}")
    s.add_row("never below the minimum (sound)", str(res["bf_never_below_exhaustive"]))
    s.add_row(
        "same, 'enter' reading of the shift", f"{res['agree_enter_reading']} / {res['pairs']}"
    )
    s.add_row("median cells evaluated / full map", f"{res['median_evaluated_ratio']:.1%}")
    s.add_row(
        "planning time median / max",
        f"{res['median_time_s'] * 1e3:.1f} / {res['max_time_s'] * 1e3:.1f} ms",
    )
    for k, v in res["mean_makespan_s"].items():
        s.add_row(f"mean makespan: {k}", f"{v:.2f} s")
    for k, v in res["exact_collisions"].items():
        s.add_row(f"collisions at exact samples: {k}", str(v))
    for name, r in res["in_env"].items():
        s.add_row(
            f"in DualArmCell-v0: {name}",
            f"success {r['success_rate']:.1%}, replanned {r['episodes_replanned']}",
        )
    console = Console()
    console.print(t)
    console.print(s)
    for d in res["disagreements"]:
        console.print(
            f"  seed {d['seed']}: {d['bf_delay']} vs {d['exhaustive_delay']}: {d['explanation']}"
        )


def run(out_dir: pathlib.Path, quick: bool = False) -> dict[str, Any]:
    """Run the paper case and the study (200 pairs, 12 when ``quick``); print, write, return."""
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    case = paper_case(out_dir)
    res = study(12 if quick else 200)
    _study_figure(out_dir, res)
    _print(case, res)
    truth = truth_study([SEED0 + i for i in range(3 if quick else TRUTH_PAIRS)])
    resolution = resolution_study(truth, (50, 100) if quick else (50, 100, 200, 400))
    print_truth_study(truth, resolution)
    numbers = {
        "paper": PAPER,
        "paper_case": case,
        "study": res,
        "truth": truth,
        "resolution": resolution,
    }
    (out_dir / "dual_arm.json").write_text(json.dumps(numbers, indent=2, default=_jsonable))
    return numbers


TRUTH_PAIRS = 200  # pairs judged against the brute force, and of the N_l study


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value)}")
