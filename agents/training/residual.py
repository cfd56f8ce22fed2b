"""Residual policy learning: a learned correction on top of a scripted policy.

Silver, Allen, Tenenbaum and Kaelbling (2018), "Residual Policy Learning":
the agent acts through ``pi(s) = pi_0(s) + f_theta(s)``, where ``pi_0`` is a
given controller (here a scripted policy of the papers) and ``f_theta`` is
learned by any RL algorithm; with ``f_theta`` near zero the agent starts as
good as ``pi_0`` and learns only what it misses.

:class:`ResidualWrapper` puts ``pi_0`` inside the environment: the learner's
action is the correction ``f``, the environment receives
``clip(pi_0(s) + scale * f, low, high)`` (clipped to the action space). The
observation is unchanged, so SB3 trains the residual with its usual
algorithms; ``info["base_action"]`` is ``pi_0(s)``. :class:`ResidualPredictor`
acts the same way outside the wrapper (evaluation of a trained residual
agent: ``motiongym train`` with ``residual: <policy>`` in the config block).

Silver et al. initialise the residual's last layer to zero, so that the
untrained agent is exactly ``pi_0``; :func:`zero_correction` does so for SB3's
policies (``motiongym train`` calls it on every residual run). Without it an
untrained SAC actor's most likely correction is ``tanh`` of a random linear
map of the observation, not zero (docs/experiments/Excavator-v1.md measures
what that costs the teacher).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import torch
from gymnasium import spaces

from motiongym.baselines import make_policy
from motiongym.baselines.policy import ScriptedPolicy
from motiongym.envs.actions import checked_box_action
from motiongym.envs.core import check_float


class ResidualWrapper(gym.Wrapper):
    """The env acted on by ``policy`` plus the learner's correction (module docstring).

    Args:
        env: a made environment (``gym.make``) with a Box action space.
        policy: the name of a scripted policy declared for ``env``'s ID, or a
            :class:`ScriptedPolicy` made for that ID (``make_policy``).
        scale: the correction's range as a multiple of the action bounds, in
            (0, 2] (1: a correction can move the action anywhere in the box).
        policy_kwargs: the scripted policy's own keywords when ``policy`` is a
            name (e.g. the dig cycle's ``tolerance``: a plan that passes a
            goal only within a tolerance below one step's correction stalls).
    """

    def __init__(
        self,
        env: gym.Env,
        policy: str | ScriptedPolicy,
        scale: float = 1.0,
        policy_kwargs: dict[str, Any] | None = None,
    ) -> None:
        super().__init__(env)
        env_id = env.spec.id if env.spec else None
        if not isinstance(env.action_space, spaces.Box):
            raise ValueError(f"env must have a Box action space, got {env.action_space}")
        if isinstance(policy, str):
            if env.spec is None:
                raise ValueError("a policy given by name needs an env made by gym.make (its ID)")
            policy = make_policy(
                env.spec.id,
                policy,
                env.observation_space,
                env.action_space,
                env.spec.kwargs,
                **(policy_kwargs or {}),
            )
        elif policy_kwargs:
            raise ValueError("policy_kwargs go with a policy's name, not a made policy")
        elif not isinstance(policy, ScriptedPolicy) or policy.env_id != env_id:
            given = getattr(policy, "env_id", None)
            raise ValueError(
                f"policy must be a scripted policy made for {env_id} (make_policy), "
                f"got {type(policy).__name__} for {given!r}"
            )
        self.policy = policy
        self.scale = check_float("scale", scale, 0.0, 2.0, low_open=True)
        self._box = env.action_space  # what the environment takes
        self._correction = spaces.Box(-1.0, 1.0, self._box.shape, np.float32)
        self.action_space = self._correction
        self._obs: Any = None

    def reset(self, **kwargs: Any):
        obs, info = self.env.reset(**kwargs)
        self.policy.reset()
        self._obs = obs
        return obs, info

    def step(self, action: Any):
        correction = checked_box_action(action, self._correction.shape, "a correction")
        base, _ = self.policy.predict(self._obs, deterministic=True)
        box = self._box
        applied = _combined(base, correction, self.scale, box)
        obs, reward, terminated, truncated, info = self.env.step(applied.astype(box.dtype))
        self._obs = obs
        return obs, reward, terminated, truncated, {**info, "base_action": base}


def _combined(
    base: np.ndarray, correction: np.ndarray, scale: float, box: spaces.Box
) -> np.ndarray:
    """``clip(base + scale * half-range * correction)`` to ``box``."""
    half = 0.5 * (box.high - box.low)
    return np.clip(base + scale * half * correction, box.low, box.high).astype(box.dtype)


class ResidualPredictor:
    """A trained residual ``learned`` acting with its scripted ``policy`` (SB3's predictor API)."""

    def __init__(self, learned: Any, policy: ScriptedPolicy, scale: float, box: spaces.Box) -> None:
        self.learned, self.policy, self.scale, self.box = learned, policy, scale, box

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        correction, state = self.learned.predict(observation, state, episode_start, deterministic)
        base, _ = self.policy.predict(observation, None, episode_start, True)
        return _combined(base, correction, self.scale, self.box), state


def zero_correction(model: Any) -> None:
    """Zero the last linear layer of ``model``'s action output (Silver et al. 2018).

    The mean (PPO, A2C: ``policy.action_net``) or pre-``tanh`` output (SAC,
    TQC: ``actor.mu``; TD3, DDPG: the last ``Linear`` of ``actor.mu``) becomes
    exactly 0 for every observation, so the deterministic correction is 0 and
    the agent acts as its scripted policy until it learns; the layer's
    gradient (the layer below's output times the loss's) is not zero, so it
    learns. The exploration noise (SAC's ``log_std``, PPO's ``log_std``) is
    left as SB3 sets it.
    """
    policy = model.policy
    head = getattr(getattr(policy, "actor", None), "mu", None)
    if head is None:
        head = getattr(policy, "action_net", None)
    if isinstance(head, torch.nn.Sequential):
        head = next((m for m in reversed(head) if isinstance(m, torch.nn.Linear)), None)
    if not isinstance(head, torch.nn.Linear):
        raise ValueError(
            f"model must have a linear action output (actor.mu or action_net), got "
            f"{type(model).__name__} with {type(head).__name__}"
        )
    with torch.no_grad():
        head.weight.zero_()
        head.bias.zero_()
