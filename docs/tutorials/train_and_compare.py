"""Train an agent and compare it with the paper's policy.

The same steps as ``motiongym train`` then ``motiongym compare``, from Python:
train PPO on ``HarvestArmPlanar-v0`` with the settings of
``configs/HarvestArmPlanar-v0.yml`` (a run folder under ``runs/``), load the
run as a predictor, and evaluate it beside the scripted ``potential-field``
policy (the paper's method) and ``random`` on the same seeded episodes.

The configuration trains 500,000 steps (about an hour on two cores); the
default budget here is 20,000 steps (a few minutes), which learns little:
the point is the sequence. ``--timesteps 1`` runs it in seconds (one PPO
rollout), as the test suite does.

Run: ``python docs/tutorials/train_and_compare.py --timesteps 20000 --episodes 10``
"""

from __future__ import annotations

import argparse
from pathlib import Path

from motiongym.agents.environments import make_env
from motiongym.agents.evaluation.episodes import EVALUATION_SEED, evaluate
from motiongym.agents.evaluation.report import comparison_table, console, write_comparison
from motiongym.agents.models.predictors import load_predictor, policy_label
from motiongym.agents.training.train import train

ENV_ID = "motiongym/HarvestArmPlanar-v0"


def main(timesteps: int, episodes: int, out: Path) -> list:
    # 1. Train: the file's first block (PPO), a run folder with model.zip,
    #    the observation normalisation (vecnormalize.npz) and a manifest.
    run_dir = train(ENV_ID, "ppo", seed=0, out_root=out / "runs", n_timesteps=timesteps,
                    progress=False)  # fmt: skip
    console.print(f"run folder: {run_dir}")

    # 2. Compare: every predictor on the same held-out episodes (seeds from
    #    EVALUATION_SEED, far from the training seeds).
    env = make_env(ENV_ID)
    seeds = range(EVALUATION_SEED, EVALUATION_SEED + episodes)
    evaluations = []
    for policy in (str(run_dir), "potential-field", "random"):
        predictor = load_predictor(policy, ENV_ID, env)
        evaluations.append(evaluate(env, predictor, seeds, ENV_ID, policy_label(policy), False))
    env.close()

    # 3. Report: the table (mean ± 95 % interval per measure), then the files
    #    (JSON, CSV, Markdown and the figure) that `motiongym compare` writes.
    console.print(comparison_table(evaluations))
    for path in write_comparison(evaluations, out / "compare", "HarvestArmPlanar-v0"):
        console.print(f"wrote {path}")
    return evaluations


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=20_000, help="default: %(default)s")
    parser.add_argument("--episodes", type=int, default=10, help="default: %(default)s")
    parser.add_argument("--out", type=Path, default=Path("results/tutorial"),
                        help="default: %(default)s")  # fmt: skip
    args = parser.parse_args()
    main(args.timesteps, args.episodes, args.out)
