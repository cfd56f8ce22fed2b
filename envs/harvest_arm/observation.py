"""The harvest-arm observation vector: one flat float32 Box, named slices.

Shared by the environment (which writes it) and the scripted policies (which
read it), so that both agree on every index.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

DISTANCE_CLIP = 1.0  # m, link-obstacle clearances are reported up to this (and for empty slots)
POSITION_BOUND = 2.0  # m, every position lies within +-this


@dataclass(frozen=True)
class ObservationLayout:
    """Slices of the observation for an arm of ``dof`` joints in ``dim`` dims.

    ``n_points`` joint points (base to gripper, ``n_points - 1`` links) and
    ``n_slots`` obstacle slots.
    """

    dof: int
    dim: int
    n_points: int
    n_slots: int

    @property
    def n_links(self) -> int:
        return self.n_points - 1

    @property
    def obstacle_width(self) -> int:
        return 2 * self.dim + 2  # a, b, radius, is_bar

    def _sizes(self) -> list[tuple[str, int]]:
        return [
            ("sin_q", self.dof),
            ("cos_q", self.dof),
            ("qdot", self.dof),
            ("points", self.n_points * self.dim),
            ("fruit", self.dim),
            ("fruit_error", self.dim),
            ("obstacles", self.n_slots * self.obstacle_width),
            ("mask", self.n_slots),
            ("distances", self.n_links * self.n_slots),
        ]

    @property
    def slices(self) -> dict[str, slice]:
        out, start = {}, 0
        for name, size in self._sizes():
            out[name] = slice(start, start + size)
            start += size
        return out

    @property
    def size(self) -> int:
        return sum(size for _, size in self._sizes())

    def bounds(self, speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Finite low/high bounds of every entry: (size,), (size,)."""
        low = np.full(self.size, -POSITION_BOUND, dtype=np.float32)
        high = np.full(self.size, POSITION_BOUND, dtype=np.float32)
        s = self.slices
        for name in ("sin_q", "cos_q"):
            low[s[name]], high[s[name]] = -1.0, 1.0
        low[s["qdot"]], high[s["qdot"]] = -speeds, speeds
        low[s["mask"]], high[s["mask"]] = 0.0, 1.0
        low[s["distances"]], high[s["distances"]] = -POSITION_BOUND, DISTANCE_CLIP
        low[s["fruit_error"]], high[s["fruit_error"]] = -2 * POSITION_BOUND, 2 * POSITION_BOUND
        return low, high

    def parse(self, observation: np.ndarray) -> dict[str, np.ndarray]:
        """Named views of one observation (float64 copies, shaped)."""
        o = np.asarray(observation, dtype=float)
        s = self.slices
        obstacles = o[s["obstacles"]].reshape(self.n_slots, self.obstacle_width)
        d = self.dim
        return {
            "q": np.arctan2(o[s["sin_q"]], o[s["cos_q"]]),  # (n,) rad
            "qdot": o[s["qdot"]],  # (n,) rad/s
            "points": o[s["points"]].reshape(self.n_points, d),  # (P, dim) m
            "fruit": o[s["fruit"]],  # (dim,) m
            "fruit_error": o[s["fruit_error"]],  # (dim,) m, fruit - gripper
            "a": obstacles[:, :d],  # (K, dim) m
            "b": obstacles[:, d : 2 * d],  # (K, dim) m
            "radius": obstacles[:, 2 * d],  # (K,) m
            "is_bar": obstacles[:, 2 * d + 1] > 0.5,  # (K,)
            "mask": o[s["mask"]] > 0.5,  # (K,)
            "distances": o[s["distances"]].reshape(self.n_links, self.n_slots),  # (L, K) m
        }
