"""The contract every motiongym world obeys: a World, a Task and one base environment.

A system is three parts (panda-gym's robot / task / simulator split,
HighwayEnv's small base with a short list of hooks):

* a **World** (:class:`World`): the state and its dynamics, the only code
  that moves state or talks to MuJoCo or the grid. ``reset(scene, rng)``
  puts a scene in place (``rng`` is the episode's generator, the only
  source of a world's noise); ``advance(action) -> events`` moves it by one
  control step and says what happened in it (contacts, cuts, bumps),
  including between samples. It owns ``action_space`` and, where it draws,
  ``render(size) -> frame``.
* a **Task** (:class:`Task`): ``sample(rng, options) -> scene``;
  ``begin(world) -> Outcome`` (the reset's, every reward term 0) and
  ``evaluate(world, events) -> Outcome`` (reward terms, success, safety
  cost, measures, terminated); ``observe(world)`` the observation. It owns
  ``observation_space``, ``reward_terms`` and its reset ``options``; it
  reads the world and never moves it.
* an **environment**: a subclass of :class:`SystemEnv` naming its
  parameters dataclass (``Params``) and building its world and task
  (:meth:`SystemEnv.make_world`, :meth:`SystemEnv.make_task`). Its class
  is metadata and a docstring: the base owns construction from keywords
  (checked once), ``reset``, ``step``, ``info``, the cost, truncation (left
  to ``TimeLimit``) and rendering.

Conventions decided once here for every world (``docs/adding_a_world.md``):

* keyword style: ``Env(render_mode=None, **kwargs)``; every other keyword
  is a field of the frozen ``Params`` dataclass, written with its default
  and unit there only, checked in its ``__post_init__``;
* reward: named terms whose sum, in their order, is the reward; weights are
  magnitudes (:func:`check_weight`), costs subtracted; ``info`` holds
  ``reward_<term>`` for each, ``is_success``, the Safety-Gymnasium ``cost``
  and the task's measures;
* render size: ``render_size`` = ``(rows, columns)`` (:func:`check_render_size`);
* the start pose: the reset option :data:`START` (the world's own
  coordinates: joint angles for an arm, the footprint's cell for the sweeper);
* observations: every Box observation is described by one
  :class:`ObservationLayout`;
* errors: one :class:`ArgumentError` message style (:mod:`.checks`); a
  deprecated name warns once (:class:`Deprecated`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any, ClassVar, NamedTuple, Protocol, runtime_checkable

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.envs.actions import checked_box_action
from motiongym.envs.checks import (
    MAX_WEIGHT,
    RENDER_SIDE,
    ArgumentError,
    Deprecated,
    MotiongymDeprecationWarning,
    check_bool,
    check_choice,
    check_float,
    check_int,
    check_keys,
    check_options,
    check_render_mode,
    check_render_size,
    check_shape,
    check_weight,
    params_from_kwargs,
    warn_deprecated,
)
from motiongym.envs.layout import Field, ObservationLayout
from motiongym.envs.rendering import Renders

__all__ = [
    "MAX_WEIGHT",
    "RENDER_SIDE",
    "START",
    "ArgumentError",
    "Deprecated",
    "Field",
    "MotiongymDeprecationWarning",
    "NeedsReset",
    "ObservationLayout",
    "Outcome",
    "SystemEnv",
    "Task",
    "World",
    "add_reward_terms",
    "check_bool",
    "check_choice",
    "check_float",
    "check_int",
    "check_keys",
    "check_options",
    "check_render_mode",
    "check_render_size",
    "check_shape",
    "check_weight",
    "params_from_kwargs",
    "reward_and_info",
    "warn_deprecated",
    "zero_terms",
]

START = "start"  # the reset option that fixes the start pose, in every world


# ---------------------------------------------------------------- the protocols


class Outcome(NamedTuple):
    """What a task makes of a step (or of the reset, with every term 0)."""

    terms: Mapping[str, float]  # reward terms in order; their sum is the reward
    success: bool  # info["is_success"]
    cost: float  # info["cost"]: 1.0 on a step that collides or violates a safety distance
    measures: Mapping[str, Any]  # the task's info keys
    terminated: bool


@runtime_checkable
class World(Protocol):
    """The state and its dynamics (see the module docstring)."""

    action_space: spaces.Space

    def reset(self, scene: Any, rng: np.random.Generator) -> None:
        """Put ``scene`` in place; ``rng`` is the episode's generator."""

    def advance(self, action: Any) -> Any:
        """Move the state by one control step under a checked ``action``; return its events."""


@runtime_checkable
class Task(Protocol):
    """What the episode asks of the world (see the module docstring)."""

    observation_space: spaces.Space
    reward_terms: tuple[str, ...]
    options: Mapping[str, Callable[[str, Any], Any]]  # reset option -> its check

    def sample(self, rng: np.random.Generator, options: Mapping[str, Any]) -> Any:
        """The episode's scene, drawn from ``rng`` only, fixed where ``options`` say."""

    def begin(self, world: Any) -> Outcome:
        """Start the episode on the reset world: per-episode state, the reset's outcome."""

    def evaluate(self, world: Any, events: Any) -> Outcome:
        """The outcome of the step that produced ``events``."""

    def observe(self, world: Any) -> Any:
        """The observation of the world now (a fresh array or dict of arrays)."""


# ---------------------------------------------------------------- reward terms


def reward_and_info(
    terms: Mapping[str, float], *, cost: float, is_success: bool, **measures: Any
) -> tuple[float, dict[str, Any]]:
    """The reward (the terms' sum, in their order) and the step's ``info``.

    ``info`` holds ``is_success``, ``cost``, the ``measures`` and
    ``reward_<term>`` for every term.
    """
    info: dict[str, Any] = {"is_success": bool(is_success), "cost": float(cost), **measures}
    return add_reward_terms(info, terms), info


def add_reward_terms(info: dict[str, Any], terms: Mapping[str, float]) -> float:
    """Write ``reward_<term>`` for every term into ``info``; return the reward (their
    sum, in their order)."""
    for key, value in terms.items():
        info[f"reward_{key}"] = float(value)
    return float(sum(terms.values()))


def zero_terms(names: Iterable[str]) -> dict[str, float]:
    """Every term 0.0 (the reset's ``info``)."""
    return {name: 0.0 for name in names}


# ---------------------------------------------------------------- the base environment


class NeedsReset:
    """Mixin: ``self._require_reset("step")`` raises until ``self._was_reset`` is set.

    Gymnasium's ``OrderEnforcing`` wrapper does the same for ``gym.make``;
    this guards the unwrapped class.
    """

    _was_reset: bool = False

    def _require_reset(self, what: str) -> None:
        if not self._was_reset:
            raise RuntimeError(f"call reset() before {what}()")


class SystemEnv(NeedsReset, Renders, gym.Env):
    """The one base of every motiongym environment (see the module docstring).

    A subclass sets ``Params`` (its frozen parameters dataclass, built by
    :func:`params_from_kwargs`; ``render_mode`` is the only other keyword)
    and implements :meth:`make_world` and :meth:`make_task`. Optional hooks:
    :meth:`check_action` (the default checks the action against the world's
    space and refuses it with a ``ValueError`` naming the space) and
    ``ACTION_MEANING`` (what a Box action's entries are, for that message).

    ``reset`` draws the scene from the task (``options`` checked against
    ``task.options``, with ``task.deprecated_options`` where a task renamed
    one), puts it in the world and returns the task's observation and the
    reset's ``info``; ``step`` checks the action, advances the world, lets
    the task evaluate the events and returns ``(observation, reward,
    terminated, False, info)``: truncation is ``TimeLimit``'s.
    """

    Params: ClassVar[type]
    ACTION_MEANING: ClassVar[str] = "the world's action"
    metadata: dict[str, Any] = {"render_modes": ["rgb_array", "human"], "render_fps": 30}

    def __init__(self, render_mode: str | None = None, **kwargs: Any) -> None:
        self.params: Any = params_from_kwargs(self.Params, kwargs)
        self.render_mode = check_render_mode(render_mode, self.metadata["render_modes"])
        self.world = self.make_world(self.params)
        self.task = self.make_task(self.params)
        self.action_space = self.world.action_space
        self.observation_space = self.task.observation_space
        self._discrete = isinstance(self.action_space, spaces.Discrete)

    # ------------------------------------------------------------ hooks
    def make_world(self, params: Any) -> World:
        """The world of this environment (built once, reset every episode)."""
        raise NotImplementedError

    def make_task(self, params: Any) -> Task:
        """The task of this environment."""
        raise NotImplementedError

    def check_action(self, action: Any) -> Any:
        """``action`` as the world takes it, or a ``ValueError`` naming the space."""
        space = self.action_space
        if self._discrete:
            try:
                allowed = space.contains(action)
            except (OverflowError, TypeError, ValueError):  # e.g. an int past int64
                allowed = False
            if not allowed:
                raise ArgumentError(f"action must be in {space}, got {action!r}")
            return int(action)
        return checked_box_action(action, tuple(space.shape or ()), self.ACTION_MEANING)

    # ------------------------------------------------------------ the loop
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        task = self.task
        options = check_options(options, task.options, getattr(task, "deprecated_options", None))
        super().reset(seed=seed)
        scene = task.sample(self.np_random, options)
        self.world.reset(scene, self.np_random)
        outcome = task.begin(self.world)
        self._was_reset = True
        info = self._info(outcome)[1]
        self._show_if_human()
        return task.observe(self.world), info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        self._require_reset("step")
        events = self.world.advance(self.check_action(action))
        outcome = self.task.evaluate(self.world, events)
        reward, info = self._info(outcome)
        self._show_if_human()
        return self.task.observe(self.world), reward, outcome.terminated, False, info

    def _info(self, outcome: Outcome) -> tuple[float, dict[str, Any]]:
        """The reward and ``info`` of an outcome (``reward_<term>`` for every term)."""
        info: dict[str, Any] = {
            "is_success": bool(outcome.success),
            "cost": float(outcome.cost),
            **outcome.measures,
        }
        return add_reward_terms(info, outcome.terms), info

    # ------------------------------------------------------------ rendering, state
    @property
    def scene(self) -> Any:
        """The episode's scene (None before the first reset)."""
        return getattr(self.world, "scene", None)

    def _frame(self) -> np.ndarray:
        render = getattr(self.world, "render", None)
        if render is None:
            raise NotImplementedError(f"{type(self.world).__name__} does not render")
        return render(self.params.render_size)

    def close(self) -> None:
        close = getattr(self.world, "close", None)
        if close is not None:
            close()
        super().close()
