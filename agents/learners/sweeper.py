"""The sweeper's learner-side features: its own map as a memory (``sweeper_map``), and two
features extractors (``sweeper_egocentric``, ``sweeper_map_pyramid``).

**The map memory.** The sweeper's observation (``SweeperEnv``) holds the
believed ``pose`` and the ``sensed`` / ``known`` / ``swept`` windows every
step, and only coarse summaries of the robot's whole map (``K x K`` blocks
holding fractions), in which one or two unswept cells left in a block are a
small change that does not say where they are. The full-resolution maps can
be built from the observation stream, exactly as the scripted policies build
theirs (:class:`~motiongym.baselines.sweeper.belief.RobotMap`);
:class:`SweeperMapMemory` builds them for a learner and presents them as an
egocentric map memory, the representation of Chaplot et al. 2020 (Active
Neural SLAM, ICLR: a map built from the agent's own observations, cropped
around the agent and turned to its heading), with a multi-scale pyramid.

Channels, from the robot's map (unknown counted free, as the scripted
policies do), in the cells of a crop:

- ``todo``: floor the robot still has to sweep: a cell sensed free, not
  swept, and inside the footprint of some *open* configuration (one whose
  ``w x w`` footprint holds no known obstacle; a free cell no footprint fits
  over is not part of the task). Unknown cells are not ``todo``: beyond the
  outer wall they stay unknown for ever, and with line-of-sight sensing every
  reachable cell is sensed free before it is swept;
- ``obstacle``: a known obstacle cell;
- ``unknown``: a cell never sensed.

Pyramid: level ``k`` (0 .. ``levels - 1``) is an ``n x n`` grid
(``n = crop``) of blocks of ``b^k x b^k`` cells (``b = factor``), centred on
the footprint's centre cell, so level ``k`` sees ``n b^k`` cells across.
Level 0 is the cells themselves; at coarser levels each channel holds its
fraction over the block's cells (a single leftover cell reads ``1 / b^2k``:
unlike the environment's world-aligned coarse maps, whose blocks are fixed,
these move with the robot and grow with the distance, so the cell is seen
sharper as the robot nears it). Cells outside the arrays count as unknown.
Every level is turned ``(1 - heading) mod 4`` quarter turns
counter-clockwise, so that the heading points up (as
:class:`SweeperEgocentric` turns the windows). With an even ``w`` the
footprint has no centre cell; the crop is then centred on the cell below and
right of its centre.

The memory is a function of the observations of the episode so far (it
never reads the world): :class:`MapMemoryWrapper` adds it to a training
environment's observation (key :data:`MEMORY_KEY`), and
:class:`~motiongym.agents.learners.memory.MapMemoryPredictor` adds it for a
trained model in evaluation (see :mod:`motiongym.agents.learners.memory`).

**The extractors.** :class:`SweeperEgocentric` re-frames the observation
around the robot: the environment's windows and coarse maps are
world-aligned (row 0 north), so the same situation (a swept lane on the
left, a wall ahead) reads differently for each heading and position, and an
MLP has to learn it once per pose. Here every input is turned so that the
robot's heading points up, and the coarse maps are shifted so that the
robot's block is at the centre. It is a pure function of the current
observation: the policy sees what the scripted policies see, in another
frame, and remembers nothing. :class:`SweeperMapPyramid` reads the map
memory's crops.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from motiongym.agents.learners import entry_shape
from motiongym.agents.learners.memory import MemoryWrapper
from motiongym.baselines.sweeper.belief import FREE, OBSTACLE, UNKNOWN, RobotMap
from motiongym.envs.core import ArgumentError, check_int, check_keys
from motiongym.envs.sweeper.occupancy import config_free, footprint_union

MEMORY_KEY = "memory"
CHANNELS = ("todo", "obstacle", "unknown")  # per level, in this order


def check_sweeper_map_kwargs(kwargs: dict[str, Any]) -> dict[str, Any]:
    """The pyramid's settings (``levels``, ``crop``, ``factor``) checked, defaults
    filled in; an unknown key or a bad value is an ``ArgumentError``."""
    settings = {"levels": 3, "crop": 11, "factor": 3}
    settings.update(check_keys("memory_kwargs", kwargs, settings))
    check_int("memory_kwargs.levels", settings["levels"], 1, 4)
    check_int("memory_kwargs.crop", settings["crop"], 3, 31)
    check_int("memory_kwargs.factor", settings["factor"], 1, 9)
    for key in ("crop", "factor"):
        if settings[key] % 2 == 0:  # blocks centred on the robot's cell
            raise ArgumentError(f"memory_kwargs.{key} must be odd, got {settings[key]}")
    return settings


def _window(array: np.ndarray, top: int, left: int, side: int, fill: Any) -> np.ndarray:
    """``array[top:top + side, left:left + side]``, with ``fill`` where it leaves the array."""
    out = np.full((side, side), fill, array.dtype)
    r0, c0 = max(top, 0), max(left, 0)
    r1, c1 = min(top + side, array.shape[0]), min(left + side, array.shape[1])
    if r1 > r0 and c1 > c0:
        out[r0 - top : r1 - top, c0 - left : c1 - left] = array[r0:r1, c0:c1]
    return out


class SweeperMapMemory:
    """One episode's map, and the pyramid of crops it shows (see the module docstring).

    Args:
        robot_width: ``w`` (cells).
        sensor_range: ``R`` (cells beyond the footprint; the windows are ``w + 2R``).
        levels, crop, factor: the pyramid (:func:`check_sweeper_map_kwargs`).
    """

    def __init__(self, robot_width: int, sensor_range: int, **kwargs: Any) -> None:
        settings = check_sweeper_map_kwargs(kwargs)
        self.w, self.R = int(robot_width), int(sensor_range)
        self.levels, self.crop = settings["levels"], settings["crop"]
        self.factor = settings["factor"]
        self.side = self.crop * self.factor ** (self.levels - 1)  # cells across the top level
        self.shape = (len(CHANNELS) * self.levels, self.crop, self.crop)
        self.map = RobotMap(self.w, self.R)

    @classmethod
    def for_env(cls, env: gym.Env, **kwargs: Any) -> SweeperMapMemory:
        """The memory for a sweeper environment (its robot width and window)."""
        space = env.observation_space
        params = getattr(env.unwrapped, "params", None)
        if not isinstance(space, spaces.Dict) or "sensed" not in space.spaces or params is None:
            raise ValueError(f"the sweeper_map memory needs a sweeper environment, got {env}")
        w = int(params.robot_width)
        S = int(round(np.sqrt(entry_shape(space, "sensed")[0])))
        return cls(w, (S - w) // 2, **kwargs)

    def space(self, observation_space: spaces.Dict) -> spaces.Dict:
        """The environment's observation space with the memory's entry added."""
        if MEMORY_KEY in observation_space.spaces:
            raise ValueError(f"the observation already has a {MEMORY_KEY!r} entry")
        memory = spaces.Box(0.0, 1.0, self.shape, np.float32)
        return spaces.Dict({**observation_space.spaces, MEMORY_KEY: memory})

    def reset(self) -> None:
        """Forget the episode: an empty map."""
        self.map = RobotMap(self.w, self.R)

    def observe(self, observation: dict[str, Any]) -> dict[str, Any]:
        """File ``observation`` in the map; return it with the crops added."""
        r, c, h, _ = self.map.integrate(observation)
        return {**observation, MEMORY_KEY: self.crops(r, c, h)}

    def channels(self, top: int, left: int, side: int) -> np.ndarray:
        """``(3, side, side)`` float: todo, obstacle, unknown over map cells
        ``[top, top + side) x [left, left + side)``."""
        o, w = self.map.off, self.w
        pad = side + 2 * w  # open configurations need the footprints around the region
        occ = _window(self.map.occ, top - w + o, left - w + o, pad, UNKNOWN)
        swept = _window(self.map.swept, top - w + o, left - w + o, pad, False)
        obstacle = occ == OBSTACLE
        coverable = footprint_union(config_free(obstacle, w), w)
        todo = (occ == FREE) & ~swept & coverable
        inner = slice(w, w + side)
        stack = np.stack([todo, obstacle, occ == UNKNOWN])[:, inner, inner]
        return stack.astype(np.float32)

    def crops(self, r: int, c: int, h: int) -> np.ndarray:
        """``(3 levels, crop, crop)``: the pyramid around footprint ``(r, c)``, heading ``h`` up."""
        half = self.side // 2
        centre_r, centre_c = r + self.w // 2, c + self.w // 2
        cells = self.channels(centre_r - half, centre_c - half, self.side)
        n, out = self.crop, []
        for level in range(self.levels):
            block = self.factor**level
            start = (self.side - n * block) // 2
            region = cells[:, start : start + n * block, start : start + n * block]
            out.append(region.reshape(len(CHANNELS), n, block, n, block).mean((2, 4)))
        pyramid = np.concatenate(out)
        return np.ascontiguousarray(np.rot90(pyramid, (1 - h) % 4, axes=(1, 2)))


class MapMemoryWrapper(MemoryWrapper):
    """A sweeper environment whose observations carry the map memory (reset with it)."""

    memory_class = SweeperMapMemory
    check_kwargs = staticmethod(check_sweeper_map_kwargs)


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

    # buffers (register_buffer)
    map_size: torch.Tensor
    window_index: torch.Tensor
    row_offset: torch.Tensor
    col_offset: torch.Tensor

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
        S = math.isqrt(entry_shape(observation_space, "sensed")[0])
        K = math.isqrt(entry_shape(observation_space, "sweep_map")[0])
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
    """The sweeper's map memory (:class:`SweeperMapMemory`) through a small CNN.

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
        depth, n, _ = entry_shape(observation_space, "memory")
        layers: list[nn.Module] = []
        for out_channels in channels:
            layers += [nn.Conv2d(depth, out_channels, 3, padding=1), nn.ReLU()]
            depth = out_channels
        self.cnn = nn.Sequential(*layers, nn.Flatten())
        self.head = nn.Sequential(nn.Linear(depth * n * n + 1, features_dim), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        features = (self.cnn(observations["memory"]), observations["pose"][:, 3:])
        return self.head(torch.cat(features, 1))


# Names a config may give ``memory`` -> the wrapper that adds it in training.
MEMORIES: dict[str, type[MemoryWrapper]] = {"sweeper_map": MapMemoryWrapper}

# Names a config may give ``features_extractor_class`` -> the class.
FEATURES_EXTRACTORS: dict[str, type[BaseFeaturesExtractor]] = {
    "sweeper_egocentric": SweeperEgocentric,
    "sweeper_map_pyramid": SweeperMapPyramid,
}
