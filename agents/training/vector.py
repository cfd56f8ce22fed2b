"""Stable-Baselines3's ``VecEnv`` over a natively batched Gymnasium vector env.

A Gymnasium ``VectorEnv`` registered with ``vector_entry_point`` (such as the
NumPy-batched sweeper) steps all its sub-environments in one call. SB3 wants
its own ``VecEnv`` protocol: after an episode ends the returned observation
already belongs to the next episode and the last one travels in
``infos[i]["terminal_observation"]``. That is Gymnasium's *same-step*
autoreset, so only environments declaring
``metadata["autoreset_mode"] == AutoresetMode.SAME_STEP`` are accepted.

Gymnasium's vector ``info`` is a dict of arrays with ``_key`` masks; it is
split here into SB3's list of per-environment dicts (only the entries whose
mask is set), plus ``TimeLimit.truncated`` for bootstrapping.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env.base_vec_env import VecEnv


def _split_info(info: dict[str, Any], num_envs: int) -> list[dict[str, Any]]:
    """Gymnasium's batched ``info`` -> one dict per sub-environment."""
    per_env: list[dict[str, Any]] = [{} for _ in range(num_envs)]
    for key, values in info.items():
        if key.startswith("_") or key in ("final_obs", "final_info"):
            continue
        mask = info.get(f"_{key}", np.ones(num_envs, dtype=bool))
        for i in np.flatnonzero(mask):
            per_env[i][key] = values[i]
    return per_env


def _take(observation: Any, i: int) -> Any:
    if isinstance(observation, dict):
        return {key: value[i] for key, value in observation.items()}
    return observation[i]


class VectorEnvAdapter(VecEnv):
    """SB3 ``VecEnv`` protocol over a same-step-autoreset Gymnasium vector env."""

    def __init__(self, env: gym.vector.VectorEnv) -> None:
        mode = env.metadata.get("autoreset_mode")
        if mode != AutoresetMode.SAME_STEP:
            raise ValueError(
                f"VectorEnvAdapter needs autoreset_mode SAME_STEP (SB3's convention), got {mode}"
            )
        self.env = env
        self.render_mode = env.render_mode
        super().__init__(env.num_envs, env.single_observation_space, env.single_action_space)
        self._actions: np.ndarray | None = None

    def reset(self) -> Any:
        seed = self._seeds[0]
        observation, info = self.env.reset(seed=seed)
        self.reset_infos = _split_info(info, self.num_envs)
        self._reset_seeds()
        self._reset_options()
        return observation

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self):
        observation, reward, terminated, truncated, info = self.env.step(self._actions)
        dones = terminated | truncated
        infos = _split_info(info, self.num_envs)
        if dones.any():
            final_infos = info.get("final_info", {})
            finished = _split_info(final_infos, self.num_envs) if final_infos else infos
            for i in np.flatnonzero(dones):
                infos[i] = {
                    **finished[i],
                    "terminal_observation": _take(info["final_obs"], int(i)),
                    "TimeLimit.truncated": bool(truncated[i] and not terminated[i]),
                }
        return observation, reward.astype(np.float32), dones, infos

    def close(self) -> None:
        self.env.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        if attr_name == "render_mode":
            return [self.env.render_mode] * self.num_envs
        value = getattr(self.env, attr_name)
        return [value] * len(self._indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        setattr(self.env, attr_name, value)

    def env_method(self, method_name: str, *args, indices: Any = None, **kwargs) -> list[Any]:
        result = getattr(self.env, method_name)(*args, **kwargs)
        return [result] * len(self._indices(indices))

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False] * len(self._indices(indices))

    def _indices(self, indices: Any) -> Sequence[int]:
        if indices is None:
            return range(self.num_envs)
        return [indices] if isinstance(indices, int) else list(indices)
