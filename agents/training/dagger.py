"""DAgger: a learner that acts alone, taught by a scripted policy on the states it visits.

Plain behaviour cloning (:func:`motiongym.agents.training.imitation.behaviour_clone`)
fits the teacher's actions on the teacher's own states; the learner's small
errors then lead it to states the teacher never showed, where its errors
compound (Ross, Gordon and Bagnell 2011, "A reduction of imitation learning
and structured prediction to no-regret online learning", AISTATS: the cost
of cloning grows with ``T^2 eps``, DAgger's with ``T eps``). DAgger
(their Algorithm 3.1) iterates:

1. iteration 0: roll out the teacher (their ``beta_1 = 1``), record its
   ``(observation, action)`` pairs, fit the learner on them (= cloning);
2. iteration ``i >= 1``: roll out the *learner* (``beta_i = 0``, the
   setting their experiments use), label every state it visits with the
   teacher's action there, aggregate with every earlier pair, refit.

The teachers here are :mod:`motiongym.baselines` policies, some with a
per-episode memory (the excavator's IK goals and waypoint index, the harvest
arm's planned path and progress on it, the dual-arm schedule). Along a
learner's episode the teacher is queried at *every* step in order, with its
memory reset at the episode's first observation (``episode_start``): its
plan is made from the same first observation as on its own, and its
progress (waypoint index, nearest path point, schedule step) is read from
the learner's states, so each label is "what the teacher does from here,
given the plan it made at the start". The learner never sees the memory:
it acts from the observation alone. Where the environment is a learner-side
memory wrapper (:class:`motiongym.agents.learners.memory.MemoryWrapper`), the
teacher reads the environment's own observation (``raw_observation``) and the
learner the wrapper's.

Episodes of iteration ``i`` are seeded ``seed + i * episodes + j`` (default
:data:`~motiongym.agents.integrations.dataset.DATASET_SEED`, far from the evaluation
seeds). With an observation normalisation (``VecNormalize``), its statistics
are the teacher's states of iteration 0, then frozen, as cloning does.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from sb3_contrib import MaskablePPO
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.vec_env import VecNormalize

from motiongym.agents.evaluation.episodes import Step, run_episode
from motiongym.agents.integrations.dataset import DATASET_SEED, stack_steps
from motiongym.agents.training.imitation import behaviour_clone
from motiongym.envs.core import check_int


@dataclass
class DaggerIteration:
    """One iteration's figures: who acted, on how many states, how well."""

    iteration: int
    actor: str  # "teacher" (iteration 0) or "learner"
    episodes: int
    success: float  # the acting policy's success rate on this iteration's episodes
    label_error: float | None  # mean squared error, learner vs teacher, on the new states,
    # before the refit (discrete actions: the share that differ; None where the teacher acted)
    states: int  # size of the aggregated data set after this iteration
    loss: float  # the last refit epoch's mean loss


class _Labelled:
    """A predictor that acts with ``learner`` (the teacher where None) and asks the
    teacher for its action at every observation (:attr:`label`), its memory reset at
    the episode's first (``episode_start``). The teacher reads the environment's own
    observation where the environment is a memory wrapper (``raw_observation``)."""

    def __init__(self, env: gym.Env, teacher: Any, learner: Any) -> None:
        self.env, self.teacher, self.learner = env, teacher, learner
        self.label = np.zeros(0)

    def predict(
        self, observation: Any, state: Any = None, episode_start: Any = None, deterministic=True
    ) -> tuple[Any, Any]:
        seen = getattr(self.env, "raw_observation", observation)  # a memory wrapper's input
        label, _ = self.teacher.predict(seen, episode_start=episode_start)
        self.label = np.asarray(label, dtype=np.float64)
        return (label if self.learner is None else self.learner(observation)), state


def _rollout(
    env: gym.Env, teacher: Any, learner: Any, seed: int
) -> tuple[list[Any], list[np.ndarray], list[np.ndarray], bool]:
    """One episode acted by ``learner`` (or the teacher where None), labelled by the
    teacher, through the one episode loop
    (:func:`~motiongym.agents.evaluation.episodes.run_episode`; torch's generator left
    as it is, for a learner that samples).

    Returns the observations, the teacher's actions, the learner's actions
    (empty where the teacher acted) and the episode's ``is_success``.
    """
    acting = _Labelled(env, teacher, learner)
    observations: list[Any] = []
    labels: list[np.ndarray] = []
    guesses: list[np.ndarray] = []
    last: dict[str, Any] = {}

    def label(step: Step) -> None:
        observations.append(step.observation)
        labels.append(acting.label)
        if learner is not None:
            guesses.append(np.asarray(step.action, dtype=np.float64))
        last["info"] = step.info

    run_episode(env, acting, seed, hook=label, seed_torch=False)
    return observations, labels, guesses, bool(last["info"].get("is_success", False))


def _learner(
    model: BaseAlgorithm,
    env: gym.Env,
    normalization: VecNormalize | None,
    deterministic: bool = True,
):
    """The model's action for one raw observation: within the box for a Box action
    space; for a discrete one, among the environment's allowed actions where it gives
    masks (MaskablePPO), sampled unless ``deterministic``."""
    space = env.action_space
    if not isinstance(space, gym.spaces.Box | gym.spaces.Discrete):
        raise ValueError(f"env must have a Box or Discrete action space, got {space}")
    if not isinstance(env.observation_space, gym.spaces.Box | gym.spaces.Dict):
        raise ValueError(
            f"env must have a Box or Dict observation space, got "
            f"{type(env.observation_space).__name__}"
        )
    masked = isinstance(model, MaskablePPO)
    unwrapped: Any = env.unwrapped  # action_masks() for a masked learner

    def act(observation: Any) -> np.ndarray:
        if normalization is not None:
            observation = normalization.normalize_obs(observation)
        kwargs = {"action_masks": unwrapped.action_masks()} if masked else {}
        action, _ = model.predict(observation, deterministic=deterministic, **kwargs)
        if isinstance(space, gym.spaces.Discrete):
            return np.asarray(int(action))
        return np.clip(action, space.low, space.high)

    return act


def _label_error(guesses: list[np.ndarray], labels: list[np.ndarray], discrete: bool) -> float:
    """Mean squared error of the learner's actions to the teacher's; for discrete
    actions, the share of states where they differ."""
    guess, label = np.asarray(guesses), np.asarray(labels)
    return float(np.mean(guess != label) if discrete else np.mean((guess - label) ** 2))


def on_policy_error(
    model: BaseAlgorithm,
    env: gym.Env,
    teacher: Any,
    seeds: range,
    normalization: VecNormalize | None = None,
) -> tuple[float, float]:
    """``(mean squared error to the teacher on the learner's own states, success rate)``.

    DAgger's measure (Ross et al.'s expected loss under the learner's state
    distribution): the learner acts on episodes ``seeds``, the teacher labels.
    """
    act = _learner(model, env, normalization)
    errors, successes = [], []
    for seed in seeds:
        _, labels, guesses, success = _rollout(env, teacher, act, seed)
        errors.append(np.mean((np.asarray(guesses) - np.asarray(labels)) ** 2, axis=1))
        successes.append(success)
    return float(np.mean(np.concatenate(errors))), float(np.mean(successes))


def dagger(
    model: BaseAlgorithm,
    env: gym.Env,
    teacher: Any,
    iterations: int = 4,
    episodes: int = 50,
    epochs: int = 20,
    seed: int = DATASET_SEED,
    normalization: VecNormalize | None = None,
    training_seed: int = 0,
    deterministic: bool = True,
) -> list[DaggerIteration]:
    """Teach ``model``'s policy by DAgger; the figures of each iteration (0: cloning).

    Args:
        model: an SB3 model whose policy is fitted (``behaviour_clone``).
        env: a made single environment of the teacher's ID (a Box or Discrete action
            space; Box or Dict observations).
        teacher: a predictor with per-episode memory reset by ``episode_start``
            (a scripted policy).
        iterations: learner-acting iterations after the teacher's (0: plain cloning).
        episodes: episodes rolled out per iteration.
        epochs: cloning epochs per refit, over the whole aggregated set.
        seed: the first episode's seed.
        normalization: observation statistics, set from iteration 0's states, then frozen.
        training_seed: seeds the refits' minibatch order.
        deterministic: the learner acts on its most likely action; False: on samples
            (a run evaluated on sampled actions, ``deterministic: false``).
    """
    check_int("iterations", iterations, 0, 10_000)
    check_int("episodes", episodes, 1, 10**6)
    learner = _learner(model, env, normalization, deterministic)
    discrete = isinstance(env.action_space, gym.spaces.Discrete)
    normalize = normalization.normalize_obs if normalization is not None else (lambda o: o)

    observations: list[Any] = []
    labels: list[np.ndarray] = []
    history = []
    for iteration in range(iterations + 1):
        acting = learner if iteration else None
        new_obs, new_labels, guesses, successes = [], [], [], []
        for j in range(episodes):
            obs, lab, guess, success = _rollout(
                env, teacher, acting, seed + iteration * episodes + j
            )
            new_obs += obs
            new_labels += lab
            guesses += guess
            successes.append(success)
        if iteration == 0 and normalization is not None:
            stacked = stack_steps(new_obs)
            if isinstance(stacked, dict):
                for key, rms in normalization.obs_rms.items():
                    rms.update(stacked[key])
            else:
                normalization.obs_rms.update(stacked)
            normalization.training = False
        error = _label_error(guesses, new_labels, discrete) if guesses else None
        observations += new_obs
        labels += new_labels
        losses = behaviour_clone(
            model,
            normalize(stack_steps(observations)),
            np.asarray(labels),
            epochs=epochs,
            seed=training_seed + iteration,
        )
        history.append(
            DaggerIteration(
                iteration,
                "learner" if iteration else "teacher",
                episodes,
                float(np.mean(successes)),
                error,
                len(labels),
                losses[-1],
            )
        )
    return history


def history_json(history: list[DaggerIteration]) -> list[dict[str, Any]]:
    """The iterations as plain dicts (``dagger.json`` of a run)."""
    return [asdict(item) for item in history]
