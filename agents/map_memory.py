"""Learner-side memories (``memory:`` in a config): the sweeper's own map, shown as
robot-centred crops (below), and the dual-arm cell's lag map
(:mod:`motiongym.agents.dual_arm_map`, ``dual_arm_map``).

The sweeper's observation (``SweeperEnv``) holds the believed ``pose`` and
the ``sensed`` / ``known`` / ``swept`` windows every step, and only coarse
summaries of the robot's whole map (``K x K`` blocks holding fractions). A
memoryless policy that sees one or two unswept cells left in a block as a
change of 1/6 cannot tell where they are (docs/experiments/Sweeper-v1.md,
"From demonstrations"). The full-resolution maps can be built from the
observation stream, exactly as the scripted policies build theirs
(:class:`~motiongym.baselines.sweeper.belief.RobotMap`); this module builds
them for a learner and presents them as an egocentric map memory, the
representation of Chaplot et al. 2020 (Active Neural SLAM, ICLR: a map
built from the agent's own observations, cropped around the agent and
turned to its heading), with a multi-scale pyramid.

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
sharper as the robot nears it). Max pooling of ``todo`` (a block with one
cell left reads 1) was tried and measured no better on the room
(docs/experiments/Sweeper-v1.md), so it is not offered. Cells outside the
arrays count as unknown. Every level is turned
``(1 - heading) mod 4`` quarter turns counter-clockwise, so that the heading
points up (as :class:`~motiongym.agents.features.SweeperEgocentric` turns the
windows). With an even ``w`` the footprint has no centre cell; the crop is
then centred on the cell below and right of its centre.

The memory is a function of the observations of the episode so far (it
never reads the world): :class:`MapMemoryWrapper` adds it to a training
environment's observation (key :data:`MEMORY_KEY`), and
:class:`MapMemoryPredictor` adds it for a trained model in evaluation, from
the same observation stream, reset by ``episode_start``. A run's
``config.yml`` names it (``memory: sweeper_map``, ``memory_kwargs``), and
:func:`motiongym.agents.predictors.load_model` puts the predictor in front
of a model trained with it.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.agents.dual_arm_map import DualArmMapMemory, check_dual_arm_map_kwargs
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
        S = int(round(np.sqrt(space["sensed"].shape[0])))
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


class MemoryWrapper(gym.ObservationWrapper):
    """An environment whose observations carry a learner-side memory (reset with it);
    subclasses name the memory class (``for_env``, ``space``, ``reset``, ``observe``) and
    its settings' check (``check_kwargs``, defaults filled in).
    ``raw_observation`` is the environment's own last observation (what a scripted
    teacher reads)."""

    memory_class: Any = None
    check_kwargs: Any = None

    def __init__(self, env: gym.Env, **memory_kwargs: Any) -> None:
        super().__init__(env)
        self.memory = self.memory_class.for_env(env, **memory_kwargs)
        self.observation_space = self.memory.space(env.observation_space)

    def reset(self, **kwargs: Any) -> tuple[Any, dict]:
        self.memory.reset()
        return super().reset(**kwargs)

    def observation(self, observation: Any) -> Any:
        self.raw_observation = observation  # the environment's own, for a DAgger teacher
        return self.memory.observe(observation)


class MapMemoryWrapper(MemoryWrapper):
    """A sweeper environment whose observations carry the map memory (reset with it)."""

    memory_class = SweeperMapMemory
    check_kwargs = staticmethod(check_sweeper_map_kwargs)


class DualArmMapWrapper(MemoryWrapper):
    """A dual-arm environment seen through the lag map (:mod:`motiongym.agents.dual_arm_map`)."""

    memory_class = DualArmMapMemory
    check_kwargs = staticmethod(check_dual_arm_map_kwargs)


class MapMemoryPredictor:
    """A model trained on a :class:`MemoryWrapper`'s observations, acting in the bare
    environment: it builds the same memory from the observations it is given.

    One memory per sub-environment (observations may come batched, with a
    leading axis); a sub-environment's memory is emptied where ``episode_start``
    is true (without ``episode_start`` it persists from call to call, as a
    scripted policy's does). Keywords after ``deterministic`` (the action
    masks) go to the model unchanged. ``memory``: a name of :data:`MEMORIES`.
    """

    def __init__(self, model: Any, env: gym.Env, memory: str = "sweeper_map", **memory_kwargs):
        self.model = model
        memory_class = MEMORIES[memory].memory_class
        self.make = lambda: memory_class.for_env(env, **memory_kwargs)
        space = env.observation_space
        self.key = next(iter(space.spaces)) if isinstance(space, spaces.Dict) else None
        self.rank = len((space[self.key] if self.key else space).shape)
        self.memories: list[Any] = []

    def predict(self, observation, state=None, episode_start=None, deterministic=True, **kwargs):
        first = observation[self.key] if self.key else observation
        batched = np.ndim(first) > self.rank
        n = len(first) if batched else 1
        if len(self.memories) != n:
            self.memories = [self.make() for _ in range(n)]
        starts = np.zeros(n, bool)
        if episode_start is not None:
            starts |= np.asarray(episode_start, dtype=bool).reshape(-1)
        seen = []
        for i, memory in enumerate(self.memories):
            if starts[i]:
                memory.reset()
            if not batched:
                one = observation
            elif self.key:
                one = {k: v[i] for k, v in observation.items()}
            else:
                one = observation[i]
            seen.append(memory.observe(one))
        if not batched:
            observation = seen[0]
        elif self.key:
            observation = {k: np.stack([s[k] for s in seen]) for k in seen[0]}
        else:
            observation = np.stack(seen)
        return self.model.predict(observation, state, episode_start, deterministic, **kwargs)


# Names a config may give ``memory`` -> the wrapper that adds it in training.
MEMORIES: dict[str, type[MemoryWrapper]] = {
    "sweeper_map": MapMemoryWrapper,
    "dual_arm_map": DualArmMapWrapper,
}


def check_memory_kwargs(kwargs: dict[str, Any], memory: str = "sweeper_map") -> dict[str, Any]:
    """``memory``'s settings checked, defaults filled in (an ``ArgumentError`` if bad)."""
    return MEMORIES[memory].check_kwargs(kwargs)
