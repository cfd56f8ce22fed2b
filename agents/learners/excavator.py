"""The excavator's learner-side features: :class:`ExcavatorFields` (``excavator_fields``)."""

from __future__ import annotations

from collections.abc import Sequence

import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from motiongym.envs.excavator.observation import layout


class ExcavatorFields(BaseFeaturesExtractor):
    """The named fields of an excavator observation, the rest dropped.

    ``fields``: names of :func:`motiongym.envs.excavator.observation.layout`
    (``q``, ``target_error``, ...) of ``task`` under ``physics``, in the
    order given; the output is those entries, concatenated, unchanged. A
    reach's action depends on the joints and the target, not on the ground
    profile, the truck or the pipe (34 of the 58 entries, each episode's
    scene): a network fed them all fits them to a few hundred scenes and
    errs on new ones (docs/experiments/ExcavatorReach-v0.md measures it).

    ``error_scales`` (m and rad, for a block with ``normalize: false``): for
    each scale ``s``, ``tanh(target_error / s)`` is appended (4 entries). The
    success tolerance is 5 cm on a reach of 10 m, and the teacher's joint-rate
    law is steepest in the last centimetres; the raw error spans metres, and a
    network that sees it only in metres settles where its output crosses
    zero, tens of centimetres off. The squashed copies resolve the last
    centimetres at ``s = 0.03`` and the approach at ``s = 0.3``.
    """

    # buffers (register_buffer)
    index: torch.Tensor
    error: torch.Tensor
    scales: torch.Tensor

    def __init__(
        self,
        observation_space: spaces.Box,
        fields: Sequence[str],
        task: str = "reach",
        physics: str = "v0",
        error_scales: Sequence[float] = (),
    ) -> None:
        slices = layout(task, physics)
        if isinstance(fields, str) or not fields or any(f not in slices for f in fields):
            raise ValueError(
                f"fields must be names of the {task} observation ({', '.join(slices)}), "
                f"got {fields!r}"
            )
        size = max(s.stop for s in slices.values())
        if observation_space.shape != (size,):
            raise ValueError(
                f"observation_space must be the {task} observation under physics {physics} "
                f"(shape ({size},)), got shape {observation_space.shape}"
            )
        scales = tuple(error_scales)
        if scales and (
            "target_error" not in slices
            or not all(isinstance(x, (int, float)) and x > 0 for x in scales)
        ):
            raise ValueError(
                f"error_scales must be positive numbers for an observation with a "
                f"target_error, got {error_scales!r} for the {task} observation"
            )
        index = torch.cat([torch.arange(slices[f].start, slices[f].stop) for f in fields])
        error = slices.get("target_error", slice(0, 0))
        super().__init__(observation_space, len(index) + 4 * len(scales))
        self.register_buffer("index", index)
        self.register_buffer("error", torch.arange(error.start, error.stop))
        self.register_buffer(
            "scales", torch.tensor(scales, dtype=torch.float32).repeat_interleave(4)
        )

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        selected = observations[:, self.index]
        if not len(self.scales):
            return selected
        error = observations[:, self.error].repeat(1, len(self.scales) // 4)
        return torch.cat([selected, torch.tanh(error / self.scales)], 1)


# Names a config may give ``features_extractor_class`` -> the class.
FEATURES_EXTRACTORS: dict[str, type[BaseFeaturesExtractor]] = {
    "excavator_fields": ExcavatorFields,
}
