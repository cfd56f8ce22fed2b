"""Running a predictor on seeded episodes and summarising what ``info`` reports.

Episode ``i`` of an evaluation is reset with ``seed + i``: every policy run
with the same ``seed`` and ``n_episodes`` faces the same scenarios. Torch's
random generator is seeded with the same number for the episode (and
restored after it), so a model that samples its actions (a run with
``deterministic: false``) acts the same on the same episode in every
evaluation, whatever ran before.

What is measured: the episode's return and length, and every key of the
environment's ``metadata["info_measures"]`` (``{key: how}``, how being
``last``, ``sum``, ``mean``, ``min`` or ``max`` over the episode's steps; the
reset's ``info`` is not a step and is not counted). An environment that
declares none reports its return and length only. Its
``metadata["info_units"]`` (``{key: unit}``) labels the figures; a unit of
``rate`` or ``fraction`` marks a measure that lies in [0, 1], whose interval
lies there too (:mod:`motiongym.agents.evaluation.statistics`).
"""

from __future__ import annotations

import csv
import json
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from tqdm.auto import tqdm

from motiongym.agents.errors import UsageError
from motiongym.agents.evaluation.statistics import interval, t_half_width

# First seed of evaluations: far from the small seeds training runs use.
EVALUATION_SEED = 100_000

AGGREGATIONS: dict[str, Callable[[np.ndarray], float]] = {
    "last": lambda values: float(values[-1]),
    "sum": lambda values: float(np.sum(values)),
    "mean": lambda values: float(np.mean(values)),
    "min": lambda values: float(np.min(values)),
    "max": lambda values: float(np.max(values)),
}


def info_measures(env: gym.Env) -> dict[str, str]:
    """The environment's declared ``{info key: aggregation}``, validated."""
    measures = dict(env.unwrapped.metadata.get("info_measures", {}))
    for key, how in measures.items():
        if how not in AGGREGATIONS:
            raise ValueError(
                f"info measure {key!r} aggregates by {how!r}; valid: {', '.join(AGGREGATIONS)}"
            )
    return measures


# Units of the two measures every evaluation has.
BASE_UNITS = {"return": "reward", "length": "steps"}


def info_units(env: gym.Env) -> dict[str, str]:
    """``{measure: unit}`` for the return, the length and the environment's declared
    ``metadata["info_units"]`` (a measure without a unit is left out)."""
    return {**BASE_UNITS, **env.unwrapped.metadata.get("info_units", {})}


@dataclass
class Step:
    """What a per-step hook sees: the step's index (0-based), the predictor that
    acted, the observation it acted on, its action and what ``env.step`` returned."""

    index: int
    predictor: Any
    observation: Any
    action: Any
    next_observation: Any
    reward: float
    terminated: bool
    truncated: bool
    info: dict[str, Any]


StepHook = Callable[[Step], bool | None]
ResetHook = Callable[[Any, dict[str, Any]], None]


def run_episode(
    env: gym.Env,
    predictor: Any,
    seed: int,
    hook: StepHook | None = None,
    options: dict[str, Any] | None = None,
    on_reset: ResetHook | None = None,
    seed_torch: bool = True,
) -> dict[str, float]:
    """One episode from ``reset(seed=seed, options=options)``; its return, length
    and measures.

    The one episode loop of motiongym: ``evaluate``, ``compare``,
    ``benchmarks``, ``record``, datasets, DAgger and every reproduction run
    their episodes through it. ``hook``, if given, is called after every step
    with a :class:`Step`; a caller collects what it needs there (a policy's
    public ``diagnostics()``, a world's measure, a dataset's transitions)
    instead of writing its own loop. A hook that returns True ends the episode
    after that step (a reproduction that has what it came for, such as the
    step at which a policy declared itself done); the measures then cover the
    steps run. ``on_reset``, if given, is called with the reset's observation
    and ``info`` before the first step.

    The predictor is asked with ``episode_start`` true on the first step and
    false after, ``deterministic=True``, and its ``state`` passed back.
    Torch's generator is seeded with ``seed`` for the episode and restored
    after it (see the module); ``seed_torch=False`` leaves it alone (DAgger,
    whose learner samples from the generator as it runs on).
    """
    measures = info_measures(env)
    observation, reset_info = env.reset(seed=seed, options=options)
    if on_reset is not None:
        on_reset(observation, reset_info)
    state, episode_start = None, np.ones(1, dtype=bool)
    trace: dict[str, list[float]] = {key: [] for key in measures}
    episode_return, length, done = 0.0, 0, False
    with torch.random.fork_rng(devices=[], enabled=seed_torch):
        if seed_torch:
            torch.manual_seed(seed)
        while not done:
            action, state = predictor.predict(
                observation, state=state, episode_start=episode_start, deterministic=True
            )
            previous = observation
            observation, reward, terminated, truncated, info = env.step(action)
            stop: bool | None = False
            if hook is not None:
                stop = hook(
                    Step(
                        length,
                        predictor,
                        previous,
                        action,
                        observation,
                        float(reward),
                        bool(terminated),
                        bool(truncated),
                        info,
                    )
                )
            episode_start = np.zeros(1, dtype=bool)
            episode_return += float(reward)
            length += 1
            done = terminated or truncated or bool(stop)
            for key in measures:
                trace[key].append(float(info[key]))
    result = {"seed": seed, "return": episode_return, "length": length}
    for key, how in measures.items():
        result[key] = AGGREGATIONS[how](np.asarray(trace[key]))
    return result


@dataclass
class Evaluation:
    """The episodes of one policy on one environment ID."""

    env_id: str
    policy: str
    episodes: list[dict[str, float]] = field(default_factory=list)
    units: dict[str, str] = field(default_factory=lambda: dict(BASE_UNITS))

    @property
    def measures(self) -> list[str]:
        return [key for key in self.episodes[0] if key != "seed"] if self.episodes else []

    def summary(self) -> dict[str, dict[str, float]]:
        """Per measure: mean, standard deviation, ``ci95`` (the half-width of Student's t
        interval of the mean), ``low`` and ``high`` (its 95 % interval: Wilson's for a
        rate of 0/1 outcomes, inside [0, 1] for any rate or fraction, else the t
        interval; :mod:`motiongym.agents.evaluation.statistics`), min and max.
        """
        table = {}
        for key in self.measures:
            values = np.array([episode[key] for episode in self.episodes])
            low, high = interval(values, self.units.get(key, ""))
            table[key] = {
                "mean": float(values.mean()),
                "std": float(values.std()),
                "ci95": t_half_width(values),
                "low": low,
                "high": high,
                "min": float(values.min()),
                "max": float(values.max()),
            }
        return table

    def to_json(self) -> dict[str, Any]:
        return {
            "env_id": self.env_id,
            "policy": self.policy,
            "seeds": [episode["seed"] for episode in self.episodes],
            "summary": self.summary(),
            "units": self.units,
            "episodes": self.episodes,
        }

    def write(self, out_dir: Path, stem: str) -> list[Path]:
        """Write ``stem.json`` (summary and episodes) and ``stem.csv`` (episodes)."""
        out_dir.mkdir(parents=True, exist_ok=True)
        json_path, csv_path = out_dir / f"{stem}.json", out_dir / f"{stem}.csv"
        json_path.write_text(json.dumps(self.to_json(), indent=2))
        with csv_path.open("w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(self.episodes[0]))
            writer.writeheader()
            writer.writerows(self.episodes)
        return [json_path, csv_path]


def evaluate(
    env: gym.Env,
    predictor: Any,
    seeds: Iterable[int],
    env_id: str,
    policy: str,
    progress: bool = True,
) -> Evaluation:
    """Run ``predictor`` once from each seed; the episodes as an :class:`Evaluation`."""
    seeds = list(seeds)
    if not seeds:
        raise UsageError("at least one episode is needed")
    evaluation = Evaluation(env_id, policy, units=info_units(env))
    for seed in tqdm(seeds, desc=f"{policy} on {env_id}", disable=not progress, leave=False):
        evaluation.episodes.append(run_episode(env, predictor, seed))
    return evaluation
