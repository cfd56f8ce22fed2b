"""PSA + CWA on Sweeper-v1's generated map families (a script, not a test; issue 33).

For each family of :mod:`motiongym.envs.sweeper.families` and each map seed given,
one episode of ``psa-cwa`` (:class:`~motiongym.baselines.sweeper.psa_cwa.PsaCwaPolicy`,
told the environment's keywords) on ``motiongym/Sweeper-v1`` with ``map_family``,
``map_seed`` (the default 40 x 60 map, robot width 3) and ``reset(seed=map seed)``,
at a noise level: ``none`` (no odometry noise: no localiser) or ``noisy`` (heading
0.01 rad per action + slip 0.05: the localiser at work). The coverage recorded is the
coverage at the step the policy declares itself done (the per-step hook of the one
episode loop reads ``diagnostics()["done"]``); a run the policy never declares done ends
on full coverage, at the 20,000-step limit, or at ``--budget`` seconds of wall clock
(then ``cut`` is true and its coverage is the coverage when cut).

The development and evaluation map seeds are fixed in ``docs/experiments/Sweeper-v1.md``
(development 0-99, evaluation 100000-100099): tune only on the first.

    nice -n 10 .venv/bin/python tests/sweeper_families_heldout.py noisy 100000 100001 out.jsonl

appends one JSON row per run to ``out.jsonl`` (families in order; ``--family NAME``
to run one) and prints a summary per family at the end.
"""

from __future__ import annotations

import argparse
import json
import time
from collections import defaultdict
from typing import Any

import gymnasium as gym

import motiongym  # noqa: F401
from motiongym.agents.evaluation.episodes import run_episode
from motiongym.baselines.sweeper.psa_cwa import PsaCwaPolicy
from motiongym.envs.sweeper.families import FAMILIES

ENV_ID = "motiongym/Sweeper-v1"
NOISE = {"none": {}, "noisy": {"heading_noise": 0.01, "slip_noise": 0.05}}


def run(family: str, map_seed: int, noise: str, budget_s: float = 150.0) -> dict[str, Any]:
    """One episode; the coverage at "done" (or at the end, or when the budget ran out)."""
    kwargs: dict[str, Any] = {"map_family": family, "map_seed": map_seed, **NOISE[noise]}
    env = gym.make(ENV_ID, **kwargs)
    policy = PsaCwaPolicy(
        env.observation_space, env.action_space, {**gym.spec(ENV_ID).kwargs, **kwargs}
    )
    seen: dict[str, Any] = {"done": False, "cut": False}
    start = time.perf_counter()

    def hook(step) -> bool:
        seen.update(coverage=step.info["coverage"], steps=step.index + 1, bumps=step.info["bumps"])
        seen["done"] = bool(policy.diagnostics()["done"])
        seen["cut"] = not seen["done"] and time.perf_counter() - start > budget_s
        return seen["done"] or seen["cut"]

    try:
        run_episode(env, policy, map_seed, hook=hook)
    finally:
        env.close()
    return {
        "family": family,
        "map_seed": map_seed,
        "noise": noise,
        "coverage": float(seen["coverage"]),
        "declared_done": seen["done"],
        "cut": seen["cut"],
        "steps": int(seen["steps"]),
        "bumps": int(seen["bumps"]),
        "seconds": round(time.perf_counter() - start, 1),
    }


def summary(rows: list[dict[str, Any]]) -> str:
    """Per (noise, family): runs, coverage mean and min (%), seconds mean and max."""
    groups: dict[tuple[str, str], list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        groups[row["noise"], row["family"]].append(row)
    lines = ["| noise | family | runs | coverage mean | min | cut | s mean | s max |"]
    for (noise, family), runs in sorted(groups.items()):
        cov = [100 * r["coverage"] for r in runs]
        sec = [r["seconds"] for r in runs]
        cut = sum(r["cut"] for r in runs)
        lines.append(
            f"| {noise} | {family} | {len(runs)} | {sum(cov) / len(cov):.1f} % | {min(cov):.1f} % "
            f"| {cut} | {sum(sec) / len(sec):.1f} | {max(sec):.1f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("noise", choices=sorted(NOISE))
    parser.add_argument("first", type=int, help="first map seed")
    parser.add_argument("last", type=int, help="last map seed (inclusive)")
    parser.add_argument("out", help="JSON lines file (appended)")
    parser.add_argument("--family", choices=FAMILIES, action="append")
    parser.add_argument("--budget", type=float, default=150.0, help="seconds per run")
    args = parser.parse_args(argv)
    rows = []
    for family in args.family or FAMILIES:
        for seed in range(args.first, args.last + 1):
            row = run(family, seed, args.noise, args.budget)
            rows.append(row)
            print(json.dumps(row), flush=True)
            with open(args.out, "a") as f:
                f.write(json.dumps(row) + "\n")
    print(summary(rows))


if __name__ == "__main__":
    main()
