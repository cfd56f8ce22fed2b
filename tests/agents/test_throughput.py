"""The benchmark's measurements run and its report is complete (no timing asserted)."""

from __future__ import annotations

import json

import gymnasium as gym
import pytest

from motiongym.agents.bench.throughput import (
    PLANNERS,
    bench,
    markdown,
    memory_growth,
    planner_seconds,
    steps_per_second,
)


def test_memory_probe_reports_the_environment_and_its_growth():
    probe = memory_growth("motiongym/Sweeper-v0", 2_000)
    assert probe["steps"] == 2_000
    assert probe["env_mib"] > 0 and probe["env_peak_mib"] >= probe["env_mib"] - 1.0
    assert abs(probe["growth_mib"]) < 50


def test_throughput_and_planner_timings_are_positive():
    assert steps_per_second(gym.make("CartPole-v1"), seconds=0.05) > 0
    for target, _ in PLANNERS.values():
        assert planner_seconds(target, repeats=1) > 0


@pytest.mark.slow
def test_quick_bench_of_one_id_writes_json_and_markdown(tmp_path):
    results = bench(tmp_path, quick=True, env_ids=["motiongym/Sweeper-v0"])
    (row,) = results["environments"]
    assert row["goal"].startswith(">= 0.3x CartPole")
    assert "vector" in row and row["vector"]["native_steps_per_s"] > 0
    assert json.loads((tmp_path / "bench.json").read_text())["machine"]
    assert "motiongym/Sweeper-v0" in (tmp_path / "bench.md").read_text()


def test_policy_table_prints_the_control_period_beside_the_time_per_step():
    memory = {"env_mib": 1.0, "env_peak_mib": 1.0, "growth_mib": 0.0, "steps": 10}
    rates = {"x CartPole-v1": 1.0, "x Reacher-v5": 1.0, "x MiniGrid-Empty-16x16-v0": 1.0}
    rows = [
        {
            "id": "arm",
            "steps_per_s": 1.0,
            **rates,
            "ppo_steps_per_s": 1.0,
            "x PPO Reacher-v5": 1.0,
            "memory": memory,
            "policy_ms_per_step": {"pf": 0.4},
            "control_period_ms": 50.0,
        },
        {
            "id": "grid",
            "steps_per_s": 1.0,
            **rates,
            "ppo_steps_per_s": 1.0,
            "x PPO Reacher-v5": 1.0,
            "memory": memory,
            "policy_ms_per_step": {"psa": 0.1},
            "control_period_ms": None,
        },
    ]
    results = {
        "machine": "m",
        "references": {"CartPole-v1": 1.0},
        "environments": rows,
        "planners": {},
    }
    text = markdown(results)
    assert "| arm | pf | 0.400 | 50 |" in text
    assert "| grid | psa | 0.100 | - |" in text
