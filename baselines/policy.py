"""The scripted-policy interface: Stable-Baselines3's predictor protocol.

A scripted policy is interchangeable with a learned SB3 model: it offers
``predict(observation, state=None, episode_start=None, deterministic=True)``
and returns ``(action, state)``. It acts from the observation alone; whatever
it must remember within an episode (a plan, a map, a stack) lives in a
per-episode *memory* object that it creates with :meth:`new_memory` and that
is replaced whenever ``episode_start`` is true.

Observations may come one at a time (a plain ``gym.Env``) or batched with a
leading ``n_envs`` axis (a ``VecEnv`` or Gymnasium vector env, as in SB3's
``evaluate_policy``); the policy then keeps one memory per sub-environment.
Batching is recognised by comparing the observation's shape with the
observation space.

Without ``episode_start`` (a hand-written loop), memory persists from call to
call: pass ``episode_start=True`` on an episode's first step or call
:meth:`reset` after ``env.reset``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, cast

import numpy as np
from gymnasium import spaces

Shape = tuple[int, ...]  # a space's shape (None only for spaces without one)


class ScriptedPolicy(ABC):
    """Base class of every scripted reference policy.

    Args:
        observation_space: the environment's (single) observation space.
        action_space: the environment's (single) action space.
        env_kwargs: the keyword arguments the environment was made with
            (its registered defaults merged with the user's), so that a policy
            can rebuild the same static model (an arm's link table, the
            robot's width) as the environment; never the environment itself.
    """

    env_id: str | None = None  # the ID it was declared for (set by ``make_policy``)

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        env_kwargs: dict[str, Any] | None = None,
    ) -> None:
        self.observation_space = observation_space
        self.action_space = action_space
        self.env_kwargs = dict(env_kwargs or {})
        self._memories: list[Any] = []

    @abstractmethod
    def new_memory(self) -> Any:
        """A fresh per-episode memory (None if the policy is memoryless)."""

    @abstractmethod
    def act(self, observation: Any, memory: Any) -> Any:
        """The action for one unbatched observation; may update ``memory``."""

    def reset(self) -> None:
        """Forget every episode in progress."""
        self._memories = []

    def diagnostics(self, index: int = 0) -> dict[str, Any]:
        """What the policy knows of its episode in progress (sub-environment ``index``).

        The public view that evaluations and reproductions read (a plan's
        delay, whether the policy has declared itself done, ...), so that
        none of them reads private memory. Empty where a policy has nothing to
        report; each policy documents its keys.
        """
        if not self._memories:
            return {}
        return self.describe(self._memories[index])

    def describe(self, memory: Any) -> dict[str, Any]:
        """``diagnostics()`` of one memory; override to report (default: nothing)."""
        return {}

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: np.ndarray | bool | None = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """SB3's predictor interface; ``state`` is passed through untouched.

        ``observation`` must match the observation space (each entry of a Dict
        space): real numbers of the space's shape, with or without a leading
        batch axis, all finite; anything else is a ``ValueError`` naming the
        entry, the shape expected and what was given.
        """
        self._check_observation(observation)
        batched = self._is_batched(observation)
        observations = _unbatch(observation) if batched else [observation]
        starts = np.zeros(len(observations), dtype=bool)
        if episode_start is not None:
            starts |= np.asarray(episode_start, dtype=bool).reshape(-1)
        if len(self._memories) != len(observations):
            self._memories = [self.new_memory() for _ in observations]
            starts[:] = False
        actions = []
        for i, obs in enumerate(observations):
            if starts[i]:
                self._memories[i] = self.new_memory()
            actions.append(self.act(obs, self._memories[i]))
        if batched:
            return np.stack([np.asarray(a) for a in actions]), state
        return np.asarray(actions[0]), state

    def _check_observation(self, observation: Any) -> None:
        checks = self.__dict__.get("_entry_checks") or self._make_entry_checks()
        if isinstance(self.observation_space, spaces.Dict):
            if not isinstance(observation, dict) or observation.keys() != checks.keys():
                shown = sorted(observation) if isinstance(observation, dict) else observation
                raise ValueError(
                    f"observation must be a dict with keys {sorted(checks)}, got {shown!r}"
                )
            for key, check in checks.items():
                check.check(observation[key])
        else:
            checks[None].check(observation)

    def _make_entry_checks(self) -> dict[Any, _EntryCheck]:
        """One :class:`_EntryCheck` per entry of the space (key None for a single space),
        built once: predict pays only the comparisons."""
        space = self.observation_space
        checks: dict[Any, _EntryCheck]
        if isinstance(space, spaces.Dict):
            checks = {k: _EntryCheck(f"observation[{k!r}]", sub) for k, sub in space.spaces.items()}
        else:
            checks = {None: _EntryCheck("observation", space)}
        self._entry_checks = checks
        return checks

    def _is_batched(self, observation: Any) -> bool:
        space = self.observation_space
        if isinstance(space, spaces.Dict):
            key = next(iter(space.spaces))
            return np.ndim(observation[key]) > len(cast(Shape, space.spaces[key].shape))
        return np.ndim(observation) > len(cast(Shape, space.shape))


class _EntryCheck:
    """One observation entry: real numbers of the space's shape, or a batch of them,
    finite, and inside a Box space's bounds (with slack for float32 rounding); else a
    ValueError naming the entry. A planner fed an observation no environment makes (a
    path 10**9 long) could plan without end. The bounds are padded once here, infinite
    ones replaced by the largest float, so that one pair of comparisons also catches
    NaN and inf."""

    def __init__(self, name: str, space: spaces.Space) -> None:
        self.name, self.shape = name, tuple(space.shape or ())
        self.box = isinstance(space, spaces.Box)
        if isinstance(space, spaces.Box):
            low, high = space.low.astype(np.float64), space.high.astype(np.float64)
            scale = np.maximum(np.abs(low), np.abs(high))
            slack = 1e-6 * (1.0 + np.where(np.isfinite(scale), scale, 0.0))
            largest = np.finfo(np.float64).max
            self.low = np.where(np.isfinite(low), low - slack, -largest)
            self.high = np.where(np.isfinite(high), high + slack, largest)

    def check(self, value: Any) -> None:
        a = value if type(value) is np.ndarray else _as_array(value)
        n = len(self.shape)
        if (
            a.dtype.kind not in "biuf"
            or a.ndim not in (n, n + 1)
            or a.shape[a.ndim - n :] != self.shape
            or (a.ndim > n and a.shape[0] == 0)
        ):
            raise ValueError(
                f"{self.name} must be real numbers of shape {self.shape} (or a batch of "
                f"them), got {type(value).__name__} of shape {a.shape} and dtype {a.dtype}"
            )
        if self.box:
            if not ((a >= self.low) & (a <= self.high)).all():
                self._refuse(a)
        elif a.dtype.kind == "f" and not np.isfinite(a).all():
            self._refuse(a)

    def _refuse(self, a: np.ndarray) -> None:
        if a.dtype.kind == "f" and not np.isfinite(a).all():
            raise ValueError(f"{self.name} must be finite (no NaN or inf)")
        outside = (a < self.low) | (a > self.high)
        i = tuple(int(k) for k in np.unravel_index(int(np.flatnonzero(outside)[0]), a.shape))
        j = i[a.ndim - len(self.shape) :]
        low, high = self.low[j], self.high[j]
        raise ValueError(
            f"{self.name}{list(i)} = {a[i]:.6g} is outside the observation space's "
            f"[{low:.6g}, {high:.6g}]"
        )


def _as_array(value: Any) -> np.ndarray:
    try:
        return np.asarray(value)
    except ValueError:  # ragged
        return np.asarray(None)


def _unbatch(observation: Any) -> list[Any]:
    if isinstance(observation, dict):
        keys = list(observation)
        n = len(observation[keys[0]])
        return [{k: observation[k][i] for k in keys} for i in range(n)]
    return list(observation)
