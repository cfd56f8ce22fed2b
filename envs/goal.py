"""Goal-conditioned variants of the reaching tasks, as Gymnasium-Robotics' ``GoalEnv``.

Hindsight experience replay (HER; Andrychowicz et al. 2017) stores a
transition once and replays it with goals that were achieved later in the
episode. It needs three things of an environment, which
:class:`GoalConditionedEnv` adds to a registered reaching task without
copying it (the task, the world and the scenes stay the base ID's):

* the observation is a ``Dict`` with ``observation`` (the base observation
  less every field that depends on the goal), ``achieved_goal`` and
  ``desired_goal``;
* the reward is a function of ``(achieved_goal, desired_goal, info)`` alone,
  vectorised over a leading batch axis: :meth:`GoalConditionedEnv.compute_reward`;
* ``compute_terminated`` / ``compute_truncated`` of the same signature
  (Gymnasium-Robotics' ``GoalEnv`` API).

Reward (the Fetch and panda-gym convention, plus the safety terms, which do
not depend on the goal and so are read from ``info``): ``0`` on success,
``-1`` otherwise; ``- collision`` on a step with a collision (the base
ID's contact keys, listed in :attr:`GoalFields.collision_keys`); ``- cost``
times the step's Safety-Gymnasium ``info["cost"]`` (1.0 on a close
approach or contact). A collision ends the episode, so with the ``-1`` per
step a collision would pay unless it costs at least what a full failed
episode does, ``1 / (1 - gamma)``: the default ``collision`` = 50 is that
for ``gamma`` = 0.98. With ``collision`` or ``cost`` non-zero, relabelled
transitions need their ``info`` (SB3: ``HerReplayBuffer(copy_info_dict=True)``);
a batch of ``info`` dicts without the keys is a ``ValueError``.

Success is recomputed from the goals as the base task defines it (each
group of goal components within its tolerance; angles wrapped to
[-pi, pi]); the goals are the base observation's float32 fields, so it can
differ from the base's float64 ``is_success`` only within float32 rounding
of a tolerance (tested to agree over scripted episodes). Termination and
truncation are the base ID's (its time limit is registered again).

Each system declares where its goal lives with a function
``goal_fields(base_kwargs) -> GoalFields`` (``envs/<system>/goal.py``) and
registers its goal IDs with :func:`goal_registration`.
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.envs.registration import load_env_creator

from motiongym.envs.core import ArgumentError, check_float

# The goal env's own keyword arguments; every other one goes to the base env.
OWN_KWARGS = ("base", "fields", "collision", "cost")
ENTRY_POINT = "motiongym.envs.goal:GoalConditionedEnv"


@dataclass(frozen=True)
class GoalFields:
    """Where a base observation holds the goal, and what success means for it.

    ``achieved``, ``desired`` and ``error`` are slices of the base (flat)
    observation of size ``base_size``: what the robot reaches (gripper,
    bucket tip and angle), the target, and ``desired - achieved`` (wrapped on
    ``angles``, indices of goal components). Success: for every ``(components,
    tolerance)`` of ``tolerances``, the norm of the error's components is at
    most the tolerance. ``collision_keys``: ``info`` keys whose truth is a
    collision (the base task's contact); ``collision_ends``: whether the base
    ends the episode on one.
    """

    base_size: int
    achieved: slice
    desired: slice
    error: slice
    tolerances: tuple[tuple[slice, float], ...]
    collision_keys: tuple[str, ...]
    angles: tuple[int, ...] = ()
    collision_ends: bool = True

    @property
    def size(self) -> int:
        """The goal's length."""
        return self.desired.stop - self.desired.start

    @functools.cached_property
    def kept(self) -> np.ndarray:
        """Indices of the base observation that do not depend on the goal."""
        return np.delete(np.arange(self.base_size), np.r_[self.desired, self.error])

    def error_of(self, achieved: np.ndarray, desired: np.ndarray) -> np.ndarray:
        """``desired - achieved`` (..., size), angle components wrapped to [-pi, pi]."""
        e = np.asarray(desired, np.float64) - np.asarray(achieved, np.float64)
        if self.angles:
            a = list(self.angles)
            e[..., a] = np.remainder(e[..., a] + np.pi, 2 * np.pi) - np.pi
        return e

    def success(self, achieved: np.ndarray, desired: np.ndarray) -> np.ndarray:
        """Whether each goal pair is reached: bool (...)."""
        e = self.error_of(achieved, desired)
        ok = np.ones(e.shape[:-1], bool)
        for components, tolerance in self.tolerances:
            ok &= np.linalg.norm(e[..., components], axis=-1) <= tolerance
        return ok

    def split(self, flat: np.ndarray) -> dict[str, np.ndarray]:
        """The goal Dict observation from a base observation (base_size,)."""
        return {
            "observation": flat[self.kept],
            "achieved_goal": flat[self.achieved].copy(),
            "desired_goal": flat[self.desired].copy(),
        }

    def join(self, observation: Mapping[str, np.ndarray]) -> np.ndarray:
        """The base observation (base_size,) from a goal Dict (inverse of :meth:`split`)."""
        flat = np.empty(self.base_size, np.float32)
        flat[self.kept] = observation["observation"]
        flat[self.desired] = observation["desired_goal"]
        flat[self.error] = self.error_of(observation["achieved_goal"], observation["desired_goal"])
        return flat


# The goal fields functions the systems registered (:func:`goal_registration`):
# ``{name: "module:function"}``. The keyword ``fields`` names one of these; no
# other string is imported.
GOAL_FIELDS: dict[str, str] = {}


def load(name: str, reference: Any) -> Any:
    """The goal fields function ``reference``: a name in :data:`GOAL_FIELDS` (registered
    by :func:`goal_registration`) or a callable passed from Python, else ArgumentError.

    A string is looked up, never imported as given: only the registered
    ``"module:function"`` targets are imported.
    """
    if callable(reference):
        return reference
    if isinstance(reference, str) and reference in GOAL_FIELDS:
        module, attribute = GOAL_FIELDS[reference].split(":")
        return getattr(importlib.import_module(module), attribute)
    shown = reference[:200] if isinstance(reference, str) else reference
    raise ArgumentError(
        f"{name} must be one of the registered goal fields {sorted(GOAL_FIELDS)} "
        f"(or a callable, from Python), got {shown!r}"
    )


def _check_base(base: Any) -> str:
    goal_ids = [s.id for s in gym.registry.values() if s.entry_point == ENTRY_POINT]
    if not isinstance(base, str) or base not in gym.registry or base in goal_ids:
        raise ArgumentError(f"base must be a registered (non-goal) environment ID, got {base!r}")
    return base


def resolve(env_kwargs: Mapping[str, Any]) -> tuple[str, dict[str, Any], GoalFields]:
    """``(base ID, base keyword arguments, GoalFields)`` of a goal env's keyword arguments.

    The base kwargs are the base ID's registered ones updated with every
    keyword that is not the goal env's own (:data:`OWN_KWARGS`); scripted
    policies adapted to the goal variant build their model from them.
    """
    if "base" not in env_kwargs or "fields" not in env_kwargs:
        raise ArgumentError(
            f"a goal env needs the keyword arguments 'base' (an ID) and 'fields' "
            f"(one of {sorted(GOAL_FIELDS)}), got {sorted(env_kwargs)}"
        )
    base = _check_base(env_kwargs["base"])
    kwargs = {**gym.spec(base).kwargs}
    kwargs.update({k: v for k, v in env_kwargs.items() if k not in OWN_KWARGS})
    model_kwargs = {k: v for k, v in kwargs.items() if k != "render_mode"}
    fields = load("fields", env_kwargs["fields"])(model_kwargs)
    if not isinstance(fields, GoalFields):
        raise ArgumentError(f"fields must return a GoalFields, got {fields!r}")
    return base, kwargs, fields


def goal_registration(base: Mapping[str, Any], goal_id: str, fields: str) -> dict[str, Any]:
    """The registration of ``goal_id``: the goal variant of the registration ``base``.

    ``fields`` (``"module:function"``) is added to :data:`GOAL_FIELDS`, the
    names the keyword ``fields`` accepts.
    """
    GOAL_FIELDS[fields] = fields
    return {
        "id": goal_id,
        "entry_point": ENTRY_POINT,
        "max_episode_steps": base["max_episode_steps"],
        "kwargs": {"base": base["id"], "fields": fields},
    }


class GoalConditionedEnv(gym.Env):
    """A reaching task as a ``GoalEnv`` (module docstring): the base ID's env, goal split out.

    Keyword arguments: ``base`` (the base ID), ``fields`` (a name in
    :data:`GOAL_FIELDS`, or from Python a callable, returning its :class:`GoalFields`),
    ``collision`` (>= 0, default 50, the penalty of a collision step), ``cost``
    (>= 0, default 0, per unit of ``info["cost"]``); every other keyword goes to
    the base env (its reward weights change nothing here: the reward is this
    one; the harvest arm's own ``collision`` weight is shadowed by the penalty of the same name).

    Observation: ``Dict(observation, achieved_goal, desired_goal)``, float32,
    bounds the base observation's. ``info``: the base env's, its
    ``reward_<term>`` replaced by this reward's terms (:meth:`reward_terms`).
    Action, termination, reset options, rendering: the base env's.
    """

    metadata = {"render_modes": ["rgb_array", "human"]}  # every base's; an instance has its base's

    def __init__(self, base: str, fields: Any, collision: float = 50.0, cost: float = 0.0, **kw):
        self.collision = check_float("collision", collision, 0.0, 1e6)
        self.cost = check_float("cost", cost, 0.0, 1e6)
        self.base_id, base_kwargs, self.fields = resolve({"base": base, "fields": fields, **kw})
        entry = gym.spec(base).entry_point
        if entry is None:
            raise ValueError(f"base {base} has no entry point")
        self.base = (load_env_creator(entry) if isinstance(entry, str) else entry)(**base_kwargs)
        self.base.spec = gym.spec(base)  # its window, where human, says which world
        self.metadata = self.base.metadata
        self.dt = getattr(self.base, "dt", None)  # s, the base's control period
        self.render_mode = self.base.render_mode
        self.action_space = self.base.action_space
        box, f = self.base.observation_space, self.fields
        if not isinstance(box, spaces.Box):
            raise ValueError(f"base {base} observes a {type(box).__name__}, not a Box")
        if box.shape != (f.base_size,):
            raise ValueError(f"{fields} describes {f.base_size} values, {base} has {box.shape}")

        def part(index: Any) -> spaces.Box:
            return spaces.Box(box.low[index], box.high[index], dtype=np.float32)

        self.observation_space = spaces.Dict(
            {
                "observation": part(f.kept),
                "achieved_goal": part(f.achieved),
                "desired_goal": part(f.desired),
            }
        )

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        flat, info = self.base.reset(seed=seed, options=options)
        info = {k: v for k, v in info.items() if not k.startswith("reward_")}
        names = ("goal", "collision", "cost") if self.collision or self.cost else ("goal",)
        return self.fields.split(flat), {**info, **{f"reward_{k}": 0.0 for k in names}}

    def step(self, action: Any):
        flat, _, terminated, truncated, info = self.base.step(action)
        obs = self.fields.split(flat)
        terms = self.reward_terms(obs["achieved_goal"], obs["desired_goal"], info)
        info = {k: v for k, v in info.items() if not k.startswith("reward_")}
        info.update({f"reward_{k}": float(v) for k, v in terms.items()})
        return obs, float(sum(terms.values())), terminated, truncated, info

    def render(self):
        return self.base.render()

    def close(self) -> None:
        self.base.close()

    # ------------------------------------------------------------------ GoalEnv
    def _goals(self, achieved: Any, desired: Any) -> tuple[np.ndarray, np.ndarray]:
        a, d = np.asarray(achieved, np.float64), np.asarray(desired, np.float64)
        for name, g in (("achieved_goal", a), ("desired_goal", d)):
            if g.ndim == 0 or g.shape[-1] != self.fields.size:
                raise ValueError(
                    f"{name} must have shape (..., {self.fields.size}) (the goal of "
                    f"{self.base_id}), got {g.shape}"
                )
        if a.shape != d.shape:
            raise ValueError(f"achieved_goal {a.shape} and desired_goal {d.shape} must match")
        return a, d

    def _safety(self, info: Any, batch: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        """``(collision 0/1, cost)`` per goal pair, from one ``info`` dict or a batch of them."""
        infos = [info] if isinstance(info, Mapping) else list(np.ravel(np.asarray(info)))
        keys = (*self.fields.collision_keys, "cost")
        if not infos or any(k not in i for i in infos for k in keys):
            raise ValueError(
                f"info must hold {list(keys)} for the safety terms (with HER: "
                "HerReplayBuffer(copy_info_dict=True)), or set collision=0 and cost=0"
            )
        hit = np.array([any(float(i[k]) > 0.0 for k in self.fields.collision_keys) for i in infos])
        cost = np.array([float(i["cost"]) for i in infos])
        if len(infos) not in (1, int(np.prod(batch))):
            raise ValueError(f"info must hold one dict per goal pair {batch}, got {len(infos)}")
        shape = batch if len(infos) > 1 else ()
        return hit.astype(float).reshape(shape), cost.reshape(shape)

    def reward_terms(self, achieved_goal: Any, desired_goal: Any, info: Any) -> dict[str, Any]:
        """``goal`` (0 reached, else -1), ``collision`` and ``cost``; they sum to the reward."""
        a, d = self._goals(achieved_goal, desired_goal)
        terms = {"goal": self.fields.success(a, d) - 1.0}
        if self.collision != 0.0 or self.cost != 0.0:
            hit, cost = self._safety(info, a.shape[:-1])
            terms["collision"] = -self.collision * hit
            terms["cost"] = -self.cost * cost
        return terms

    def compute_reward(self, achieved_goal: Any, desired_goal: Any, info: Any) -> Any:
        """The sum of :meth:`reward_terms`: ``-1`` unless reached, ``- collision`` on
        contact, ``- cost * info['cost']``.

        Vectorised: goals (..., g) with ``info`` a dict or an array of dicts
        (one per goal pair); returns a float for one pair, else an array.
        """
        reward = sum(self.reward_terms(achieved_goal, desired_goal, info).values())
        return float(reward) if np.ndim(reward) == 0 else reward

    def compute_terminated(self, achieved_goal: Any, desired_goal: Any, info: Any) -> Any:
        """Reached, or (where the base ends on it) a collision: as the base terminates."""
        a, d = self._goals(achieved_goal, desired_goal)
        done = self.fields.success(a, d)
        if self.fields.collision_ends:
            done = done | (self._safety(info, a.shape[:-1])[0] > 0.0)
        return bool(done) if done.ndim == 0 else done

    def compute_truncated(self, achieved_goal: Any, desired_goal: Any, info: Any) -> Any:
        """Never: truncation is the registered time limit's."""
        a, _ = self._goals(achieved_goal, desired_goal)
        done = np.zeros(a.shape[:-1], bool)
        return bool(done) if done.ndim == 0 else done
