"""Tables and figures of the harvest-arm reproduction (:mod:`.harvest_arm`)."""

from __future__ import annotations

import pathlib
from typing import Any

import gymnasium as gym
import numpy as np

from motiongym.agents.evaluation.episodes import run_episode

MEASURE_OF = {  # the measure each ablated mechanism exists for
    "no eq. 8": "joint-to-path",
    "no eq. 9-10": "close (axis), collision",
    "no virtual plane": "stalled paths",
    "with escape": "stalled -> escaped",
    "resolved-rate": "close (axis), collision",
}


def _cell(summary: dict[str, float]) -> str:
    return f"{summary['mean']:.4f} ± {summary['std']:.4f} ({summary['below_pct']:.0f}%)"


def _tables(console: Any, results: dict[str, Any]) -> None:
    from rich.table import Table

    for key, res in results.items():
        kind, dof = key.split("-")
        table = Table(
            title=f"Table {res['table']}: shortest distances to obstacles, {kind} {dof}-DOF arm "
            "(m, mean ± std (% of trials below 0.03 m)); paired scenes"
        )
        for column in ("run", "paper", "ours: axis", "ours: clearance", "with escape: axis",
                       "resolved-rate: axis", "resolved-rate: clearance"):  # fmt: skip
            table.add_column(column)
        runs = res["runs"]
        for i, p in enumerate(res["paper"]):
            if i >= len(runs["full"]):
                break
            table.add_row(
                str(i + 1),
                f"{p[0]:.4f} ± {p[1]:.4f} ({p[2]}%)",
                _cell(runs["full"][i]["axis"]),
                _cell(runs["full"][i]["clearance"]),
                _cell(runs["with escape"][i]["axis"]),
                _cell(runs["resolved-rate"][i]["axis"]),
                _cell(runs["resolved-rate"][i]["clearance"]),
            )
        console.print(table)


def _ablation(console: Any, results: dict[str, Any]) -> None:
    from rich.table import Table

    table = Table(title="Ablations on the paired scenes (close: shortest distance < 0.03 m; "
                  "p: exact McNemar against full, close (axis) / collision / stalled)")  # fmt: skip
    for column in ("arm", "variant", "n", "succ. %", "coll. %", "self %",
                   "close axis % [95% CI]", "close clear. %", "joint-path m",
                   "stalled %", "escaped %", "ms/step", "p close/coll/stall",
                   "d joint-path ± 95%"):  # fmt: skip
        table.add_column(column, no_wrap=True)
    for key, res in results.items():
        for name, r in res["rates"].items():
            test = res["ablation"].get(name)
            p = diff = ""
            if test is not None:
                p = "/".join(f"{test[m]['p']:.2g}" for m in ("close_axis", "collision", "stalled"))
                diff = f"{test['joint_to_path_diff'][0]:+.3f} ± {test['joint_to_path_diff'][1]:.3f}"
            low, high = r["close_axis_ci95"]
            table.add_row(
                key, name, str(r["n"]), f"{r['success_pct']:.1f}", f"{r['collision_pct']:.1f}",
                f"{r['self_collision_pct']:.1f}",
                f"{r['close_axis_pct']:.1f} [{low:.1f}, {high:.1f}]",
                f"{r['close_clearance_pct']:.1f}", f"{r['joint_to_path']:.3f}",
                f"{r['stalled_pct']:.1f}", f"{r['escaped_pct']:.1f}", f"{r['ms_per_step']:.2f}",
                p, diff,
            )  # fmt: skip
    console.print(table)


def print_report(results: dict[str, Any], trend: dict[str, Any]) -> None:
    """The paper's tables with ours beside, the DOF trend and the ablation table."""
    from rich.console import Console

    console = Console(width=240)
    _tables(console, results)
    for kind, t in trend.items():
        low, high = t["dofs"]
        for measure in ("close_axis", "close_clearance", "collision"):
            m = t[measure]
            console.print(
                f"DOF trend, {kind} {low} vs {high} DOF, {measure}: only {low}-DOF "
                f"{m['only_first']}, only {high}-DOF {m['only_second']}, McNemar p = {m['p']:.3g}"
            )
    _ablation(console, results)


def figures(results: dict[str, Any], out_dir: pathlib.Path) -> list[str]:
    """% below 0.03 m per arm (paper, ours, baseline) and the Fig. 8 analogue."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = list(results)
    x = np.arange(len(keys))
    bars = [
        ("paper", [np.mean([r[2] for r in results[k]["paper"]]) for k in keys]),
        ("ours, axis", [results[k]["rates"]["full"]["close_axis_pct"] for k in keys]),
        ("ours, clearance", [results[k]["rates"]["full"]["close_clearance_pct"] for k in keys]),
        ("resolved-rate, axis", [results[k]["rates"]["resolved-rate"]["close_axis_pct"]
                                 for k in keys]),
    ]  # fmt: skip
    fig, ax = plt.subplots(figsize=(8, 4))
    for i, (label, values) in enumerate(bars):
        ax.bar(x - 0.3 + 0.2 * i, values, 0.2, label=label)
    ax.set_xticks(x, keys)
    ax.set_ylabel("% of trials below 0.03 m")
    ax.legend(fontsize=8)
    fig.tight_layout()
    name = "harvest_arm_close_approaches.png"
    fig.savefig(out_dir / name, dpi=100)
    plt.close(fig)
    return [name, _figure8(out_dir, plt)]


def _figure8(out_dir: pathlib.Path, plt: Any) -> str:
    """Paper Fig. 8: a 3-D run among bars, the safe path, the arm."""
    from motiongym.agents.reproduce.harvest_arm import _kwargs, _Trial
    from motiongym.baselines.harvest_arm.policy import PotentialFieldPolicy

    kwargs = _kwargs("spatial", 5)
    env = gym.make("motiongym/HarvestArm-v1", **kwargs)
    policy = PotentialFieldPolicy(env.observation_space, env.action_space, kwargs)
    paths: list[np.ndarray] = []

    def hook(step: Any) -> None:
        trial(step)
        if step.index == 0:
            paths.append(step.predictor.diagnostics()["path"])

    trial = _Trial(env)
    run_episode(env, policy, seed=7, hook=hook)
    scene = env.get_wrapper_attr("scene")
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="3d")
    for a, b, bar in zip(scene.a, scene.b, scene.is_bar, strict=True):
        if bar:
            ax.plot(*np.stack([a, b]).T, color="saddlebrown", lw=2)
        else:
            ax.scatter(*a, color="green", s=30)
    ax.scatter(*scene.fruit, s=120, facecolors="none", edgecolors="red")
    ax.plot(*paths[0].T, color="orange", lw=1, label="safe path (eq. 2-7)")
    poses = np.array(trial.poses)
    for i in np.linspace(0, len(poses) - 1, 6).astype(int):
        ax.plot(*poses[i].T, color="navy", lw=2.5, alpha=0.3 + 0.7 * i / max(len(poses) - 1, 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(f"5-DOF arm among bars; shortest axis distance {trial.axis:.3f} m")
    ax.legend(fontsize=8)
    name = "harvest_arm_fig8.png"
    fig.savefig(out_dir / name, dpi=100)
    plt.close(fig)
    return name
