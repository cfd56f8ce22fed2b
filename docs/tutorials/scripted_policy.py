"""Write your own scripted policy and evaluate it with motiongym's harness.

A scripted policy is anything with Stable-Baselines3's predictor interface,
``predict(observation, state, episode_start, deterministic) -> (action,
state)``: motiongym's evaluation, ``compare`` and SB3's own
``evaluate_policy`` run it exactly as they run a trained model. Subclassing
:class:`motiongym.baselines.ScriptedPolicy` gives ``predict`` (batched or
single observations, a fresh memory at every episode start); a policy writes
two methods, ``new_memory`` and ``act``.

The example: in the dual-arm cell (``DualArmCell-v1``, two arms on fixed
paths, collision avoided by timing), robot 2 waits a fixed number of steps
and then runs, robot 1 runs at once. The paper's ``boundary-following``
computes the smallest safe delay for each pair of tasks; a fixed delay is
either too short (a collision) or longer than needed (a longer makespan). The evaluation shows
both, on the same seeded episodes, with ``undelayed`` (no delay) and
``sequential`` (robot 2 waits until robot 1 is done) for reference.

Run: ``python docs/tutorials/scripted_policy.py --episodes 20``
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Any

import numpy as np

from motiongym.agents.environments import make_env
from motiongym.agents.evaluation.episodes import EVALUATION_SEED, evaluate
from motiongym.agents.evaluation.report import comparison_table, console
from motiongym.agents.models.predictors import load_predictor
from motiongym.baselines import ScriptedPolicy

ENV_ID = "motiongym/DualArmCell-v1"


@dataclass
class Clock:
    """The policy's memory within an episode: steps taken so far."""

    steps: int = 0


class FixedDelayPolicy(ScriptedPolicy):
    """Robot 1 advances at full speed; robot 2 waits ``delay`` steps, then does too.

    Action (control="both"): ``[robot 1's advance, robot 2's advance]``, each in [0, 1].
    """

    def __init__(self, observation_space, action_space, delay: int = 100) -> None:
        super().__init__(observation_space, action_space)
        if delay < 0:
            raise ValueError(f"delay must be a number of steps >= 0, got {delay}")
        self.delay = delay

    def new_memory(self) -> Clock:
        return Clock()

    def act(self, observation: np.ndarray, memory: Clock) -> np.ndarray:
        robot_2 = 1.0 if memory.steps >= self.delay else 0.0
        memory.steps += 1
        return np.array([1.0, robot_2], dtype=np.float32)

    def describe(self, memory: Clock) -> dict[str, Any]:
        return {"steps": memory.steps, "delay": self.delay}


def main(episodes: int) -> list:
    env = make_env(ENV_ID)
    seeds = range(EVALUATION_SEED, EVALUATION_SEED + episodes)
    evaluations = []
    for delay in (50, 150):  # steps of 0.02 s: 1 s and 3 s
        policy = FixedDelayPolicy(env.observation_space, env.action_space, delay)
        label = f"fixed delay {delay}"
        evaluations.append(evaluate(env, policy, seeds, ENV_ID, label, progress=False))
    for name in ("boundary-following", "undelayed", "sequential"):
        predictor = load_predictor(name, ENV_ID, env)
        evaluations.append(evaluate(env, predictor, seeds, ENV_ID, name, progress=False))
    env.close()
    console.print(comparison_table(evaluations))
    return evaluations


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=20, help="default: %(default)s")
    main(parser.parse_args().episodes)
