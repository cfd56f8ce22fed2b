"""Features for the goal IDs of every world (:mod:`motiongym.envs.goal`): :class:`GoalError`
(``goal_error``), for hindsight experience replay."""

from __future__ import annotations

import math
from collections.abc import Sequence

import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from motiongym.agents.learners import entry_shape


class GoalError(BaseFeaturesExtractor):
    """A goal ``Dict`` observation with its goal error made explicit.

    Input: ``observation``, ``achieved_goal``, ``desired_goal`` (a goal ID of
    :mod:`motiongym.envs.goal`), raw (``normalize: false``: the squashing
    below is in the goal's own units, m and rad). Output, concatenated: the
    ``observation`` entries at ``keep`` (default all), ``achieved_goal``,
    ``desired_goal``, the error ``e = desired - achieved`` (components at
    ``angles`` wrapped to [-pi, pi], as the env's success test), and for each
    ``s`` of ``error_scales``, ``tanh(e / s)``.

    Every output is a function of the observation and the two goals, so a
    transition relabelled by HER (another ``desired_goal``) gets the
    features of that goal: the extractor is consistent with relabelling.
    Why the error and its squashed copies: the goal env drops the base
    task's ``target_error`` (it depends on the goal), and a success
    tolerance of 5 cm on a 10 m reach is a difference of two inputs in
    metres; :class:`ExcavatorFields` gives the same reason and its measure
    for the non-goal reach, and ``docs/experiments/ExcavatorReachGoal-v1.md``
    the measure for this one.
    """

    # buffers (register_buffer)
    keep: torch.Tensor
    wrap: torch.Tensor
    scales: torch.Tensor

    def __init__(
        self,
        observation_space: spaces.Dict,
        keep: Sequence[int] | None = None,
        angles: Sequence[int] = (),
        error_scales: Sequence[float] = (),
    ) -> None:
        keys = ("observation", "achieved_goal", "desired_goal")
        if not isinstance(observation_space, spaces.Dict) or set(observation_space.spaces) != set(
            keys
        ):
            raise ValueError(
                f"goal_error needs a Dict observation of {keys}, got {observation_space}"
            )
        n_obs = entry_shape(observation_space, "observation")[0]
        size = entry_shape(observation_space, "desired_goal")[0]
        kept = list(range(n_obs)) if keep is None else list(keep)
        if not all(isinstance(i, int) and 0 <= i < n_obs for i in kept):
            raise ValueError(
                f"keep must be indices of the {n_obs} observation entries, got {keep!r}"
            )
        if not all(isinstance(i, int) and 0 <= i < size for i in angles):
            raise ValueError(f"angles must be indices of the {size} goal entries, got {angles!r}")
        scales = tuple(error_scales)
        if not all(isinstance(x, (int, float)) and x > 0 for x in scales):
            raise ValueError(f"error_scales must be positive numbers, got {error_scales!r}")
        super().__init__(observation_space, len(kept) + size * (3 + len(scales)))
        self.register_buffer("keep", torch.tensor(kept, dtype=torch.long))
        wrap = torch.zeros(size, dtype=torch.bool)
        wrap[list(angles)] = True
        self.register_buffer("wrap", wrap)
        self.register_buffer(
            "scales", torch.tensor(scales, dtype=torch.float32).repeat_interleave(size)
        )

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        achieved, desired = observations["achieved_goal"], observations["desired_goal"]
        error = desired - achieved
        error = torch.where(
            self.wrap, torch.remainder(error + math.pi, 2 * math.pi) - math.pi, error
        )
        parts = [observations["observation"][:, self.keep], achieved, desired, error]
        if len(self.scales):
            parts.append(
                torch.tanh(error.repeat(1, len(self.scales) // error.shape[1]) / self.scales)
            )
        return torch.cat(parts, 1)
