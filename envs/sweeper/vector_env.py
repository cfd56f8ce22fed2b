"""``motiongym/Sweeper-v0`` natively vectorised: N sweeper worlds stepped in NumPy."""

from __future__ import annotations

import sys
from types import SimpleNamespace
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from motiongym.envs.sweeper import task
from motiongym.envs.sweeper.env import SweeperEnv
from motiongym.envs.sweeper.vector_state import BatchedGrids
from motiongym.envs.sweeper.world import DC, DR

TURN = np.array([0, 1, 3], np.int64)  # heading change per action (forward, left, right) mod 4
INFO_KEYS = (
    "is_success",
    "cost",
    "coverage",
    "travel",
    "travel_ratio",
    "overlap",
    "turns",
    "bumps",
    "steps",
    "reward_sweep",
    "reward_time",
    "reward_bump",
)


class SweeperVectorEnv(VectorEnv):
    """N :class:`~motiongym.envs.sweeper.env.SweeperEnv` worlds in a few NumPy arrays.

    Step for step identical to ``gymnasium.vector.SyncVectorEnv`` over N
    ``gym.make("motiongym/Sweeper-v0", max_episode_steps=...)`` with
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
    sub-environment (as SyncVectorEnv does); ``options={"reset_mask": mask}``
    resets only the masked ones.

    ## Layout and limits
    All sub-environments share one padded map shape (the largest map seen;
    see :mod:`motiongym.envs.sweeper.vector_state`). A fixed map is stored
    once. Odometry noise (``heading_noise``, ``slip_noise``) draws from each
    world's generator inside the step and is not batched: a non-zero value
    raises ValueError. Per-environment Python work happens only in resets.
    The returned observation arrays are fresh copies on every call (SB3's
    rollout buffer keeps the previous observation while stepping).

    ``render()`` returns one frame per sub-environment (the robot's path is
    recorded only when ``render_mode="rgb_array"``).
    """

    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": 30,
        "autoreset_mode": AutoresetMode.SAME_STEP,
        "info_measures": dict(SweeperEnv.metadata["info_measures"]),
    }

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int = 20_000,
        render_mode: str | None = None,
        **kwargs: Any,
    ) -> None:
        if int(num_envs) != num_envs or num_envs < 1:
            raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
        if max_episode_steps is None or int(max_episode_steps) < 1:
            raise ValueError(f"max_episode_steps must be >= 1, got {max_episode_steps!r}")
        for name in ("heading_noise", "slip_noise"):
            if kwargs.get(name, 0.0):
                raise ValueError(
                    f"{name}={kwargs[name]!r}: odometry noise is not batched in "
                    "SweeperVectorEnv; use SyncVectorEnv of SweeperEnv for noisy runs"
                )
        # The single environment validates the keywords and holds the spaces.
        self._single = single = SweeperEnv(render_mode=render_mode, **kwargs)
        self.num_envs = N = int(num_envs)
        self.max_episode_steps = int(max_episode_steps)
        self.render_mode = render_mode
        self.single_observation_space = single.observation_space
        self.observation_space = batch_space(single.observation_space, N)
        self.single_action_space = single.action_space
        self.action_space = batch_space(single.action_space, N)
        self.w, self.R, self.S, self.K = single.w, single.R, single.S, single.K
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
        KK, SS = self.K * self.K, self.S * self.S
        self.csw = np.zeros((N, KK), np.float32)  # coarse swept-cell counts
        self.cob = np.zeros((N, KK), np.float32)  # coarse known-obstacle counts
        self.sw_obs = np.zeros((N, KK), np.float32)  # csw * inv_block, kept current
        self.ob_obs = np.zeros((N, KK), np.float32)  # cob * inv_block, kept current
        self.sensed = np.zeros((N, SS), np.float32)  # observation windows, kept current
        self.swept = np.zeros((N, SS), np.float32)
        self._rngs: list[np.random.Generator | None] = [None] * N
        self._scenarios: list[task.Scenario | None] = [None] * N
        self._paths: list[list[tuple[int, int]]] = [[] for _ in range(N)]
        self._pool = _BufferPool(self.observation_space)
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
                raise ValueError(f"reset got {len(seeds)} seeds for num_envs={N}")
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is None:
            idx = np.arange(N)
        else:
            mask = np.asarray(mask)
            if mask.shape != (N,) or mask.dtype != np.bool_ or not mask.any():
                raise ValueError(
                    f"options['reset_mask'] must be a bool array of shape ({N},) with a True"
                )
            if not self._ready:
                raise RuntimeError("call reset() without reset_mask first")
            idx = np.flatnonzero(mask)
        self._reset_envs(idx, [seeds[i] for i in idx], options or None)
        self._ready = True
        info = self._info(
            idx, np.zeros(len(idx)), 0.0, np.zeros(len(idx)), np.zeros(len(idx), bool)
        )
        if mask is not None:
            info = _spread(info, idx, N)
        return self._observation(), info

    def _reset_envs(self, idx: np.ndarray, seeds: list, options: dict | None) -> None:
        """Sample and load new episodes for sub-environments ``idx`` (Python per world)."""
        single, g = self._single, self._grids
        scenarios = []
        for i, s in zip(idx.tolist(), seeds, strict=True):
            if s is not None or self._rngs[i] is None:
                self._rngs[i] = seeding.np_random(s)[0]
            sc = task.sample_scenario(self._rngs[i], single.fixed, single.map_name, self.w, options)
            scenarios.append(sc)
        shape = np.array([sc.obstacle.shape for sc in scenarios]).max(axis=0)
        if g.ensure(int(shape[0]), int(shape[1])):
            self.anchor[:] = self.r * g.Wp + self.c
        w, K = self.w, self.K
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
            # Footprint swept; the whole window sensed (as SweeperEnv.reset).
            blocks = g.block[0 if g.shared is not None else i]
            foot = a + g.foot_off
            g.cnt[i, foot] = 1
            self.csw[i] = 0.0
            np.add.at(self.csw[i], blocks[foot], np.float32(1.0))
            win = a + g.win_off
            obst = g.obst_b[0 if g.shared is not None else i, win]
            g.known[i, win] = obst
            seen = blocks[win[obst]]
            self.cob[i] = 0.0
            np.add.at(self.cob[i], seen[seen >= 0], np.float32(1.0))
            self.sw_obs[i] = self.csw[i] * inv
            self.ob_obs[i] = self.cob[i] * inv
            self.sensed[i] = obst
            self.swept[i] = g.cnt[i, win] > 0

    # ------------------------------------------------------------------- step
    def step(self, actions: Any) -> tuple[dict, np.ndarray, np.ndarray, np.ndarray, dict]:
        if not self._ready:
            raise RuntimeError("call reset() before step()")
        a = self._check_actions(actions)
        g, N, L = self._grids, self.num_envs, self._grids.L
        self.steps += 1
        fwd = np.flatnonzero(a == 0)
        hf = self.h[fwd]
        na = self.anchor[fwd] + g.delta[hf]
        ok = g.reach.ravel()[fwd * L + na]
        moved, hm, am = fwd[ok], hf[ok], na[ok]
        bump = np.zeros(N, bool)
        bump[fwd[~ok]] = True
        self.bump = bump
        self.bumps += bump
        self.turns += a != 0
        self.h = (self.h + TURN[a]) & 3
        new = np.zeros(N, np.int64)
        if len(moved):
            moved, count = self._move(moved, hm, am)
            new[moved] = count
        r_sweep = self._single.sweep_reward * new / self.w
        r_bump = np.where(bump, self._single.bump_reward, 0.0)
        reward = r_sweep + self._single.time_reward + r_bump
        terminated = self.n_swept >= self.n_reach
        truncated = self.steps >= self.max_episode_steps
        everyone = slice(None)
        info = self._info(everyone, r_sweep, self._single.time_reward, r_bump, bump)
        obs = self._observation()
        done = terminated | truncated
        if done.any():
            self._autoreset(np.flatnonzero(done), done, obs, info)
        return obs, reward, terminated, truncated, info

    def _move(
        self, moved: np.ndarray, hm: np.ndarray, am: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Move the worlds ``moved`` one cell along ``hm`` to anchors ``am``; sweep, sense.

        Returns the worlds (reordered by heading) and their newly swept cell counts.
        """
        g, L, KK = self._grids, self._grids.L, self.K * self.K
        order = np.argsort(hm, kind="stable")  # group by heading for the window shifts
        moved, hm, am = moved[order], hm[order], am[order]
        self.anchor[moved] = am
        self.r[moved] += DR[hm]
        self.c[moved] += DC[hm]
        self.travel[moved] += 1.0
        ob = g.obst_base[moved][:, None] + am[:, None]  # (M, 1) anchor in obst_b / block
        inv = self.inv_block[moved][:, None]  # (M, 1)
        # Sweep the w cells entering the footprint (counts saturate at 2).
        cnt = g.cnt.ravel()
        enter = g.enter_off[hm]  # (M, w)
        cells = (moved * L + am)[:, None] + enter
        before = cnt[cells]
        cnt[cells] = np.minimum(before + 1, 2)
        fresh = before == 0
        new = fresh.sum(axis=1)
        self.n_swept[moved] += new
        self.n_over[moved] += (before == 1).sum(axis=1)
        if new.any():
            target = (moved[:, None] * KK + g.block.ravel()[ob + enter])[fresh]
            csw = self.csw.ravel()
            np.add.at(csw, target, np.ones(len(target), np.float32))
            self.sw_obs.ravel()[target] = csw[target] * np.broadcast_to(inv, fresh.shape)[fresh]
        # Sense the window's leading edge (the only cells new to it).
        edge = g.edge_off[hm]  # (M, S)
        obst = g.obst_b.ravel()[ob + edge]
        known = g.known.ravel()
        kcells = (moved * L + am)[:, None] + edge
        seen = obst & ~known[kcells]
        if seen.any():
            known[kcells[seen]] = True
            blocks = g.block.ravel()[(ob + edge)[seen]]
            env = np.broadcast_to(moved[:, None], seen.shape)[seen]
            inside = blocks >= 0
            target = env[inside] * KK + blocks[inside]
            cob = self.cob.ravel()
            np.add.at(cob, target, np.ones(len(target), np.float32))
            self.ob_obs.ravel()[target] = cob[target] * self.inv_block[env[inside]]
        # Observation windows: shift by the move, fill the leading edge (and the
        # entering cells, now swept); cells inside the window do not change otherwise.
        swept_edge = cnt[kcells] > 0
        sensed, swept = self.sensed[moved], self.swept[moved]  # (M, S*S) copies
        S = self.S
        sensed3, swept3 = sensed.reshape(-1, S, S), swept.reshape(-1, S, S)
        bounds = np.searchsorted(hm, np.arange(5))
        for k in range(4):
            lo, hi = bounds[k], bounds[k + 1]
            if lo == hi:
                continue
            for buf, fill in ((sensed3, obst), (swept3, swept_edge)):
                part = buf[lo:hi]
                if k == 0:  # east: new[i, j] = old[i, j + 1]
                    part[:, :, :-1] = part[:, :, 1:].copy()
                    part[:, :, -1] = fill[lo:hi]
                elif k == 1:  # north: new[i, j] = old[i - 1, j]
                    part[:, 1:, :] = part[:, :-1, :].copy()
                    part[:, 0, :] = fill[lo:hi]
                elif k == 2:  # west
                    part[:, :, 1:] = part[:, :, :-1].copy()
                    part[:, :, 0] = fill[lo:hi]
                else:  # south
                    part[:, :-1, :] = part[:, 1:, :].copy()
                    part[:, -1, :] = fill[lo:hi]
            rr, cc = g.enter_win[k]
            swept3[lo:hi, rr, cc] = 1.0
        self.sensed[moved] = sensed
        self.swept[moved] = swept
        if self.render_mode is not None:
            rows, cols = self.r[moved].tolist(), self.c[moved].tolist()
            for i, r, c in zip(moved.tolist(), rows, cols, strict=True):
                self._paths[i].append((r, c))
        return moved, new

    def _autoreset(self, di: np.ndarray, done: np.ndarray, obs: dict, info: dict) -> None:
        """Same-step autoreset of worlds ``di``: final obs/info, then their new episodes."""
        final_obs = np.full(self.num_envs, None, dtype=object)
        for i in di.tolist():
            final_obs[i] = {key: value[i].copy() for key, value in obs.items()}
        final_info: dict[str, Any] = {}
        for key in INFO_KEYS:
            arr = np.zeros_like(info[key])
            arr[di] = info[key][di]
            final_info[key], final_info[f"_{key}"] = arr, done.copy()
        self._reset_envs(di, [None] * len(di), None)
        zeros = np.zeros(len(di))
        fresh = self._info(di, zeros, 0.0, zeros, np.zeros(len(di), bool))
        for key in INFO_KEYS:
            info[key][di] = fresh[key]
        new_obs = self._observation(di)
        for key, value in new_obs.items():
            obs[key][di] = value
        info["final_obs"], info["_final_obs"] = final_obs, done.copy()
        info["final_info"], info["_final_info"] = final_info, done.copy()

    def _check_actions(self, actions: Any) -> np.ndarray:
        a = np.asarray(actions)
        N = self.num_envs
        if a.shape not in ((N,), (N, 1)):
            raise ValueError(
                f"actions must have shape ({N},): one of 0 (forward), 1 (left), 2 (right) "
                f"per sub-environment; got shape {a.shape}"
            )
        a = a.reshape(N)
        if a.dtype.kind not in "iu":
            if a.dtype.kind not in "fb":
                raise ValueError(f"actions must be integers in {{0, 1, 2}}, got dtype {a.dtype}")
            if a.dtype.kind == "f":
                if np.isnan(a).any():
                    raise ValueError(
                        f"actions contain NaN at indices {np.flatnonzero(np.isnan(a))}"
                    )
                if (a != np.round(a)).any():
                    raise ValueError("actions must be integers in {0, 1, 2}, got fractional values")
            a = a.astype(np.int64)
        bad = (a < 0) | (a > 2)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(
                "actions must be 0 (forward), 1 (left) or 2 (right); "
                f"sub-environment {k} got {a[k]}"
            )
        return a

    # ---------------------------------------------------------------- outputs
    def _observation(self, idx: Any = None) -> dict:
        """Observation arrays for worlds ``idx``; all worlds in recycled buffers by default."""
        if idx is not None:  # fancy indexing: fresh arrays
            pose = np.stack([self.r[idx], self.c[idx], self.h[idx], self.bump[idx]], 1)
            return {
                "sensed": self.sensed[idx],
                "swept": self.swept[idx],
                "pose": pose.astype(np.float32),
                "sweep_map": self.sw_obs[idx],
                "obstacle_map": self.ob_obs[idx],
            }
        out = self._pool.take()
        pose = out["pose"]
        pose[:, 0], pose[:, 1], pose[:, 2], pose[:, 3] = self.r, self.c, self.h, self.bump
        np.copyto(out["sensed"], self.sensed)
        np.copyto(out["swept"], self.swept)
        np.copyto(out["sweep_map"], self.sw_obs)
        np.copyto(out["obstacle_map"], self.ob_obs)
        return dict(out)

    def _info(self, idx: Any, r_sweep: Any, r_time: float, r_bump: Any, bump: np.ndarray) -> dict:
        n = self.n_reach[idx]
        n_swept = self.n_swept[idx]
        travel = self.travel[idx]
        size = len(n)
        mask = np.ones(size, bool)
        info = {
            "is_success": n_swept >= n,
            "cost": bump.astype(np.float64),
            "coverage": n_swept / n,
            "travel": travel.copy(),
            "travel_ratio": travel * self.w / n,
            "overlap": self.n_over[idx] / n,
            "turns": self.turns[idx].copy(),
            "bumps": self.bumps[idx].copy(),
            "steps": self.steps[idx].copy(),
            "reward_sweep": np.asarray(r_sweep, np.float64),
            "reward_time": np.full(size, r_time, np.float64),
            "reward_bump": np.asarray(r_bump, np.float64),
        }
        for key in INFO_KEYS:
            info[f"_{key}"] = mask.copy()
        return info

    # ----------------------------------------------------------------- render
    def render(self) -> tuple[np.ndarray, ...] | None:
        if self.render_mode != "rgb_array" or not self._ready:
            return None
        from motiongym.envs.sweeper.render import draw

        g, P, frames = self._grids, self.R, []
        for i in range(self.num_envs):
            H, W = self._scenarios[i].obstacle.shape
            cnt = g.cnt[i].reshape(g.Hp, g.Wp)[P : P + H, P : P + W]
            r, c = int(self.r[i]), int(self.c[i])
            view = SimpleNamespace(
                scenario=self._scenarios[i],
                sweeps=cnt,
                path=self._paths[i],
                noisy=False,
                w=self.w,
                r=r,
                c=c,
                br=r,
                bc=c,
                h=int(self.h[i]),
            )
            frames.append(draw(view, self._single.cell_pixels))
        return tuple(frames)


class _BufferPool:
    """Output observation buffers, reused once nobody else holds them.

    Every call hands out a set of arrays that no caller references any more
    (CPython reference counts: a caller's dict, a view or a tensor sharing
    the memory all hold a reference, so a set in use is never overwritten).
    Reusing the memory spares the allocator's page faults on ~10 MB per step
    with thousands of worlds; the contents are always fully rewritten.
    """

    def __init__(self, space: Any, size: int = 4) -> None:
        self.space, self.size = space, size
        self.sets: list[dict[str, np.ndarray]] = []

    def take(self) -> dict[str, np.ndarray]:
        for arrays in self.sets:
            if _most_refs(arrays) <= _FREE:
                return arrays
        arrays = {k: np.empty(sp.shape, sp.dtype) for k, sp in self.space.items()}
        if len(self.sets) < self.size:
            self.sets.append(arrays)
        return arrays


def _most_refs(arrays: dict[str, np.ndarray]) -> int:
    """The largest reference count among ``arrays``' values (huge without refcounts)."""
    if not hasattr(sys, "getrefcount"):
        return 1 << 30
    return max(sys.getrefcount(a) for a in arrays.values())


_FREE = _most_refs({"unused": np.empty(0)})  # held by the dict alone


def _spread(info: dict, idx: np.ndarray, N: int) -> dict:
    """Info of worlds ``idx`` -> full ``(N,)`` arrays, zero and unmasked elsewhere."""
    out = {}
    for key, value in info.items():
        full = np.zeros((N, *value.shape[1:]), value.dtype)
        full[idx] = value
        if key.startswith("_"):
            full[:] = False
            full[idx] = True
        out[key] = full
    return out
