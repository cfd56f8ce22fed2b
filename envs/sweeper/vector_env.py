"""``motiongym/Sweeper-v0`` natively vectorised: N sweeper worlds stepped in NumPy."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.spaces.utils import flatdim
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from motiongym.envs.checks import check_num_envs, per_env
from motiongym.envs.core import (
    START,
    check_int,
    check_options,
    check_render_mode,
    zero_terms,
)
from motiongym.envs.sweeper import families, sight, task
from motiongym.envs.sweeper.env import SweeperEnv
from motiongym.envs.sweeper.measures import (
    INFO_KEYS,
    REWARD_TERMS,
    batch_info,
    is_success,
    measures,
    reward_terms,
)
from motiongym.envs.sweeper.occupancy import DC, DR
from motiongym.envs.sweeper.render import frame
from motiongym.envs.sweeper.state import SweeperState
from motiongym.envs.sweeper.vector_state import (
    COUNT,
    KNOWN,
    BatchedGrids,
    ObservationPool,
    check_actions,
    shift_windows,
    spread_info,
)

PROCEDURAL_SIDE = 56  # cells: the largest side of a procedural map (generator.random_map)
OVERHEAD_BYTES = 4096  # per sub-environment: its generator, scenario and path objects
WINDOW_KEYS = ("sensed", "swept", "known")  # the planes of the kept windows, in order
TURN = np.array([0, 1, 3], np.int64)  # heading change per action (forward, left, right) mod 4


def bytes_per_env(single: SweeperEnv) -> int:
    """An upper estimate of one sub-environment's memory, in bytes, for ``single``'s
    parameters: its map of ``H x W`` cells (a fixed map's, else a generated family's
    ``map_size``, else :data:`PROCEDURAL_SIDE` squared) padded by the sensor range
    ``R`` to ``L = (H + 2R) (W + 2R)`` cells in
    :class:`~motiongym.envs.sweeper.vector_state.BatchedGrids` (the sweep state and
    reachability, 2 bytes a cell; with procedural maps also the obstacle and int32
    block maps, 5 more), the scenario's four ``H x W`` bool maps, five float32 copies
    of the observation (the current one and the
    :class:`~motiongym.envs.sweeper.vector_state.ObservationPool`'s four), the four
    float32 ``K x K`` coarse maps, three ``S x S`` window planes and
    :data:`OVERHEAD_BYTES`."""
    p = single.params
    if single.fixed is not None:
        H, W = single.fixed.shape
    elif p.map_family is not None:
        H, W = families.check_size(p.map_size, p.robot_width)
    else:
        H, W = (PROCEDURAL_SIDE,) * 2
    R, K, S = p.sensor_range, p.coarse, p.window
    cells = (H + 2 * R) * (W + 2 * R)
    grids = (2 if single.fixed is not None else 7) * cells
    observation = 4 * flatdim(single.observation_space)  # float32
    return grids + 4 * H * W + 5 * observation + 16 * K * K + 3 * S * S + OVERHEAD_BYTES


def _one_start(value: Any) -> bool:
    """True for one ``start`` (None or a pair), False for a sequence of per-env starts."""
    if not isinstance(value, (list, tuple, np.ndarray)) or len(value) == 0:
        return True
    return not (value[0] is None or isinstance(value[0], (list, tuple, np.ndarray)))


def _one_value(value: Any) -> bool:
    """True for one value, False for a list, tuple or array of per-env values."""
    return not isinstance(value, (list, tuple, np.ndarray))


def _mask(name: str, mask: Any) -> Any:
    return mask  # checked in reset, where num_envs is known


class SweeperVectorEnv(VectorEnv):
    """N :class:`~motiongym.envs.sweeper.env.SweeperEnv` worlds in a few NumPy arrays.

    Step for step identical to ``gymnasium.vector.SyncVectorEnv`` over N
    ``gym.make("motiongym/Sweeper-v0" or "-v1", max_episode_steps=...)`` with
    ``autoreset_mode=AutoresetMode.SAME_STEP``: same observations (a dict of
    ``(N, ...)`` float32 arrays), rewards (float64), ``terminated``,
    ``truncated`` and ``info`` (each key an ``(N,)`` array with its ``_key``
    mask, dtypes as SyncVectorEnv builds them). The single environment's
    class docstring is the spec of observations, actions, rewards and info.

    ## Autoreset (same step, SB3's convention)
    A sub-environment that terminates or reaches ``max_episode_steps``
    (truncation is done here, as ``CartPoleVectorEnv`` does) is reset in the
    same ``step``: the returned observation and info are the new episode's;
    ``info["final_obs"]`` (object array, ``None`` where not done) and
    ``info["final_info"]`` (dict of arrays) with masks ``_final_obs`` /
    ``_final_info`` carry the finished episode's last observation and info.

    ## Seeding
    ``reset(seed=s)`` seeds sub-environment ``i`` with ``s + i`` (a list
    gives one seed per sub-environment) exactly as SyncVectorEnv does; each
    sub-environment keeps its own ``numpy.random.Generator`` for its later
    resets, drawing through the single environment's own
    :func:`motiongym.envs.sweeper.task.sample_scenario`, so every scenario
    (procedural map, start, heading) equals the separate environments' ones.
    ``reset(options=...)`` passes ``start`` / ``heading`` to every
    sub-environment (as SyncVectorEnv does), or, given a sequence of one per
    sub-environment (``start``: ``num_envs`` pairs or None; ``heading``:
    ``num_envs`` integers or None), value ``i`` to sub-environment ``i``; a
    sequence of another length is a ValueError naming the option.
    ``options={"reset_mask": mask}`` resets only the masked ones (per-env
    values are still indexed by sub-environment). A list of seeds must have
    ``num_envs`` entries.

    ## Layout and limits
    All sub-environments share one padded map shape (the largest map seen;
    see :mod:`motiongym.envs.sweeper.vector_state`). A fixed map is stored
    once. Odometry noise (``heading_noise``, ``slip_noise``) draws from each
    world's generator inside the step and is not batched: a non-zero value
    raises ValueError. Per-environment Python work happens only in resets.
    ``num_envs`` is an integer from 1 up to the memory bound: 4 GiB
    (:data:`~motiongym.envs.checks.VECTOR_MEMORY_BOUND`) over
    :func:`bytes_per_env`, the upper estimate of one sub-environment's memory
    for the parameters given (60 KiB, so 69,897 sub-environments, with the
    default parameters on procedural maps; 29 KiB on the shipped room). Anything
    else (0, negative, a float, beyond the bound) is a ValueError naming
    ``num_envs``, the value and the range. ``max_episode_steps`` is an
    integer >= 1; the other keywords are the single environment's, checked
    by :class:`~motiongym.envs.sweeper.params.SweeperParams`.

    ## Actions
    Exactly what ``action_space.contains`` accepts: a list or an array of
    shape ``(N,)`` whose dtype casts safely to int64, values 0..2; anything
    else a ValueError naming the space. ``state(i)`` gives sub-environment
    ``i``'s :class:`~motiongym.envs.sweeper.state.SweeperState`.

    ## Returned observations
    The arrays of a returned observation are never written while anyone
    holds them (a later step never changes an observation you keep, as with
    copies). Once dropped, their memory is reused for a later observation and
    only the changed parts are written
    (:class:`~motiongym.envs.sweeper.vector_state.ObservationPool`): copy an
    observation before modifying it in place, or set the class attribute
    ``recycle_observations = False`` for fresh arrays on every call.

    ``render()`` returns one frame per sub-environment (the robot's path is
    recorded only when ``render_mode="rgb_array"``).
    """

    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": 30,
        "autoreset_mode": AutoresetMode.SAME_STEP,
        "info_measures": dict(SweeperEnv.metadata["info_measures"]),
        "info_units": dict(SweeperEnv.metadata["info_units"]),
    }
    recycle_observations = True  # False: fresh observation arrays on every call (slower)

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int = 20_000,
        render_mode: str | None = None,
        **kwargs: Any,
    ) -> None:
        render_mode = check_render_mode(render_mode, self.metadata["render_modes"])
        max_episode_steps = check_int("max_episode_steps", max_episode_steps, 1)
        # The single environment validates the keywords and holds the spaces.
        self._single = single = SweeperEnv(render_mode=render_mode, **kwargs)
        self.params = p = single.params
        N = check_num_envs(num_envs, bytes_per_env(single))
        for name in ("heading_noise", "slip_noise"):
            if getattr(p, name):
                raise ValueError(
                    f"{name}={getattr(p, name)!r}: odometry noise is not batched in "
                    "SweeperVectorEnv; use SyncVectorEnv of SweeperEnv for noisy runs"
                )
        self.num_envs = N
        self.max_episode_steps = max_episode_steps
        self.render_mode = render_mode
        self.single_observation_space = single.observation_space
        self.observation_space = batch_space(single.observation_space, N)
        self.single_action_space = single.action_space
        self.action_space = batch_space(single.action_space, N)
        self.w, self.R, self.S, self.K = p.robot_width, p.sensor_range, p.window, p.coarse
        self._grids = BatchedGrids(N, self.w, self.R, self.K, single.fixed)

        i64 = np.int64
        self.r, self.c, self.h = np.zeros(N, i64), np.zeros(N, i64), np.zeros(N, i64)
        self.anchor = np.zeros(N, i64)  # r * Wp + c: window top-left in padded coordinates
        self.bump = np.zeros(N, bool)
        self.n_swept, self.n_over = np.zeros(N, i64), np.zeros(N, i64)
        self.turns, self.bumps, self.steps = np.zeros(N, i64), np.zeros(N, i64), np.zeros(N, i64)
        self.travel = np.zeros(N, np.float64)
        self.n_reach = np.ones(N, i64)
        self.inv_block = np.ones(N, np.float32)
        KK = self.K * self.K
        self.csw = np.zeros((N, KK), np.float32)  # coarse swept-cell counts
        self.cob = np.zeros((N, KK), np.float32)  # coarse known-obstacle counts
        self.sw_obs = np.zeros((N, KK), np.float32)  # csw * inv_block, kept current
        self.ob_obs = np.zeros((N, KK), np.float32)  # cob * inv_block, kept current
        S = self.S
        # v1's lines of sight (None: v0, the see-through window)
        self._rays = sight.ray_matrix(self.w, self.R) if p.line_of_sight else None
        planes = 2 if self._rays is None else 3
        self.win = np.zeros((N, planes, S, S), np.uint8)  # [sensed, swept, known (v1)], current
        self._rngs: list[np.random.Generator | None] = [None] * N
        self._scenarios: list[task.Scenario | None] = [None] * N
        self._paths: list[list[tuple[int, int]]] = [[] for _ in range(N)]
        self._pool = ObservationPool(self.observation_space, 4 if self.recycle_observations else 0)
        self._ready = False

    # ------------------------------------------------------------------ reset
    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict | None = None
    ) -> tuple[dict, dict]:
        N = self.num_envs
        if seed is None or isinstance(seed, (int, np.integer)):
            if seed is not None:
                super().reset(seed=int(seed))
            seeds = [None if seed is None else int(seed) + i for i in range(N)]
        else:
            seeds = list(seed)
            if len(seeds) != N:
                raise ValueError(
                    f"seed must be an integer, None or a list of num_envs={N} seeds, "
                    f"got {len(seeds)} seeds: {seed!r}"
                )
        options = check_options(options, {**self._per_env_options, "reset_mask": _mask})
        mask = options.pop("reset_mask", None)
        if mask is None:
            idx = np.arange(N)
        else:
            mask = np.asarray(mask)
            if mask.shape != (N,) or mask.dtype != np.bool_ or not mask.any():
                raise ValueError(
                    f"options['reset_mask'] must be a bool array of shape ({N},) with a True, "
                    f"got shape {mask.shape}, dtype {mask.dtype}: {mask!r}"
                )
            if not self._ready:
                raise RuntimeError("call reset() without reset_mask first")
            idx = np.flatnonzero(mask)
        self._reset_envs(idx, [seeds[i] for i in idx], options)
        self._ready = True
        info = self._info(idx, zero_terms(REWARD_TERMS), np.zeros(len(idx), bool))
        if mask is not None:
            info = spread_info(info, idx, N)
        self._pool.record(None)
        return self._observation(), info

    @property
    def _per_env_options(self) -> dict[str, Any]:
        """The reset options' checks: one value for every sub-environment, or a list of
        one per sub-environment (see the class docstring); each returns the list."""
        N = self.num_envs

        def start(name: str, value: Any) -> list:
            return per_env(name, value, N, _one_start, task.OPTIONS[START])

        def heading(name: str, value: Any) -> list:
            return per_env(name, value, N, _one_value, task.OPTIONS["heading"])

        return {START: start, "heading": heading}

    def _reset_envs(self, idx: np.ndarray, seeds: list, options: dict[str, list]) -> None:
        """Sample and load new episodes for sub-environments ``idx`` (Python per world);
        ``options``: each reset option's list of one value per sub-environment."""
        single, g = self._single, self._grids
        scenarios = []
        for i, s in zip(idx.tolist(), seeds, strict=True):
            if s is not None or self._rngs[i] is None:
                self._rngs[i] = seeding.np_random(s)[0]
            own = {key: values[i] for key, values in options.items()}
            sc = single.task.sample(self._rngs[i], own)
            scenarios.append(sc)
        shape = np.array([sc.obstacle.shape for sc in scenarios]).max(axis=0)
        if g.ensure(int(shape[0]), int(shape[1])):
            self.anchor[:] = self.r * g.Wp + self.c
        w, K, S = self.w, self.K, self.S
        one = np.float32(1.0)
        for i, sc in zip(idx.tolist(), scenarios, strict=True):
            self._scenarios[i] = sc
            H, W = sc.obstacle.shape
            g.load(i, sc.obstacle, sc.reach_configs)
            r, c = sc.start
            self.r[i], self.c[i], self.h[i] = r, c, sc.heading
            a = self.anchor[i] = r * g.Wp + c
            self.inv_block[i] = inv = np.float32(1.0 / ((-(-H // K)) * (-(-W // K))))
            self.n_reach[i] = int(sc.reachable.sum())
            self.n_swept[i], self.n_over[i] = w * w, 0
            self.turns[i] = self.bumps[i] = self.steps[i] = 0
            self.travel[i], self.bump[i] = 0.0, False
            self._paths[i] = [(r, c)]
            # Footprint swept, the whole window sensed (as SweeperEnv.reset).
            m = 0 if g.shared is not None else i
            foot, win = a + g.foot_off, a + g.win_off
            g.cell[i, foot] = 1
            self.csw[i] = 0.0
            np.add.at(self.csw[i], g.block[m, foot], one)
            obst = g.obst[m, win]
            if self._rays is not None:
                vis = sight.visible(obst, self._rays)
                obst = obst & vis
                self.win[i, 2] = vis.reshape(S, S)
            g.cell[i, win[obst]] |= KNOWN
            seen = g.block[m, win[obst]]
            self.cob[i] = 0.0
            np.add.at(self.cob[i], seen[seen >= 0], one)
            self.sw_obs[i] = self.csw[i] * inv
            self.ob_obs[i] = self.cob[i] * inv
            self.win[i, 0] = obst.reshape(S, S)
            self.win[i, 1] = (g.cell[i, win] & COUNT).reshape(S, S) > 0

    # ------------------------------------------------------------------- step
    def step(self, actions: Any) -> tuple[dict, np.ndarray, np.ndarray, np.ndarray, dict]:
        if not self._ready:
            raise RuntimeError("call reset() before step()")
        a = check_actions(actions, self.num_envs)
        g, N, L = self._grids, self.num_envs, self._grids.L
        self.steps += 1
        fwd = np.flatnonzero(a == 0)
        hf = self.h[fwd]
        na = self.anchor[fwd] + g.delta[hf]
        ok = g.reach.ravel()[fwd * L + na]
        bump = np.zeros(N, bool)
        bump[fwd[~ok]] = True
        self.bump = bump
        self.bumps += bump
        self.turns += a != 0
        self.h = (self.h + TURN[a]) & 3
        new = np.zeros(N, np.int64)
        changes: dict[str, list[np.ndarray]] = {"rows": [], "reset": [], "sweep": [], "obst": []}
        if ok.any():
            moved, count = self._move(fwd[ok], hf[ok], na[ok], changes)
            new[moved] = count
        terms = reward_terms(new, bump, self.params)
        reward = terms["sweep"] + terms["time"] + terms["bump"]
        terminated = is_success(self.n_swept, self.n_reach)
        truncated = self.steps >= self.max_episode_steps
        info = self._info(slice(None), terms, bump)
        self._pool.record(changes)
        obs = self._observation()
        done = terminated | truncated
        if done.any():
            self._autoreset(np.flatnonzero(done), done, obs, info, changes)
        return obs, reward, terminated, truncated, info

    def _move(
        self, moved: np.ndarray, hm: np.ndarray, am: np.ndarray, changes: dict
    ) -> tuple[np.ndarray, np.ndarray]:
        """Move the worlds ``moved`` one cell along ``hm`` to anchors ``am``; sweep, sense.

        Returns the worlds (reordered by heading) and their newly swept cell counts.
        """
        g, L, KK = self._grids, self._grids.L, self.K * self.K
        order = np.argsort(hm.astype(np.int8), kind="stable")  # group by heading
        moved, hm, am = moved[order], hm[order], am[order]
        self.anchor[moved] = am
        self.r[moved] += DR[hm]
        self.c[moved] += DC[hm]
        self.travel[moved] += 1.0
        at_map = (g.map_base[moved] + am)[:, None]  # (M, 1) anchor in obst / block
        at_cell = (moved * L + am)[:, None]  # (M, 1) anchor in cell
        cell = g.cell.ravel()
        # Sweep the w cells entering the footprint (counts saturate at 2).
        enter = g.enter_off[hm]  # (M, w)
        cells = at_cell + enter
        before = cell[cells]
        count = before & COUNT
        cell[cells] = before + (count < 2)
        fresh = count == 0
        new = np.einsum("ij->i", fresh.view(np.uint8))  # row sums of small (M, w)
        self.n_swept[moved] += new
        self.n_over[moved] += np.einsum("ij->i", (count == 1).view(np.uint8))
        if new.any():
            ri, ci = np.nonzero(fresh)
            env = moved[ri]
            target = env * KK + g.block.ravel()[at_map[ri, 0] + enter[ri, ci]]
            self._count(self.csw, self.sw_obs, env, target)
            changes["sweep"].append(target)
        if self._rays is not None:
            self._sense_window(moved, at_map[:, 0], at_cell[:, 0], changes)
        else:
            self._sense_edge(moved, hm, at_map, at_cell, changes)
        changes["rows"].append(moved)
        if self.render_mode is not None:
            rows, cols = self.r[moved].tolist(), self.c[moved].tolist()
            for i, r, c in zip(moved.tolist(), rows, cols, strict=True):
                self._paths[i].append((r, c))
        return moved, new

    def _sense_window(
        self, moved: np.ndarray, at_map: np.ndarray, at_cell: np.ndarray, changes: dict
    ) -> None:
        """v1: sense the whole window of the worlds ``moved`` through lines of sight."""
        g, S = self._grids, self.S
        obst = g.obst.ravel()[at_map[:, None] + g.win_off]  # (M, S*S)
        vis = sight.visible(obst, self._rays)
        obst &= vis
        where = at_cell[:, None] + g.win_off
        state = g.cell.ravel()[where]
        seen = obst & (state < KNOWN)
        if seen.any():
            ri, ci = np.nonzero(seen)
            cells, maps = where[ri, ci], at_map[ri] + g.win_off[ci]
            self._file_obstacles(moved[ri], cells, maps, state[ri, ci], changes)
        M = len(moved)
        self.win[moved] = np.stack([obst, (state & COUNT) != 0, vis], axis=1).reshape(M, 3, S, S)

    def _sense_edge(
        self, moved: np.ndarray, hm: np.ndarray, at_map: np.ndarray, at_cell: np.ndarray, changes
    ) -> None:
        """v0: sense the window's leading edge (the only cells new to it); shift the windows."""
        g = self._grids
        edge = g.edge_off[hm]  # (M, S)
        obst = g.obst.ravel()[at_map + edge]
        state = g.cell.ravel()[at_cell + edge]
        seen = obst & (state < KNOWN)
        if seen.any():
            ri, ci = np.nonzero(seen)
            e = edge[ri, ci]
            self._file_obstacles(
                moved[ri], at_cell[ri, 0] + e, at_map[ri, 0] + e, state[ri, ci], changes
            )
        fill = np.stack([obst, (state & COUNT) != 0], axis=1)  # (M, 2, S)
        self.win[moved] = shift_windows(self.win[moved], fill, hm, g.enter_win)

    def _file_obstacles(
        self, env: np.ndarray, cells: np.ndarray, maps: np.ndarray, state: np.ndarray, changes
    ) -> None:
        """Mark sensed obstacles known: flat ``cells`` of ``g.cell`` (previous ``state``),
        flat ``maps`` of ``g.block``, of worlds ``env``; count them in the coarse maps."""
        g = self._grids
        g.cell.ravel()[cells] = state | KNOWN
        blocks = g.block.ravel()[maps]
        inside = blocks >= 0
        env = env[inside]
        target = env * (self.K * self.K) + blocks[inside]
        self._count(self.cob, self.ob_obs, env, target)
        changes["obst"].append(target)

    def _count(
        self, counts: np.ndarray, scaled: np.ndarray, env: np.ndarray, target: np.ndarray
    ) -> None:
        """Add one to coarse ``counts`` at flat ``target`` of worlds ``env``; rescale."""
        flat = counts.ravel()
        np.add.at(flat, target, np.ones(len(target), np.float32))  # repeats add up
        scaled.ravel()[target] = flat[target] * self.inv_block[env]

    def _autoreset(
        self, di: np.ndarray, done: np.ndarray, obs: dict, info: dict, changes: dict
    ) -> None:
        """Same-step autoreset of worlds ``di``: final obs/info, then their new episodes."""
        final_obs = np.full(self.num_envs, None, dtype=object)
        for i in di.tolist():
            final_obs[i] = {key: value[i].copy() for key, value in obs.items()}
        final_info: dict[str, Any] = {}
        for key in INFO_KEYS:
            arr = np.zeros_like(info[key])
            arr[di] = info[key][di]
            final_info[key], final_info[f"_{key}"] = arr, done.copy()
        self._reset_envs(di, [None] * len(di), {})
        changes["reset"].append(di)
        fresh = self._info(di, zero_terms(REWARD_TERMS), np.zeros(len(di), bool))
        for key in INFO_KEYS:
            info[key][di] = fresh[key]
        for key, value in self._observation(di).items():
            obs[key][di] = value
        info["final_obs"], info["_final_obs"] = final_obs, done.copy()
        info["final_info"], info["_final_info"] = final_info, done.copy()

    # ---------------------------------------------------------------- outputs
    def _observation(self, idx: np.ndarray | None = None) -> dict:
        """Observation of worlds ``idx`` (fresh arrays), or of all (pooled arrays)."""
        N, SS = self.num_envs, self.S * self.S
        if idx is not None:
            pose = np.stack([self.r[idx], self.c[idx], self.h[idx], self.bump[idx]], axis=1)
            obs = {
                key: self.win[idx, k].reshape(-1, SS).astype(np.float32)
                for k, key in enumerate(WINDOW_KEYS[: self.win.shape[1]])
            }
            obs.update(pose=pose.astype(np.float32), sweep_map=self.sw_obs[idx])
            obs["obstacle_map"] = self.ob_obs[idx]
            return obs
        out, missing = self._pool.take()
        pose = out["pose"]
        pose[:, 0], pose[:, 1], pose[:, 2], pose[:, 3] = self.r, self.c, self.h, self.bump
        if missing is None:  # copy whole
            for k, key in enumerate(WINDOW_KEYS[: self.win.shape[1]]):
                np.copyto(out[key], self.win[:, k].reshape(N, SS))
            np.copyto(out["sweep_map"], self.sw_obs)
            np.copyto(out["obstacle_map"], self.ob_obs)
            return dict(out)
        parts = {key: [a for c in missing for a in c[key]] for key in missing[0]} if missing else {}
        if parts.get("rows") or parts.get("reset"):
            rows = np.concatenate(parts["rows"] + parts["reset"])
            for k, key in enumerate(WINDOW_KEYS[: self.win.shape[1]]):
                out[key][rows] = self.win[rows, k].reshape(-1, SS)
        for key, src in (("sweep", self.sw_obs), ("obst", self.ob_obs)):
            dst = out["sweep_map" if key == "sweep" else "obstacle_map"]
            if parts.get(key):
                flat = np.concatenate(parts[key])
                dst.ravel()[flat] = src.ravel()[flat]
            if parts.get("reset"):
                rows = np.concatenate(parts["reset"])
                dst[rows] = src[rows]
        return dict(out)

    def _info(self, idx: Any, terms: dict[str, Any], bump: np.ndarray) -> dict:
        counters = (self.n_swept, self.n_reach, self.n_over, self.travel, self.turns)
        n_swept, n_reach, n_over, travel, turns, bumps, steps = (
            a[idx] for a in (*counters, self.bumps, self.steps)
        )
        success = is_success(n_swept, n_reach)
        done = measures(n_swept, n_reach, n_over, travel, turns, bumps, steps, self.w)
        info = batch_info(success, bump, terms, **done)
        mask = np.ones(len(info["coverage"]), bool)
        for key in INFO_KEYS:
            info[f"_{key}"] = mask.copy()
        return info

    # ----------------------------------------------------------------- render
    def state(self, i: int) -> SweeperState:
        """Sub-environment ``i``'s state, as the single environment holds it.

        Without odometry noise the believed pose is the true one; sweep counts
        stop at 2 (the twin stores no more); ``path`` is recorded only when
        ``render_mode="rgb_array"``.
        """
        if not self._ready:
            raise RuntimeError("call reset() before state()")
        g, P = self._grids, self.R
        sc = self._scenarios[i]
        assert sc is not None, "reset() sets every sub-environment's scenario"
        H, W = sc.obstacle.shape
        cell = g.cell[i].reshape(g.Hp, g.Wp)[: H + 2 * P, : W + 2 * P]
        r, c = int(self.r[i]), int(self.c[i])
        K = self.K
        return SweeperState(
            scenario=sc,
            row=r,
            col=c,
            heading=int(self.h[i]),
            believed_row=r,
            believed_col=c,
            y=float(r),
            x=float(c),
            heading_error=0.0,
            sweeps=(cell[P : P + H, P : P + W] & COUNT).astype(np.int32),
            believed_swept=((cell & COUNT) > 0).astype(np.float32),
            known_obstacles=(cell & KNOWN) > 0,
            coarse_swept=self.csw[i].reshape(K, K).copy(),
            coarse_obstacles=self.cob[i].reshape(K, K).copy(),
            window=self.win[i, 0].astype(np.float32),
            visible=None if self._rays is None else self.win[i, 2].astype(np.float32),
            n_reachable=int(self.n_reach[i]),
            n_swept=int(self.n_swept[i]),
            n_overswept=int(self.n_over[i]),
            turns=int(self.turns[i]),
            bumps=int(self.bumps[i]),
            steps=int(self.steps[i]),
            travel=float(self.travel[i]),
            bump=bool(self.bump[i]),
            path=list(self._paths[i]),
        )

    # Gymnasium types the frames with a TypeVar bound to no class argument: no concrete
    # return type matches it.
    def render(self) -> tuple[np.ndarray, ...] | None:  # type: ignore[override]
        if self.render_mode != "rgb_array" or not self._ready:
            return None
        p = self.params
        return tuple(
            frame(self.state(i), self.w, p.render_size, p.cell_pixels) for i in range(self.num_envs)
        )
