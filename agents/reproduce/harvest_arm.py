"""Reproduction of the harvest-arm paper's simulation study (Tables 4-9, Fig. 8).

Protocol (paper section 3-ra, 4): planar arms with 3, 4, 5 DOF among 8
random obstacles and spatial arms with 5, 6, 7 DOF among 10 random obstacles
(3 bars), 4 runs x 50 trials each. Per trial: the shortest arm-obstacle
distance over the whole motion; per run: its mean, standard deviation and
the percentage of trials below 0.03 m. As in the paper, the arm always drives
on to the fruit (``terminate_on_collision=False``); success (gripper within
tolerance of the fruit) and collision (an obstacle touched, or two
non-adjacent links touching: the ``-v1`` IDs) are reported beside.

**Paired scenes.** The paper compares the DOF "on the same obstacle
environments". Scenes are drawn by the first arm of each kind (planar 3-DOF,
spatial 5-DOF) from seeds 0, 1, 2, ...; a scene is kept if it is valid for
all three arms of its kind (obstacles 0.05 m clear of each arm's start pose,
the fruit reachable by each: :mod:`motiongym.envs.harvest_arm.task`'s rules),
and the first 200 kept are run ``r`` = 0-3 of 50. Every arm, policy and
ablation sees exactly these scenes, passed as reset options.

**One distance.** The paper's "shortest distance between the joints and the
obstacles" treats the links as lines and the obstacles as points and lines
(its eq. 9-10 measure ``rho`` from the link's line to the obstacle's point or
axis). Our *axis distance* is that: link centre segments to obstacle centres
and bar axes. It is the distance of every comparison with the paper below,
for our method and the baselines alike; the *clearance* (surface to surface:
link capsules of radius 0.02 m against spheres of 0.01-0.02 m and bars of
0.008 m; the environment's ``min_distance`` and ``cost``) is printed beside
it and is 0.028-0.04 m smaller.

Printed: the paper's Tables 4-9 (paper run beside ours: axis distance, then
clearance); the DOF trend (exact McNemar test on the paired scenes: the
lowest against the highest DOF of each kind); the ablation table (the
paper's method in full, without eq. 8, without eq. 9-10, without the virtual
plane, with our vortex escape, and the resolved-rate baseline) with the
measure each mechanism is for and McNemar's p against the full method.
Written: ``harvest_arm.json`` (every number), ``harvest_arm_close_approaches.png``
and ``harvest_arm_fig8.png`` (paper Fig. 8: a spatial run among bars).
"""

from __future__ import annotations

import json
import pathlib
import time
from typing import Any

import gymnasium as gym
import numpy as np
from scipy.stats import binomtest

import motiongym  # noqa: F401  (registers the IDs)
from motiongym.agents.evaluation.episodes import Step, run_episode
from motiongym.agents.evaluation.statistics import wilson_interval
from motiongym.baselines.harvest_arm.policy import (
    ExtendedPotentialFieldPolicy,
    PotentialFieldPolicy,
    ResolvedRatePolicy,
)
from motiongym.envs.geometry import closest_point_on_segment
from motiongym.envs.harvest_arm.observation import observation_views
from motiongym.envs.harvest_arm.task import START_CLEARANCE, clearance_to_arm, solve_ik

PAPER = {  # (mean m, std m, % below 0.03 m) per run, Tables 4-9
    ("planar", 3): [(0.0732, 0.0350, 8), (0.0700, 0.0394, 22), (0.0786, 0.0352, 12),
                    (0.0796, 0.0407, 14)],
    ("planar", 4): [(0.0668, 0.0273, 8), (0.0691, 0.0347, 12), (0.0772, 0.0452, 6),
                    (0.0737, 0.0288, 4)],
    ("planar", 5): [(0.0681, 0.0220, 4), (0.0748, 0.0237, 0), (0.0745, 0.0228, 2),
                    (0.0685, 0.0245, 4)],
    ("spatial", 5): [(0.0834, 0.0414, 8), (0.0890, 0.0402, 6), (0.0991, 0.0497, 6),
                     (0.0926, 0.0461, 6)],
    ("spatial", 6): [(0.0838, 0.0358, 8), (0.0775, 0.0382, 8), (0.0861, 0.0383, 6),
                     (0.0917, 0.0424, 8)],
    ("spatial", 7): [(0.0939, 0.0380, 0), (0.0964, 0.0395, 2), (0.0976, 0.0422, 0),
                     (0.1003, 0.0406, 4)],
}  # fmt: skip
TABLE = {("planar", 3): 4, ("planar", 4): 5, ("planar", 5): 6,
         ("spatial", 5): 7, ("spatial", 6): 8, ("spatial", 7): 9}  # fmt: skip
DOFS = {"planar": (3, 4, 5), "spatial": (5, 6, 7)}
SAFETY = 0.03  # m, the paper's collision-risk distance
VARIANTS: dict[str, tuple[type, dict[str, bool]]] = {
    "full": (PotentialFieldPolicy, {}),
    "no eq. 8": (PotentialFieldPolicy, {"trajectory_following": False}),
    "no eq. 9-10": (PotentialFieldPolicy, {"link_avoidance": False}),
    "no virtual plane": (PotentialFieldPolicy, {"virtual_plane": False}),
    "with escape": (ExtendedPotentialFieldPolicy, {}),
    "resolved-rate": (ResolvedRatePolicy, {}),
}
"""The paper's method (``potential-field``), each mechanism off, our escape
(``potential-field-extended``) and the plain baseline."""


def _env_id(kind: str) -> str:
    return "motiongym/HarvestArmPlanar-v1" if kind == "planar" else "motiongym/HarvestArm-v1"


def _kwargs(kind: str, dof: int) -> dict[str, Any]:
    return {**gym.spec(_env_id(kind)).kwargs, "dof": dof, "terminate_on_collision": False}


def _as_options(scene: Any) -> dict[str, Any]:
    obstacles = [
        {"a": a.tolist(), "b": b.tolist(), "radius": float(r)}
        if bar
        else {"center": a.tolist(), "radius": float(r)}
        for a, b, r, bar in zip(scene.a, scene.b, scene.radius, scene.is_bar, strict=True)
    ]
    return {"fruit": scene.fruit.tolist(), "obstacles": obstacles}


def paired_scenes(kind: str, n: int) -> tuple[list[dict[str, Any]], int]:
    """The first ``n`` scenes valid for every arm of ``kind`` (reset options), and seeds drawn."""
    envs: list[Any] = [  # the arms' own environments (scene, kinematics, link radius)
        gym.make(_env_id(kind), **_kwargs(kind, dof)).unwrapped for dof in DOFS[kind]
    ]
    scenes: list[dict[str, Any]] = []
    seed = 0
    while len(scenes) < n:
        envs[0].reset(seed=seed)
        scene = envs[0].scene
        seed += 1
        valid = True
        for env in envs[1:]:
            kin, home = env.world.kinematics, np.array(env.world.arm.home)
            start = kin.forward(home)
            radius = env.params.link_radius
            valid &= bool(clearance_to_arm(start, radius, scene).min() >= START_CLEARANCE)
            valid = valid and solve_ik(kin, scene.fruit, home)[1] < 2e-3
        if valid:
            scenes.append(_as_options(scene))
    return scenes, seed


class _Trial:
    """A run_episode hook: shortest distances, collisions and the poses of one trial."""

    def __init__(self, env: gym.Env, record: bool = False) -> None:
        base: Any = env.unwrapped  # the arm's environment (its task's layout, link radius)
        self.layout, self.record = base.task.layout, record
        self.link_radius = base.params.link_radius
        self.axis = self.clearance = np.inf
        self.collision = self.self_collision = False
        self.poses: list[np.ndarray] = []

    def __call__(self, step: Step) -> None:
        o = observation_views(self.layout, step.next_observation)
        axes = o["distances"] + self.link_radius + o["radius"][None, :]  # (L, K) centre lines
        self.axis = min(self.axis, float(axes[:, o["mask"]].min()))
        self.clearance = min(self.clearance, step.info["min_distance"])
        self.collision |= bool(step.info["collision"])
        self.self_collision |= bool(step.info.get("self_collision", False))
        self.poses.append(o["points"].copy())

    def joint_to_path(self) -> float:
        """Mean distance of the joints (base and gripper excluded) to the gripper's travelled
        path, over the second half of the motion (m): eq. 8's measure."""
        poses = np.array(self.poses)  # (T, P, dim)
        trail = poses[:, -1]
        values = []
        for t in range(max(2, len(poses) // 2), len(poses)):
            d, _ = closest_point_on_segment(
                poses[t, 1:-1, None], trail[None, :t], trail[None, 1 : t + 1]
            )
            values.append(d.min(axis=1).mean())
        return float(np.mean(values)) if values else float("nan")


def run_variant(kind: str, dof: int, variant: str, scenes: list[dict]) -> dict[str, Any]:
    """One arm and one policy variant on the paired scenes: per-trial measures."""
    env = gym.make(_env_id(kind), **_kwargs(kind, dof))
    cls, options = VARIANTS[variant]
    policy = cls(env.observation_space, env.action_space, _kwargs(kind, dof), **options)
    trials: dict[str, list] = {k: [] for k in (
        "axis", "clearance", "success", "collision", "self_collision", "joint_to_path",
        "stalled", "escaped", "steps")}  # fmt: skip
    t0 = time.perf_counter()
    for i, scene in enumerate(scenes):
        hook = _Trial(env)
        result = run_episode(env, policy, seed=i, hook=hook, options=scene)
        diagnostics = policy.diagnostics()
        for key, value in (
            ("axis", hook.axis), ("clearance", hook.clearance),
            ("success", bool(result["is_success"])), ("collision", hook.collision),
            ("self_collision", hook.self_collision), ("joint_to_path", hook.joint_to_path()),
            ("stalled", bool(diagnostics.get("stalled", False))),
            ("escaped", diagnostics.get("escapes", 0) > 0), ("steps", result["length"]),
        ):  # fmt: skip
            trials[key].append(value)
    seconds = time.perf_counter() - t0
    out: dict[str, Any] = {key: np.array(value) for key, value in trials.items()}
    out["ms_per_step"] = 1e3 * seconds / max(int(out["steps"].sum()), 1)
    return out


def mcnemar(first: np.ndarray, second: np.ndarray) -> dict[str, float]:
    """Exact McNemar test of paired booleans: discordant counts and two-sided p."""
    b = int(np.sum(first & ~second))
    c = int(np.sum(~first & second))
    p = 1.0 if b + c == 0 else float(binomtest(b, b + c, 0.5).pvalue)
    return {"only_first": b, "only_second": c, "p": p}


def _summary(values: np.ndarray) -> dict[str, float]:
    return {
        "mean": float(values.mean()),
        "std": float(values.std()),
        "below_pct": float(100.0 * (values < SAFETY).mean()),
    }


def _rates(t: dict[str, Any]) -> dict[str, float]:
    n = len(t["axis"])
    close = t["axis"] < SAFETY
    return {
        "n": n,
        "success_pct": 100.0 * t["success"].mean(),
        "collision_pct": 100.0 * t["collision"].mean(),
        "self_collision_pct": 100.0 * t["self_collision"].mean(),
        "close_axis_pct": 100.0 * close.mean(),
        "close_axis_ci95": _wilson(int(close.sum()), n),
        "close_clearance_pct": 100.0 * (t["clearance"] < SAFETY).mean(),
        "mean_axis": float(t["axis"].mean()),
        "mean_clearance": float(t["clearance"].mean()),
        "joint_to_path": float(np.nanmean(t["joint_to_path"])),
        "stalled_pct": 100.0 * t["stalled"].mean(),
        "escaped_pct": 100.0 * t["escaped"].mean(),
        "ms_per_step": float(t["ms_per_step"]),
    }


def _wilson(k: int, n: int, z: float = 1.96) -> list[float]:
    """Wilson 95 % interval of a proportion, in %."""
    return [100.0 * bound for bound in wilson_interval(k, n, z)]


def _ablation_tests(trials: dict[str, dict], full: dict) -> dict[str, dict]:
    """Each variant against the full method on the paired scenes."""
    out = {}
    for name, t in trials.items():
        if name == "full":
            continue
        diff = t["joint_to_path"] - full["joint_to_path"]
        diff = diff[np.isfinite(diff)]
        half = 1.96 * diff.std(ddof=1) / np.sqrt(len(diff)) if len(diff) > 1 else float("nan")
        out[name] = {
            "close_axis": mcnemar(t["axis"] < SAFETY, full["axis"] < SAFETY),
            "collision": mcnemar(t["collision"], full["collision"]),
            "stalled": mcnemar(t["stalled"], full["stalled"]),
            "joint_to_path_diff": [float(diff.mean()), float(half)],
        }
    return out


def evaluate(kind: str, dof: int, scenes: list[dict], runs: int) -> dict[str, Any]:
    """Every variant on one arm: per-run tables, rates and the ablation tests."""
    trials = {name: run_variant(kind, dof, name, scenes) for name in VARIANTS}
    per = len(scenes) // runs
    tables = {
        name: [
            {
                "axis": _summary(trials[name]["axis"][r * per : (r + 1) * per]),
                "clearance": _summary(trials[name]["clearance"][r * per : (r + 1) * per]),
            }
            for r in range(runs)
        ]
        for name in ("full", "with escape", "resolved-rate")
    }
    return {
        "paper": PAPER[(kind, dof)],
        "table": TABLE[(kind, dof)],
        "runs": tables,
        "rates": {name: _rates(t) for name, t in trials.items()},
        "ablation": _ablation_tests(trials, trials["full"]),
        "_trials": trials,
    }


def _dof_trend(results: dict[str, Any]) -> dict[str, Any]:
    """McNemar, lowest against highest DOF of each kind, full method, paired scenes."""
    out = {}
    for kind, dofs in DOFS.items():
        low = results[f"{kind}-{dofs[0]}"]["_trials"]["full"]
        high = results[f"{kind}-{dofs[-1]}"]["_trials"]["full"]
        out[kind] = {
            "dofs": [dofs[0], dofs[-1]],
            "close_axis": mcnemar(low["axis"] < SAFETY, high["axis"] < SAFETY),
            "close_clearance": mcnemar(low["clearance"] < SAFETY, high["clearance"] < SAFETY),
            "collision": mcnemar(low["collision"], high["collision"]),
        }
    return out


def run(out_dir: pathlib.Path, quick: bool = False) -> dict:
    """Tables 4-9, the DOF trend and the ablations (``quick``: 1 run x 6 paired scenes)."""
    from motiongym.agents.reproduce.harvest_arm_report import figures, print_report

    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    runs, trials = (1, 6) if quick else (4, 50)
    t0 = time.perf_counter()
    results, drawn = {}, {}
    for kind, dofs in DOFS.items():
        scenes, drawn[kind] = paired_scenes(kind, runs * trials)
        for dof in dofs:
            results[f"{kind}-{dof}"] = evaluate(kind, dof, scenes, runs)
    trend = _dof_trend(results)
    print_report(results, trend)
    numbers = {
        "protocol": {
            "runs": runs,
            "trials": trials,
            "safety_distance": SAFETY,
            "distance": "axis (link centre segments to obstacle centres and bar axes)",
            "seeds_drawn": drawn,
        },
        "results": {k: {f: v for f, v in r.items() if f != "_trials"} for k, r in results.items()},
        "dof_trend": trend,
    }
    numbers["figures"] = figures(results, out_dir)
    numbers["seconds"] = time.perf_counter() - t0
    (out_dir / "harvest_arm.json").write_text(json.dumps(numbers, indent=2, default=float))
    print(f"harvest-arm reproduction: {numbers['seconds']:.0f} s")
    return numbers
