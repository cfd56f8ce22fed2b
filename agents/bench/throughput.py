"""Throughput of every world, its scripted policies and planners, and PPO on it.

Machines are noisy, so every figure is printed beside a reference measured in
the same run, as a ratio; environments and their references are timed in
alternating chunks, so that load drifting during the run affects both alike.
The references: Gymnasium's ``CartPole-v1`` and ``Reacher-v5``, MiniGrid's
``MiniGrid-Empty-16x16-v0``, and PPO on ``Reacher-v5`` for training. The
systems' declared goals are checked here (never by timed tests): ``GOALS`` for
environment throughput, ``VECTOR_GOALS`` for the natively vectorised worlds,
``PLANNERS`` for planning times.

Memory: each ID runs in a fresh subprocess (:mod:`motiongym.agents.bench.memory_probe`)
for a million random steps (20,000 with ``--quick``): the environment's own
resident memory, its peak, and the growth from the first tenth to the end.
"""

from __future__ import annotations

import importlib
import json
import os
import platform
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium as gym
import minigrid  # noqa: F401  (registers the MiniGrid reference)
import numpy as np
from rich.markdown import Markdown

from motiongym.agents.environments import check_env_id, make_env, resolved_env_kwargs
from motiongym.agents.evaluation.report import console
from motiongym.baselines import make_policy, scripted_policies
from motiongym.envs import ENV_IDS
from motiongym.systems import declared

REFERENCES = ("CartPole-v1", "Reacher-v5", "MiniGrid-Empty-16x16-v0")
# Goals and planners, as each system declares them (motiongym.systems).
GOALS: dict[str, tuple[str, float]] = declared("envs", "BENCH_GOALS")
VECTOR_GOALS: dict[str, tuple[float, float]] = declared("envs", "BENCH_VECTOR_GOALS")
PLANNERS: dict[str, tuple[str, float | None]] = declared("baselines", "PLANNERS")


def machine() -> str:
    """The processor and core count, for the published table."""
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores, Python {platform.python_version()}"


def steps_per_second(env: gym.Env, seconds: float, seed: int = 0) -> float:
    """Random-action steps per second of ``env`` (resets included)."""
    env.reset(seed=seed)
    env.action_space.seed(seed)
    actions = [env.action_space.sample() for _ in range(1024)]
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        for action in actions:
            _, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                env.reset()
        steps += len(actions)
    return steps / (time.perf_counter() - start)


def interleaved_steps_per_second(
    envs: dict[str, gym.Env], seconds: float, rounds: int = 5
) -> dict[str, float]:
    """Steps per second of each env, measured in alternating chunks.

    The machine's load drifts; timing an environment and its references in
    turns, ``rounds`` times, exposes them to the same drift, so the ratios
    between them are fair.
    """
    steps = dict.fromkeys(envs, 0.0)
    elapsed = dict.fromkeys(envs, 0.0)
    for _ in range(rounds):
        for name, env in envs.items():
            start = time.perf_counter()
            rate = steps_per_second(env, seconds / rounds)
            took = time.perf_counter() - start
            steps[name] += rate * took
            elapsed[name] += took
    return {name: steps[name] / elapsed[name] for name in envs}


def vector_steps_per_second(env: gym.vector.VectorEnv, seconds: float) -> float:
    """Steps per second, summed over sub-environments, of a vector env."""
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(16)]
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        for action in actions:
            env.step(action)
        steps += len(actions) * env.num_envs
    return steps / (time.perf_counter() - start)


def policy_ms_per_step(env_id: str, name: str, max_steps: int) -> float:
    """Milliseconds per ``predict`` call of a scripted policy over one episode."""
    env = make_env(env_id)
    policy = make_policy(
        env_id, name, env.observation_space, env.action_space, resolved_env_kwargs(env_id, None)
    )
    observation, _ = env.reset(seed=0)
    elapsed, steps, start_flag = 0.0, 0, True
    while steps < max_steps:
        start = time.perf_counter()
        action, _ = policy.predict(observation, episode_start=np.array([start_flag]))
        elapsed += time.perf_counter() - start
        start_flag = False
        observation, _, terminated, truncated, _ = env.step(action)
        steps += 1
        if terminated or truncated:
            break
    return 1000 * elapsed / steps


def ppo_steps_per_second(env_id: str, timesteps: int) -> float:
    """PPO (SB3 defaults, one environment) training steps per second."""
    from stable_baselines3 import PPO

    env = gym.make(env_id)
    policy = (
        "MultiInputPolicy" if isinstance(env.observation_space, gym.spaces.Dict) else "MlpPolicy"
    )
    from stable_baselines3.common.logger import Logger

    model = PPO(policy, env, n_steps=512, batch_size=64, n_epochs=4, device="cpu", seed=0)
    model.set_logger(Logger(folder=None, output_formats=[]))  # SB3's default makes a temp folder
    start = time.perf_counter()
    model.learn(total_timesteps=timesteps)
    return timesteps / (time.perf_counter() - start)


def planner_seconds(
    target: str, repeats: int, clock: Callable[[], float] = time.perf_counter
) -> float:
    """Median time of a planner call ``module:function`` (wall time; ``clock=time.process_time``:
    this process's CPU time, which other load on a shared machine does not inflate)."""
    module, function = target.split(":")
    plan: Callable[[], Any] = getattr(importlib.import_module(module), function)
    times = []
    for _ in range(repeats):
        start = clock()
        plan()
        times.append(clock() - start)
    return float(np.median(times))


def memory_growth(env_id: str, steps: int) -> dict[str, float]:
    """Resident memory of ``env_id`` over ``steps`` random steps, in a fresh process.

    See :mod:`motiongym.agents.bench.memory_probe`; adds ``growth_mib``, the change
    between the first tenth of the run and its end.
    """
    result = subprocess.run(
        [sys.executable, "-m", "motiongym.agents.bench.memory_probe", env_id, str(steps)],
        capture_output=True,
        text=True,
        check=True,
    )
    probe = json.loads(result.stdout.strip().splitlines()[-1])
    probe["growth_mib"] = probe["rss_end_mib"] - probe["rss_early_mib"]
    probe["steps"] = steps
    return probe


def _verdict(value: float, goal: float | None, higher_is_better: bool = True) -> str:
    if goal is None:
        return ""
    met = value >= goal if higher_is_better else value <= goal
    return "met" if met else "MISSED"


def bench(out_dir: Path, quick: bool = False, env_ids: list[str] | None = None) -> dict:
    """Measure everything; print the tables; write ``bench.json`` and ``bench.md``."""
    seconds = 0.5 if quick else 3.0
    env_ids = list(env_ids or ENV_IDS)
    for env_id in env_ids:  # every ID checked before any work
        check_env_id(env_id)
    results: dict[str, Any] = {"machine": machine(), "quick": quick, "references": {}}
    references = {reference: gym.make(reference) for reference in REFERENCES}
    results["references"].update(interleaved_steps_per_second(references, seconds))
    ppo_steps = 1024 if quick else 8192
    results["references"]["PPO Reacher-v5"] = ppo_steps_per_second("Reacher-v5", ppo_steps)

    rows = []
    for env_id in env_ids:
        env = make_env(env_id)
        rates = interleaved_steps_per_second({env_id: env, **references}, seconds)
        dt = getattr(env.unwrapped, "dt", None)  # s, the control period; None: a grid world
        row: dict[str, Any] = {"id": env_id, "steps_per_s": rates[env_id]}
        for reference in REFERENCES:
            row[f"x {reference}"] = rates[env_id] / rates[reference]
        if env_id in GOALS:
            goal_reference, goal = GOALS[env_id]
            row["goal"] = f">= {goal}x {goal_reference}"
            row["goal_met"] = _verdict(row[f"x {goal_reference}"], goal)
        row["policy_ms_per_step"] = {
            name: policy_ms_per_step(env_id, name, 200 if quick else 2000)
            for name in scripted_policies(env_id)
        }
        row["control_period_ms"] = None if dt is None else 1000.0 * dt
        row["ppo_steps_per_s"] = ppo_steps_per_second(env_id, ppo_steps)
        row["x PPO Reacher-v5"] = row["ppo_steps_per_s"] / results["references"]["PPO Reacher-v5"]
        if gym.spec(env_id).vector_entry_point:
            row["vector"] = _vector_row(env_id, seconds, quick)
        row["memory"] = memory_growth(env_id, 20_000 if quick else 1_000_000)
        rows.append(row)
    results["environments"] = rows
    results["planners"] = {
        label: {
            "seconds": (s := planner_seconds(target, 3 if quick else 10)),
            "cpu_seconds": planner_seconds(target, 3 if quick else 10, time.process_time),
            "goal_s": goal,
            "goal_met": _verdict(s, goal, higher_is_better=False),
        }
        for label, (target, goal) in PLANNERS.items()
    }
    console.print(Markdown(markdown(results)))
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "bench.json").write_text(json.dumps(results, indent=2))
    (out_dir / "bench.md").write_text(markdown(results))
    console.print(f"wrote {out_dir / 'bench.json'} and {out_dir / 'bench.md'}")
    return results


def _vector_row(env_id: str, seconds: float, quick: bool) -> dict[str, Any]:
    num_envs = 1024 if quick else 4096
    native = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point")
    sync = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="sync")
    row: dict[str, Any] = {
        "num_envs": num_envs,
        "native_steps_per_s": vector_steps_per_second(native, seconds),
        "sync_steps_per_s": vector_steps_per_second(sync, seconds),
    }
    row["x sync"] = row["native_steps_per_s"] / row["sync_steps_per_s"]
    if env_id in VECTOR_GOALS:
        least_rate, least_ratio = VECTOR_GOALS[env_id]
        row["goal"] = f">= {least_rate:.0f} steps/s and >= {least_ratio}x sync"
        met = row["native_steps_per_s"] >= least_rate and row["x sync"] >= least_ratio
        row["goal_met"] = "met" if met else "MISSED"
    return row


def _period(ms: float | None) -> str:
    """The control period as printed (a grid world has none)."""
    return "-" if ms is None else f"{ms:.0f}"


def markdown(results: dict[str, Any]) -> str:
    """The environment table as Markdown (docs/throughput.md holds the latest)."""
    refs = results["references"]
    lines = [
        f"Measured on: {results['machine']}. References (timed in turns with each ID; "
        "here the first measurement): "
        + ", ".join(f"{name} {rate:,.0f} steps/s" for name, rate in refs.items())
        + ".",
        "",
        "| ID | steps/s | x CartPole | x Reacher | x MiniGrid | PPO steps/s (x Reacher PPO) "
        "| goal | env MiB (peak) / growth over run |",
        "|---|---:|---:|---:|---:|---:|---|---|",
    ]
    for row in results["environments"]:
        memory = row["memory"]
        goal = f"{row.get('goal', '')} {row.get('goal_met', '')}".strip()
        lines.append(
            f"| {row['id']} | {row['steps_per_s']:,.0f} | {row['x CartPole-v1']:.2f} "
            f"| {row['x Reacher-v5']:.2f} | {row['x MiniGrid-Empty-16x16-v0']:.2f} "
            f"| {row['ppo_steps_per_s']:,.0f} ({row['x PPO Reacher-v5']:.2f}) | {goal} "
            f"| {memory['env_mib']:.1f} ({memory['env_peak_mib']:.1f}) / "
            f"{memory['growth_mib']:+.1f} over "
            f"{memory['steps']:,} steps |"
        )
    for row in results["environments"]:
        if "vector" in row:
            vector = row["vector"]
            lines.append("")
            lines.append(
                f"Vectorised {row['id']} ({vector['num_envs']} envs): "
                f"{vector['native_steps_per_s']:,.0f} steps/s, "
                f"{vector['x sync']:.0f}x SyncVectorEnv {vector.get('goal_met', '')}"
            )
    if results["planners"]:
        lines += ["", "| planner | seconds | CPU seconds | goal |", "|---|---:|---:|---|"]
        for label, planner in results["planners"].items():
            goal = f"<= {planner['goal_s']} s {planner['goal_met']}" if planner["goal_s"] else ""
            cpu = planner["cpu_seconds"]
            lines.append(f"| {label} | {planner['seconds']:.4f} | {cpu:.4f} | {goal} |")
    policy_rows = [
        f"| {row['id']} | {name} | {ms:.3f} | {_period(row.get('control_period_ms'))} |"
        for row in results["environments"]
        for name, ms in row["policy_ms_per_step"].items()
    ]
    if policy_rows:
        header = "| ID | scripted policy | ms per step | control period (ms) |"
        lines += ["", header, "|---|---|---:|---:|", *policy_rows]
    return "\n".join(lines) + "\n"
