"""One policy with shared parameters for every agent of a PettingZoo parallel env.

Training (``vec_env: pettingzoo`` in a ``configs/`` block):
:class:`SharedPolicyVecEnv` is an SB3 ``VecEnv`` over ``n_copies`` copies of
an ID's PettingZoo ``ParallelEnv``, with one *slot* per (copy, agent), slot
``copy * n_agents + agent_index``. SB3 sees ``n_copies * n_agents``
environments and trains one policy on all of them: parameter sharing
(Gupta, Egorov & Kochenderfer 2017), as SuperSuit's
``pettingzoo_env_to_vec_env_v1`` does, written here in a few lines.

Slot observation: the agent's observation followed by the one-hot index of
the agent in ``possible_agents`` (``[obs, e_i]``, shape ``(d + n_agents,)``).
With the dual-arm cell both agents see the same observation, so without the
index the shared policy could only give both arms the same advance; with it
the policy can act differently per arm while every parameter is shared.

Conventions (SB3's): each slot's reward is its agent's reward; when a copy
ends (every agent terminated or truncated together) every slot of it is
done, its ``info`` carries ``terminal_observation`` (the slot's last
observation) and ``TimeLimit.truncated``, and the copy is reset at once.
Agents that drop out one by one are refused (the slots are fixed).
Seeding: ``seed(s)`` then ``reset()`` resets copy ``k`` with ``s + k``.
SB3's step count counts slots: one environment step of a copy is
``n_agents`` timesteps.

Evaluation in the single-agent view: :class:`SharedPolicyPredictor` takes the
Gymnasium environment's observation (the one every agent sees), builds each
agent's slot observation, predicts and concatenates the agents' actions in
``possible_agents`` order, which is the joint action of the single-agent
environment (``DualArmCell-v0``: robot 1's advance, then robot 2's).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

from motiongym.agents.errors import UsageError
from motiongym.systems import declared


def parallel_factory(env_id: str) -> Callable[..., ParallelEnv]:
    """The factory of ``env_id``'s PettingZoo parallel environment (the systems'
    ``PARALLEL_ENVS`` declarations, :mod:`motiongym.systems`)."""
    found = declared("envs", "PARALLEL_ENVS")
    if env_id not in found:
        raise UsageError(
            f"{env_id} has no PettingZoo parallel version (needed by vec_env: pettingzoo); "
            f"IDs that have one: {', '.join(found)}"
        )
    module, function = found[env_id].split(":")
    return getattr(importlib.import_module(module), function)


def slot_observation_space(agent_space: spaces.Box, n_agents: int) -> spaces.Box:
    """The agent's observation space followed by ``n_agents`` one-hot entries in [0, 1]."""
    low = np.concatenate([agent_space.low, np.zeros(n_agents)]).astype(np.float32)
    high = np.concatenate([agent_space.high, np.ones(n_agents)]).astype(np.float32)
    return spaces.Box(low, high, dtype=np.float32)


def slot_observations(per_agent: np.ndarray) -> np.ndarray:
    """``(B, n_agents, d)`` agents' observations -> ``(B * n_agents, d + n_agents)`` slots.

    Row ``b * n_agents + i`` is ``[per_agent[b, i], e_i]``.
    """
    batch, n_agents, _ = per_agent.shape
    one_hot = np.broadcast_to(np.eye(n_agents, dtype=np.float32), (batch, n_agents, n_agents))
    slots = np.concatenate([per_agent.astype(np.float32), one_hot], axis=2)  # (B, n, d + n)
    return slots.reshape(batch * n_agents, -1)


class SharedPolicyVecEnv(VecEnv):
    """SB3 ``VecEnv`` with one slot per (copy, agent) of ``n_copies`` parallel envs."""

    def __init__(self, make_env: Callable[[], ParallelEnv], n_copies: int) -> None:
        if n_copies < 1:
            raise ValueError(f"n_copies must be at least 1, got {n_copies}")
        self.envs = [make_env() for _ in range(n_copies)]
        self.agents = list(self.envs[0].possible_agents)
        self.n_agents = len(self.agents)
        agent_space = self.envs[0].observation_space(self.agents[0])
        action_space = self.envs[0].action_space(self.agents[0])
        for agent in self.agents:
            if (
                self.envs[0].observation_space(agent) != agent_space
                or self.envs[0].action_space(agent) != action_space
            ):
                raise ValueError(
                    f"agent {agent} has other spaces than {self.agents[0]}; "
                    "a shared policy needs one observation and one action space"
                )
        if not isinstance(agent_space, spaces.Box) or len(agent_space.shape) != 1:
            raise ValueError(f"a shared policy needs a flat Box observation, got {agent_space}")
        self.agent_observation_space = agent_space
        self._actions = np.empty(0)
        super().__init__(
            len(self.envs) * self.n_agents,
            slot_observation_space(agent_space, self.n_agents),
            action_space,
        )

    def _copy_of(self, slot: int) -> ParallelEnv:
        return self.envs[slot // self.n_agents]

    def _slot_observations(self, observations: dict[str, np.ndarray]) -> np.ndarray:
        per_agent = np.stack([observations[agent] for agent in self.agents])[None]  # (1, n, d)
        return slot_observations(per_agent)  # (n, d + n)

    def seed(self, seed: int | None = None) -> Sequence[int | None]:
        """Copy ``k`` (each of its slots) gets ``seed + k`` at the next reset."""
        base = super().seed(seed)[0]  # seed + slot (an int: SB3 draws one for None)
        assert base is not None
        self._seeds = [base + slot // self.n_agents for slot in range(self.num_envs)]
        return self._seeds

    def reset(self) -> np.ndarray:
        observations, self.reset_infos = [], []
        for k, env in enumerate(self.envs):
            first = k * self.n_agents
            options = {"options": self._options[first]} if self._options[first] else {}
            obs, infos = env.reset(seed=self._seeds[first], **options)
            observations.append(self._slot_observations(obs))
            self.reset_infos += [infos[agent] for agent in self.agents]
        self._reset_seeds()
        self._reset_options()
        return np.concatenate(observations)

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        observations, rewards, dones, slot_infos = [], [], [], []
        for k, env in enumerate(self.envs):
            first = k * self.n_agents
            joint = {agent: self._actions[first + i] for i, agent in enumerate(self.agents)}
            obs, reward, terminated, truncated, infos = env.step(joint)
            ended = [terminated[agent] or truncated[agent] for agent in self.agents]
            if any(ended) and env.agents:
                raise ValueError(
                    f"agents {[a for a, e in zip(self.agents, ended, strict=True) if e]} ended "
                    "while others go on; a shared-policy slot needs the copy to end together"
                )
            slot_obs = self._slot_observations(obs)
            done = not env.agents
            infos = {agent: dict(infos[agent]) for agent in self.agents}
            for agent in self.agents:
                infos[agent]["TimeLimit.truncated"] = bool(
                    truncated[agent] and not terminated[agent]
                )
            if done:
                for agent, last in zip(self.agents, slot_obs, strict=True):
                    infos[agent]["terminal_observation"] = last
                obs, reset_infos = env.reset()
                slot_obs = self._slot_observations(obs)
                self.reset_infos[first : first + self.n_agents] = [
                    reset_infos[agent] for agent in self.agents
                ]
            observations.append(slot_obs)
            rewards += [reward[agent] for agent in self.agents]
            dones += [done] * self.n_agents
            slot_infos += [infos[agent] for agent in self.agents]
        return (
            np.concatenate(observations),
            np.asarray(rewards, dtype=np.float32),
            np.asarray(dones, dtype=bool),
            slot_infos,
        )

    def close(self) -> None:
        for env in self.envs:
            env.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(self._copy_of(slot), attr_name) for slot in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        for slot in self._get_indices(indices):
            setattr(self._copy_of(slot), attr_name, value)

    def env_method(self, method_name: str, *args, indices: Any = None, **kwargs) -> list[Any]:
        return [
            getattr(self._copy_of(slot), method_name)(*args, **kwargs)
            for slot in self._get_indices(indices)
        ]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False for _ in self._get_indices(indices)]


def check_single_agent_view(venv: SharedPolicyVecEnv, env: gym.Env, env_id: str) -> None:
    """Raise unless ``env`` observes what each agent does and acts with their joint action."""
    if env.observation_space != venv.agent_observation_space:
        raise UsageError(
            f"the shared policy's agents observe {venv.agent_observation_space}; "
            f"the {env_id} environment has {env.observation_space}"
        )
    joint_shape = (venv.n_agents * int(np.prod(venv.action_space.shape or ())),)
    if env.action_space.shape != joint_shape:
        raise UsageError(
            f"the shared policy's {venv.n_agents} agents act with a joint action of shape "
            f"{joint_shape}; the {env_id} environment's action space is {env.action_space}"
        )


class SharedPolicyPredictor:
    """The shared policy acting for every agent of the single-agent view.

    ``slot_predictor`` predicts from slot observations (a model, or a model
    behind its observation normalisation). ``predict`` takes one observation
    ``(d,)`` or a batch ``(B, d)`` and returns the joint action ``(n_agents a,)``
    or ``(B, n_agents a)``, agents in ``possible_agents`` order. A recurrent
    policy's state is per slot (``B * n_agents`` rows).
    """

    def __init__(self, slot_predictor: Any, n_agents: int) -> None:
        self.slot_predictor = slot_predictor
        self.n_agents = n_agents

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        observation = np.asarray(observation)
        single = observation.ndim == 1
        batch = observation.reshape(1, -1) if single else observation  # (B, d)
        if episode_start is not None:
            episode_start = np.repeat(np.asarray(episode_start).reshape(-1), self.n_agents)
        per_agent = np.repeat(batch[:, None, :], self.n_agents, axis=1)  # (B, n, d)
        actions, state = self.slot_predictor.predict(
            slot_observations(per_agent), state, episode_start, deterministic
        )  # (B n, a)
        joint = actions.reshape(batch.shape[0], -1)  # (B, n a)
        return (joint[0] if single else joint), state
