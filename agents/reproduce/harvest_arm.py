"""Reproduction of the harvest-arm paper's simulation study (Tables 4-9, Fig. 8).

Protocol (paper section 3-ra, 4): planar arms with 3, 4, 5 DOF among 8
random obstacles and spatial arms with 5, 6, 7 DOF among 10 random obstacles
(3 bars), 4 runs x 50 trials each. Per trial: the shortest arm-obstacle
distance over the whole motion; per run: its mean, standard deviation and
the percentage of trials below 0.03 m. As in the paper, the arm always drives
on to the fruit (``terminate_on_collision=False``); success (gripper within
tolerance of the fruit) and collision (clearance <= 0 at some step) are
reported beside.

Two distances per trial: the *clearance* (surface to surface, link capsules
of radius 0.02 m vs obstacle spheres and bars, what the environment's
``min_distance`` and ``cost`` use) and the *axis distance* (link centre
segments to obstacle centres and bar axes, the paper's model of links and
obstacles as lines and points). Run ``r`` uses the seeds ``1000 r + t``;
every policy sees the same scenes: the paper's method (``potential-field``),
the same with our two extensions of eq. 9-10 (``potential-field-extended``)
and the plain resolved-rate baseline (``resolved-rate``).

Where ours differ from the paper (full protocol, 200 trials per arm): the
mean shortest axis distances agree (planar 0.075-0.083 m vs 0.067-0.080 m,
spatial 0.082-0.095 m vs 0.078-0.100 m) and the spatial close approaches
fall with DOF (about 10, 9, 6.5 % vs the paper's 6.5, 7.5, 1.5 %), but the
planar ones stay near 13 % for 3, 4 and 5 DOF (paper 14, 7.5, 2.5 %). In our
planar scenes almost every close approach happens on arrival, on the two
links next to the gripper, against an obstacle about 0.2 m from the fruit
that the gripper's path went round on the side away from the base: in the
plane the arm's body cannot follow it round, whatever the DOF. The paper's
scene distribution is not given; ours is documented in
:mod:`motiongym.envs.harvest_arm.task`. The clearance (surface) figures are
higher than the axis ones because links and obstacles have thickness.

Printed: one table per paper table, the paper's run beside ours; written:
``harvest_arm.json`` (every number), ``harvest_arm_close_approaches.png``
(% below 0.03 m per arm: paper, ours, baseline) and ``harvest_arm_fig8.png``
(paper Fig. 8: a spatial run among bars, the safe path, the arm).
"""

from __future__ import annotations

import json
import pathlib
import time
from typing import Any

import gymnasium as gym
import numpy as np

import motiongym  # noqa: F401  (registers the IDs)
from motiongym.baselines import make_policy

PAPER = {  # (mean m, std m, % below 0.03 m) per run, Tables 4-9
    ("planar", 3): [
        (0.0732, 0.0350, 8),
        (0.0700, 0.0394, 22),
        (0.0786, 0.0352, 12),
        (0.0796, 0.0407, 14),
    ],
    ("planar", 4): [
        (0.0668, 0.0273, 8),
        (0.0691, 0.0347, 12),
        (0.0772, 0.0452, 6),
        (0.0737, 0.0288, 4),
    ],
    ("planar", 5): [
        (0.0681, 0.0220, 4),
        (0.0748, 0.0237, 0),
        (0.0745, 0.0228, 2),
        (0.0685, 0.0245, 4),
    ],
    ("spatial", 5): [
        (0.0834, 0.0414, 8),
        (0.0890, 0.0402, 6),
        (0.0991, 0.0497, 6),
        (0.0926, 0.0461, 6),
    ],
    ("spatial", 6): [
        (0.0838, 0.0358, 8),
        (0.0775, 0.0382, 8),
        (0.0861, 0.0383, 6),
        (0.0917, 0.0424, 8),
    ],
    ("spatial", 7): [
        (0.0939, 0.0380, 0),
        (0.0964, 0.0395, 2),
        (0.0976, 0.0422, 0),
        (0.1003, 0.0406, 4),
    ],
}
TABLE = {
    ("planar", 3): 4,
    ("planar", 4): 5,
    ("planar", 5): 6,
    ("spatial", 5): 7,
    ("spatial", 6): 8,
    ("spatial", 7): 9,
}
POLICIES = ("potential-field", "potential-field-extended", "resolved-rate")
SAFETY = 0.03  # m


def _env_id(kind: str) -> str:
    return "motiongym/HarvestArmPlanar-v0" if kind == "planar" else "motiongym/HarvestArm-v0"


def run_trial(env: gym.Env, policy: Any, seed: int, record: bool = False) -> dict[str, Any]:
    """One trial: shortest clearance and axis distance, success, collision (and the poses)."""
    base = env.unwrapped
    layout, link_radius = base.layout, base.link_radius
    observation, info = env.reset(seed=seed)
    policy.reset()
    clearance, axis = np.inf, np.inf
    poses, start, steps = [], True, 0
    while True:
        o = layout.parse(observation)
        axes = o["distances"] + link_radius + o["radius"][None, :]
        axis = min(axis, float(axes[:, o["mask"]].min()))
        clearance = min(clearance, info["min_distance"])
        if record:
            poses.append(o["points"].copy())
        action, _ = policy.predict(observation, episode_start=start)
        start = False
        observation, _, terminated, truncated, info = env.step(action)
        steps += 1
        if terminated or truncated:
            break
    o = layout.parse(observation)
    axes = o["distances"] + link_radius + o["radius"][None, :]
    axis = min(axis, float(axes[:, o["mask"]].min()))
    clearance = min(clearance, info["min_distance"])
    if record:
        poses.append(o["points"].copy())
    out = {
        "clearance": clearance,
        "axis": axis,
        "success": bool(info["is_success"]),
        "collision": clearance <= 0.0,
        "steps": steps,
    }
    if record:
        out["poses"] = np.array(poses)
    return out


def _summary(values: np.ndarray) -> dict[str, float]:
    return {
        "mean": float(values.mean()),
        "std": float(values.std()),
        "below_pct": float(100.0 * (values < SAFETY).mean()),
    }


def evaluate(kind: str, dof: int, runs: int, trials: int) -> dict[str, Any]:
    """The protocol for one arm; both policies on the same seeds."""
    env_id = _env_id(kind)
    env = gym.make(env_id, dof=dof, terminate_on_collision=False)
    kwargs = {**gym.spec(env_id).kwargs, "dof": dof, "terminate_on_collision": False}
    result: dict[str, Any] = {"paper": PAPER[(kind, dof)], "table": TABLE[(kind, dof)]}
    for name in POLICIES:
        policy = make_policy(env_id, name, env.observation_space, env.action_space, kwargs)
        per_run = []
        t0, n_steps = time.perf_counter(), 0
        for r in range(runs):
            trials_out = [run_trial(env, policy, 1000 * r + t) for t in range(trials)]
            n_steps += sum(t["steps"] for t in trials_out)
            clear = np.array([t["clearance"] for t in trials_out])
            axis = np.array([t["axis"] for t in trials_out])
            per_run.append(
                {
                    "clearance": _summary(clear),
                    "axis": _summary(axis),
                    "success_pct": float(100 * np.mean([t["success"] for t in trials_out])),
                    "collision_pct": float(100 * np.mean([t["collision"] for t in trials_out])),
                }
            )
        result[name] = {
            "runs": per_run,
            "ms_per_step": 1e3 * (time.perf_counter() - t0) / max(n_steps, 1),
        }
    return result


def _cell(summary: dict[str, float]) -> str:
    return f"{summary['mean']:.4f} ± {summary['std']:.4f} ({summary['below_pct']:.0f}%)"


def _print(results: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console(width=160)
    for key, res in results.items():
        kind, dof = key.split("-")
        table = Table(
            title=f"Table {res['table']}: shortest distances to obstacles, {kind} {dof}-DOF arm "
            "(m, mean ± std (% of trials below 0.03 m))"
        )
        table.add_column("run")
        table.add_column("paper")
        table.add_column("ours: axis distance")
        table.add_column("ours: clearance")
        table.add_column("succ/coll %")
        table.add_column("extended: clearance")
        table.add_column("resolved-rate: clearance")
        table.add_column("RR succ/coll %")
        pf, ext, rr = (res[name]["runs"] for name in POLICIES)
        for i, (p, a, e, b) in enumerate(zip(res["paper"], pf, ext, rr, strict=False)):
            table.add_row(
                str(i + 1),
                f"{p[0]:.4f} ± {p[1]:.4f} ({p[2]}%)",
                _cell(a["axis"]),
                _cell(a["clearance"]),
                f"{a['success_pct']:.0f}/{a['collision_pct']:.0f}",
                _cell(e["clearance"]),
                _cell(b["clearance"]),
                f"{b['success_pct']:.0f}/{b['collision_pct']:.0f}",
            )
        console.print(table)


def _pooled(res: dict[str, Any], policy: str, measure: str) -> float:
    return float(np.mean([r[measure]["below_pct"] for r in res[policy]["runs"]]))


def _figures(results: dict[str, Any], out_dir: pathlib.Path, quick: bool) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    keys = list(results)
    x = np.arange(len(keys))
    paper = [np.mean([r[2] for r in results[k]["paper"]]) for k in keys]
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.bar(x - 0.3, paper, 0.2, label="paper")
    ax.bar(x - 0.1, [_pooled(results[k], "potential-field", "axis") for k in keys], 0.2,
           label="ours, axis distance")  # fmt: skip
    ax.bar(x + 0.1, [_pooled(results[k], "potential-field", "clearance") for k in keys], 0.2,
           label="ours, clearance")  # fmt: skip
    ax.bar(x + 0.3, [_pooled(results[k], "resolved-rate", "clearance") for k in keys], 0.2,
           label="plain resolved-rate, clearance")  # fmt: skip
    ax.plot(x + 0.1, [_pooled(results[k], "potential-field-extended", "clearance") for k in keys],
            "k_", ms=14, label="extended, clearance")  # fmt: skip
    ax.set_xticks(x, keys)
    ax.set_ylabel("% of trials below 0.03 m")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = out_dir / "harvest_arm_close_approaches.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    files.append(path.name)
    files.append(_figure8(out_dir, plt))
    return files


def _figure8(out_dir: pathlib.Path, plt: Any) -> str:
    """Paper Fig. 8: a 3-D run among bars, the safe path, the arm."""
    env_id = _env_id("spatial")
    env = gym.make(env_id, dof=5, terminate_on_collision=False)
    kwargs = {**gym.spec(env_id).kwargs, "dof": 5}
    policy = make_policy(env_id, "potential-field", env.observation_space, env.action_space, kwargs)
    trial = run_trial(env, policy, seed=7, record=True)
    scene = env.unwrapped.scene
    path = policy._memories[0]["path"]
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="3d")
    for a, b, bar in zip(scene.a, scene.b, scene.is_bar, strict=True):
        if bar:
            ax.plot(*np.stack([a, b]).T, color="saddlebrown", lw=2)
        else:
            ax.scatter(*a, color="green", s=30)
    ax.scatter(*scene.fruit, s=120, facecolors="none", edgecolors="red")
    ax.plot(*path.T, color="orange", lw=1, label="safe path (eq. 2-7)")
    poses = trial["poses"]
    for i in np.linspace(0, len(poses) - 1, 6).astype(int):
        ax.plot(*poses[i].T, color="navy", lw=2.5, alpha=0.3 + 0.7 * i / (len(poses) - 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(f"5-DOF arm among bars; shortest clearance {trial['clearance']:.3f} m")
    ax.legend(fontsize=8)
    name = "harvest_arm_fig8.png"
    fig.savefig(out_dir / name, dpi=100)
    plt.close(fig)
    return name


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Tables 4-9 on our scenes (``quick``: 1 run x 6 trials per arm)."""
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    runs, trials = (1, 6) if quick else (4, 50)
    results = {}
    for kind, dofs in (("planar", (3, 4, 5)), ("spatial", (5, 6, 7))):
        for dof in dofs:
            results[f"{kind}-{dof}"] = evaluate(kind, dof, runs, trials)
    _print(results)
    summary = {
        key: {
            "paper_below_pct": float(np.mean([r[2] for r in res["paper"]])),
            "ours_axis_below_pct": _pooled(res, "potential-field", "axis"),
            "ours_clearance_below_pct": _pooled(res, "potential-field", "clearance"),
            "extended_clearance_below_pct": _pooled(res, "potential-field-extended", "clearance"),
            "baseline_clearance_below_pct": _pooled(res, "resolved-rate", "clearance"),
            "baseline_axis_below_pct": _pooled(res, "resolved-rate", "axis"),
        }
        for key, res in results.items()
    }
    numbers = {
        "protocol": {"runs": runs, "trials": trials, "safety_distance": SAFETY},
        "results": results,
        "summary": summary,
    }
    numbers["figures"] = _figures(results, out_dir, quick)
    (out_dir / "harvest_arm.json").write_text(json.dumps(numbers, indent=2))
    return numbers
