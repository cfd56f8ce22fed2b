"""A fifth world, the way docs/adding_a_world.md builds one: a point walks along a line.

One module stands in for the three a real system has (its environments,
its baselines and its reproduction modules); test_adding_a_world.py adds it
with one call to :func:`motiongym.systems.add_system`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.baselines.policy import ScriptedPolicy
from motiongym.envs import core

# ---------------------------------------------------------------- environments module
REGISTRATIONS = (
    {"id": "motiongym/ToyLine-v0", "entry_point": "toy_world:ToyLineEnv", "max_episode_steps": 50},
)
BENCH_GOALS = {"motiongym/ToyLine-v0": ("CartPole-v1", 0.01)}

LAYOUT = core.ObservationLayout(
    [("position", 1, "m", "the point"), ("goal", 1, "m", "where it must go")]
)


@dataclass(frozen=True)
class ToyParams:
    length: float = 10.0  # m
    time: float = 0.1  # weight of the time term

    def __post_init__(self) -> None:
        core.check_float("length", self.length, 1.0, 100.0)
        core.check_float("time", self.time, 0.0, 10.0)


class ToyLineEnv(core.NeedsReset, gym.Env):
    """Walk a point to a goal on a line. Action Discrete(2): 0 left, 1 right."""

    metadata = {"render_modes": [], "info_measures": {"is_success": "last", "cost": "sum"}}

    def __init__(self, render_mode: str | None = None, **kwargs: Any) -> None:
        self.render_mode = core.check_render_mode(render_mode, self.metadata["render_modes"])
        self.params = core.params_from_kwargs(ToyParams, kwargs)
        low, high = LAYOUT.bounds(
            {"position": (0, self.params.length), "goal": (0, self.params.length)}
        )
        self.observation_space = spaces.Box(low, high)
        self.action_space = spaces.Discrete(2)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        core.check_options(options, {})
        self.position, self.goal = self.np_random.integers(0, int(self.params.length), 2)
        self._was_reset = True
        _, info = core.reward_and_info(core.zero_terms(["time"]), cost=0.0, is_success=False)
        return self._observation(), info

    def step(self, action: Any):
        self._require_reset("step")
        if not self.action_space.contains(action):
            raise ValueError(f"action must be in {self.action_space}, got {action!r}")
        self.position = int(
            np.clip(self.position + (1 if action == 1 else -1), 0, self.params.length)
        )
        done = self.position == self.goal
        reward, info = core.reward_and_info({"time": -self.params.time}, cost=0.0, is_success=done)
        return self._observation(), reward, done, False, info

    def _observation(self) -> np.ndarray:
        return LAYOUT.pack({"position": self.position, "goal": self.goal})


# ---------------------------------------------------------------- baselines module
POLICIES = {"motiongym/ToyLine-v0": {"walk-to-goal": "toy_world:WalkPolicy"}}
PLANNERS: dict[str, tuple[str, float | None]] = {}


class WalkPolicy(ScriptedPolicy):
    """Step towards the goal."""

    def new_memory(self) -> None:
        return None

    def act(self, observation: Any, memory: Any) -> int:
        parts = LAYOUT.parse(observation)
        return int(parts["goal"][0] > parts["position"][0])


# ---------------------------------------------------------------- reproduction module
def run(out_dir: Path, quick: bool = False) -> dict:
    from motiongym.agents.evaluate import run_episode
    from motiongym.baselines import make_policy

    env = gym.make("motiongym/ToyLine-v0")
    policy = make_policy(
        "motiongym/ToyLine-v0", "walk-to-goal", env.observation_space, env.action_space
    )
    episodes = [run_episode(env, policy, seed) for seed in range(3 if quick else 20)]
    return {"success": float(np.mean([e["is_success"] for e in episodes]))}
