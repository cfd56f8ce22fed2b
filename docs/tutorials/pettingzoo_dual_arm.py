"""Use the dual-arm cell as a PettingZoo multi-agent environment.

``motiongym.envs.dual_arm.parallel_env()`` is a PettingZoo ``ParallelEnv``
over the same world as ``DualArmCell-v0``: agents ``robot_1`` and
``robot_2``, each choosing its own arm's advance (Box(0, 1, (1,))), both
seeing the full observation and sharing the reward. This tutorial

1. checks it with PettingZoo's own API test;
2. runs an episode in the usual PettingZoo loop, each agent acting from its
   own observation: robot 1 advances, robot 2 follows the schedule of the
   paper's ``boundary-following`` policy (the scripted policy plans the
   joint action from the observation both agents see; robot 2 takes its
   part);
3. trains one policy shared by both agents (SB3 PPO on the PettingZoo env,
   ``vec_env: pettingzoo`` in ``configs/DualArmCell-v0-shared.yml``) and
   evaluates it in the single-agent ID, as ``motiongym train`` and
   ``motiongym evaluate`` do.

The configuration trains 1,000,000 steps; the default budget here is
10,000; ``--timesteps 1`` (one rollout) runs in seconds, as the test suite
does.

Run: ``python docs/tutorials/pettingzoo_dual_arm.py --timesteps 10000``
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

from pettingzoo.test import parallel_api_test

from motiongym.agents.environments import make_env
from motiongym.agents.evaluation.episodes import EVALUATION_SEED, evaluate
from motiongym.agents.evaluation.report import comparison_table, console
from motiongym.agents.models.predictors import load_predictor, policy_label
from motiongym.agents.training.train import train
from motiongym.envs.dual_arm import parallel_env

ENV_ID = "motiongym/DualArmCell-v0"
SHARED_CONFIG = Path(str(resources.files("motiongym.configs") / "DualArmCell-v0-shared.yml"))


def one_episode(seed: int) -> dict[str, float]:
    """One episode of the parallel env in PettingZoo's loop; the agents' returns."""
    single = make_env(ENV_ID)  # the single-agent ID: the joint action's space
    planner = load_predictor("boundary-following", ENV_ID, single)
    single.close()
    env = parallel_env()
    observations, infos = env.reset(seed=seed)
    returns = dict.fromkeys(env.agents, 0.0)
    while env.agents:
        joint, _ = planner.predict(observations["robot_2"])  # [robot 1, robot 2]
        actions = {"robot_1": joint[:1], "robot_2": joint[1:]}
        observations, rewards, terminations, truncations, infos = env.step(actions)
        for agent, reward in rewards.items():
            returns[agent] += reward
    console.print(f"seed {seed}: success {infos['robot_1']['is_success']}, returns {returns}")
    env.close()
    return returns


def main(timesteps: int, episodes: int, out: Path) -> list:
    parallel_api_test(parallel_env(), num_cycles=100)
    one_episode(EVALUATION_SEED)

    run_dir = train(ENV_ID, "ppo", config_path=SHARED_CONFIG, out_root=out,
                    n_timesteps=timesteps, progress=False)  # fmt: skip
    env = make_env(ENV_ID)
    seeds = range(EVALUATION_SEED, EVALUATION_SEED + episodes)
    evaluations = []
    for policy in (str(run_dir), "boundary-following"):
        predictor = load_predictor(policy, ENV_ID, env)
        evaluations.append(evaluate(env, predictor, seeds, ENV_ID, policy_label(policy), False))
    env.close()
    console.print(comparison_table(evaluations))
    return evaluations


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timesteps", type=int, default=10_000, help="default: %(default)s")
    parser.add_argument("--episodes", type=int, default=10, help="default: %(default)s")
    parser.add_argument("--out", type=Path, default=Path("runs/tutorial"),
                        help="default: %(default)s")  # fmt: skip
    args = parser.parse_args()
    main(args.timesteps, args.episodes, args.out)
