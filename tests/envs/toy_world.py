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
    time: float = 0.1  # weight of the time term (a cost: subtracted)
    render_size: tuple[int, int] = (16, 64)  # rows, columns

    def __post_init__(self) -> None:
        core.check_float("length", self.length, 1.0, 100.0)
        core.check_weight("time", self.time)
        object.__setattr__(
            self, "render_size", core.check_render_size("render_size", self.render_size)
        )


@dataclass
class Scene:
    position: int
    goal: int


class ToyWorld:
    """The point on its line: the only code that moves it."""

    def __init__(self, params: ToyParams) -> None:
        self.length = int(params.length)
        self.action_space = spaces.Discrete(2)
        self.scene: Scene | None = None

    def reset(self, scene: Scene, rng: np.random.Generator) -> None:
        self.scene = scene
        self.position = scene.position

    def advance(self, action: int) -> None:
        self.position = min(max(self.position + (1 if action == 1 else -1), 0), self.length)

    def render(self, size: tuple[int, int]) -> np.ndarray:
        frame = np.zeros((*size, 3), np.uint8)
        frame[:, int(self.position / self.length * (size[1] - 1))] = 255
        return frame


class ToyTask:
    """Reach the goal; every step costs ``time``."""

    reward_terms = ("time",)

    def __init__(self, params: ToyParams) -> None:
        self.params = params
        low, high = LAYOUT.bounds({"position": (0, params.length), "goal": (0, params.length)})
        self.observation_space = spaces.Box(low, high)
        self.options = {core.START: lambda name, v: core.check_int(name, v, 0, int(params.length))}

    def sample(self, rng: np.random.Generator, options: dict) -> Scene:
        position, goal = rng.integers(0, int(self.params.length), 2)
        return Scene(int(options.get(core.START, position)), int(goal))

    def begin(self, world: ToyWorld) -> core.Outcome:
        return core.Outcome(core.zero_terms(self.reward_terms), False, 0.0, {}, False)

    def evaluate(self, world: ToyWorld, events: None) -> core.Outcome:
        done = world.position == world.scene.goal
        return core.Outcome({"time": -self.params.time}, done, 0.0, {}, done)

    def observe(self, world: ToyWorld) -> np.ndarray:
        return LAYOUT.pack({"position": world.position, "goal": world.scene.goal})


class ToyLineEnv(core.SystemEnv):
    """Walk a point to a goal on a line. Action Discrete(2): 0 left, 1 right."""

    Params = ToyParams
    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": 10,  # Gymnasium's checker asks every rendering env for its frame rate
        "info_measures": {"is_success": "last", "cost": "sum"},
    }

    def make_world(self, params: ToyParams) -> ToyWorld:
        return ToyWorld(params)

    def make_task(self, params: ToyParams) -> ToyTask:
        return ToyTask(params)


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
    from motiongym.agents.evaluation.episodes import run_episode
    from motiongym.baselines import make_policy

    env = gym.make("motiongym/ToyLine-v0")
    policy = make_policy(
        "motiongym/ToyLine-v0", "walk-to-goal", env.observation_space, env.action_space
    )
    episodes = [run_episode(env, policy, seed) for seed in range(3 if quick else 20)]
    return {"success": float(np.mean([e["is_success"] for e in episodes]))}
