"""Resident memory of one environment over a long random run (``motiongym bench``).

Run as ``python -m motiongym.agents.bench.memory_probe ID STEPS`` in a fresh
process: it imports only Gymnasium and motiongym's worlds (no torch), reads
the resident set size (RSS) before and after making the environment, after
the first tenth of the steps and at the end, sampling it every 1 % of the
run for the peak, and prints one JSON line (MiB):

* ``env_mib``: RSS added by making and resetting the environment;
* ``env_peak_mib``: the largest RSS seen during the run, less the RSS before
  the environment was made;
* ``rss_early_mib`` / ``rss_end_mib``: RSS after a tenth of the run and at
  its end (their difference is the growth the benchmark reports).
"""

from __future__ import annotations

import json
import resource
import sys
from pathlib import Path

import gymnasium as gym

import motiongym  # noqa: F401  (registers the IDs)


def rss_mib() -> float:
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * resource.getpagesize() / 2**20


def probe(env_id: str, steps: int) -> dict[str, float]:
    before = rss_mib()
    env = gym.make(env_id)
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(1024)]
    made = rss_mib()
    early = peak = made
    sample_every = max(steps // 100, 1)
    for step in range(steps):
        _, _, terminated, truncated, _ = env.step(actions[step % len(actions)])
        if terminated or truncated:
            env.reset()
        if step % sample_every == 0:
            peak = max(peak, rss_mib())
        if step == steps // 10:
            early = rss_mib()
    end = rss_mib()
    return {
        "env_mib": made - before,
        "env_peak_mib": max(peak, end) - before,
        "rss_early_mib": early,
        "rss_end_mib": end,
    }


if __name__ == "__main__":
    print(json.dumps(probe(sys.argv[1], int(sys.argv[2]))))
