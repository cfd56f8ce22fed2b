"""Features extractors that configs name in ``policy_kwargs`` (never code in YAML).

A block's ``policy_kwargs`` may say ``features_extractor_class:
sweeper_egocentric`` (a key of :data:`FEATURES_EXTRACTORS`) with its keywords in
``features_extractor_kwargs``; ``motiongym.agents.train`` turns the name into
the class.

:class:`SweeperEgocentric` re-frames the sweeper's observation around the
robot. The environment's windows and coarse maps are world-aligned (row 0
north), so the same situation (a swept lane on the left, a wall ahead) reads
differently for each heading and position, and an MLP has to learn it once
per pose. Here every input is turned so that the robot's heading points up,
and the coarse maps are shifted so that the robot's block is at the centre.
It is a pure function of the current observation: the policy sees what the
scripted policies see, in another frame, and remembers nothing.

:class:`ExcavatorFields` keeps the named fields of an excavator observation
(``excavator_fields`` with ``fields: [q, target_error, ...]``).

:class:`motiongym.agents.obstacle_sets.HarvestObstacleSet` (``harvest_obstacle_set``)
pools shared per-obstacle networks over the harvest arm's obstacle slots.

:class:`GoalError` adds the goal error ``desired - achieved`` (and squashed copies
of it) to a goal-conditioned observation (``goal_error``, for the goal IDs of
:mod:`motiongym.envs.goal` and hindsight experience replay).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from motiongym.agents.obstacle_sets import HarvestObstacleSet
from motiongym.envs.excavator.observation import layout


def _heading(pose: torch.Tensor) -> torch.Tensor:
    """``(B,)``: the believed heading (0 east, 1 north, ...) as an index."""
    return pose[:, 2].round().long().clamp(0, 3)


def _quarter_turns(heading: torch.Tensor) -> torch.Tensor:
    """Counter-clockwise quarter turns that bring ``heading`` (0 east, 1 north, ...) up."""
    return (1 - heading) % 4


def _rotated(grid: torch.Tensor) -> torch.Tensor:
    """``(4, n)``: ``grid`` (a square of values) turned 0..3 quarter turns, flattened.

    Gathering a flattened image at ``_rotated(arange)[k]`` turns the image
    ``k`` quarter turns counter-clockwise (``torch.rot90``'s convention).
    """
    return torch.stack([torch.rot90(grid, k).flatten() for k in range(4)])


WINDOW_KEYS = ("sensed", "swept", "known")  # the local windows, in this order where present


class SweeperEgocentric(BaseFeaturesExtractor):
    """The sweeper's observation in the robot's frame, through a small CNN.

    Inputs (see ``SweeperEnv``'s observation table), for a batch of ``B``:

    - local windows ``sensed``, ``swept`` and, where the observation has it
      (``Sweeper-v1``), ``known`` ``(S, S)`` around the footprint, turned
      ``(1 - heading) mod 4`` quarter turns counter-clockwise so that the
      heading points up (the footprint is at the window's centre, so the
      turn keeps it there): ``2 S^2`` or ``3 S^2`` features, flattened;
    - coarse maps ``sweep_map`` and ``obstacle_map`` ``(K, K)``: block
      ``(i, j)`` covers cells ``[i bh, (i+1) bh) x [j bw, (j+1) bw)`` with
      ``bh, bw = ceil(H / K), ceil(W / K)``. The robot's block is that of its
      believed footprint's top-left cell ``(pose[0] // bh, pose[1] // bw)``.
      The maps are re-sampled on a ``(2K - 1)^2`` grid centred on that block
      (any block of the map stays in view wherever the robot is), turned like
      the windows, with a third channel marking blocks outside the map (the
      others are 0 there): ``(3, 2K - 1, 2K - 1)`` through three 3x3
      stride-2 convolutions;
    - the believed pose: row and column over ``H`` and ``W``, the heading
      one-hot, the bump flag. Within a block the maps and, in swept floor,
      the windows are the same at every cell, so without the pose those cells
      look alike and a deterministic policy loops among them.

    The observation gives the robot's cell, not its block, and ``H, W`` are
    the map's, not the observation's: ``map_shape`` names them (the registered
    room is 30 x 40). A policy built with it is for maps of that size. The
    pose must reach the extractor raw (no VecNormalize on ``pose``).

    Output: ``features_dim`` features (ReLU of a linear layer over the
    concatenation).
    """

    def __init__(
        self,
        observation_space: spaces.Dict,
        map_shape: Sequence[int],
        features_dim: int = 64,
        channels: Sequence[int] = (16, 32, 32),
    ) -> None:
        super().__init__(observation_space, features_dim)
        shape = tuple(map_shape)
        if len(shape) != 2 or not all(isinstance(n, int) and n > 0 for n in shape):
            raise ValueError(f"map_shape must be two positive integers (H, W), got {map_shape!r}")
        if not channels or not all(isinstance(n, int) and n > 0 for n in channels):
            raise ValueError(f"channels must be positive integers, got {channels!r}")
        S = math.isqrt(observation_space["sensed"].shape[0])
        K = math.isqrt(observation_space["sweep_map"].shape[0])
        self.window_keys = tuple(k for k in WINDOW_KEYS if k in observation_space.spaces)
        self.K = K
        self.register_buffer("map_size", torch.tensor(shape, dtype=torch.float32))
        self.block = (-(-shape[0] // K), -(-shape[1] // K))  # (bh, bw), cells
        # Blocks holding map cells: rows [0, ceil(H / bh)), columns [0, ceil(W / bw)).
        self.n_blocks = (-(-shape[0] // self.block[0]), -(-shape[1] // self.block[1]))
        self.register_buffer("window_index", _rotated(torch.arange(S * S).reshape(S, S)))
        offsets = torch.arange(-(K - 1), K)
        rows, cols = torch.meshgrid(offsets, offsets, indexing="ij")
        self.register_buffer("row_offset", _rotated(rows))  # (4, (2K - 1)^2)
        self.register_buffer("col_offset", _rotated(cols))
        layers: list[nn.Module] = []
        in_channels, side = 3, 2 * K - 1
        for out_channels in channels:
            layers += [nn.Conv2d(in_channels, out_channels, 3, stride=2), nn.ReLU()]
            in_channels, side = out_channels, (side - 3) // 2 + 1
        if side < 1:
            raise ValueError(f"{len(channels)} stride-2 convolutions shrink a {2 * K - 1} map to 0")
        self.cnn = nn.Sequential(*layers, nn.Flatten())
        n_inputs = len(self.window_keys) * S * S + in_channels * side * side + 2 + 4 + 1
        self.head = nn.Sequential(nn.Linear(n_inputs, features_dim), nn.ReLU())

    def egocentric_maps(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        """``(B, 3, 2K - 1, 2K - 1)``: swept, obstacle and outside-the-map, robot-centred."""
        pose = observations["pose"].round().long()
        k = _quarter_turns(_heading(observations["pose"]))
        K, (bh, bw), (nr, nc) = self.K, self.block, self.n_blocks
        rr = (pose[:, :1] // bh).clamp(0, K - 1) + self.row_offset[k]  # (B, (2K - 1)^2)
        cc = (pose[:, 1:2] // bw).clamp(0, K - 1) + self.col_offset[k]
        inside = ((rr >= 0) & (rr < nr) & (cc >= 0) & (cc < nc)).float()
        index = rr.clamp(0, K - 1) * K + cc.clamp(0, K - 1)
        swept = observations["sweep_map"].gather(1, index) * inside
        obstacle = observations["obstacle_map"].gather(1, index) * inside
        side = 2 * K - 1
        return torch.stack([swept, obstacle, 1.0 - inside], 1).reshape(-1, 3, side, side)

    def egocentric_windows(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        """``(B, 2 or 3, S^2)``: the windows (sensed, swept, known) turned heading-up."""
        k = _quarter_turns(_heading(observations["pose"]))
        index = self.window_index[k]  # (B, S^2)
        return torch.stack([observations[key].gather(1, index) for key in self.window_keys], 1)

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        pose = observations["pose"]
        heading = nn.functional.one_hot(_heading(pose), 4)
        features = (
            self.egocentric_windows(observations).flatten(1),
            self.cnn(self.egocentric_maps(observations)),
            pose[:, :2] / self.map_size,
            heading.float(),
            pose[:, 3:],
        )
        return self.head(torch.cat(features, 1))


class SweeperMapPyramid(BaseFeaturesExtractor):
    """The sweeper's map memory (:mod:`motiongym.agents.map_memory`) through a small CNN.

    Inputs, for a batch of ``B``: the memory's crops ``(3 L, n, n)``
    (``todo``, ``obstacle``, ``unknown`` per pyramid level, robot-centred,
    heading up; the levels are concentric, so they are stacked as channels,
    as Active Neural SLAM stacks its local and global maps), through 3x3
    convolutions with padding 1 (``channels``, ReLU after each), flattened;
    and the bump flag (``pose[3]``). Nothing else of the observation is used:
    the crops hold the windows' content, filed in the map, and the robot's
    place in it (the centre); the pose's row and column do not enter, so the
    policy is the same wherever a situation occurs.

    Output: ``features_dim`` features (ReLU of a linear layer over the concatenation).
    """

    def __init__(
        self,
        observation_space: spaces.Dict,
        features_dim: int = 128,
        channels: Sequence[int] = (32, 32),
    ) -> None:
        super().__init__(observation_space, features_dim)
        if "memory" not in observation_space.spaces:
            raise ValueError(
                "sweeper_map_pyramid needs the map memory in the observation "
                "(a run with memory: sweeper_map)"
            )
        if not channels or not all(isinstance(n, int) and n > 0 for n in channels):
            raise ValueError(f"channels must be positive integers, got {channels!r}")
        depth, n, _ = observation_space["memory"].shape
        layers: list[nn.Module] = []
        for out_channels in channels:
            layers += [nn.Conv2d(depth, out_channels, 3, padding=1), nn.ReLU()]
            depth = out_channels
        self.cnn = nn.Sequential(*layers, nn.Flatten())
        self.head = nn.Sequential(nn.Linear(depth * n * n + 1, features_dim), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        features = (self.cnn(observations["memory"]), observations["pose"][:, 3:])
        return self.head(torch.cat(features, 1))


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
        n_obs = observation_space["observation"].shape[0]
        size = observation_space["desired_goal"].shape[0]
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


# Names a config may give ``features_extractor_class`` -> the class.
FEATURES_EXTRACTORS: dict[str, type[BaseFeaturesExtractor]] = {
    "sweeper_egocentric": SweeperEgocentric,
    "sweeper_map_pyramid": SweeperMapPyramid,
    "excavator_fields": ExcavatorFields,
    "harvest_obstacle_set": HarvestObstacleSet,
    "goal_error": GoalError,
}
