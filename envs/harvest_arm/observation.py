"""The harvest-arm observation vector: one flat float32 Box, named slices.

Shared by the environment (which writes it) and the scripted policies (which
read it), so that both agree on every index.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from motiongym.envs import core

DISTANCE_CLIP = 1.0  # m, link-obstacle clearances are reported up to this (and for empty slots)
POSITION_BOUND = 2.0  # m, every position lies within +-this


@dataclass(frozen=True)
class ObservationLayout:
    """Slices of the observation for an arm of ``dof`` joints in ``dim`` dims.

    ``n_points`` joint points (base to gripper, ``n_points - 1`` links) and
    ``n_slots`` obstacle slots. Built on :class:`motiongym.envs.core.ObservationLayout`
    (named fields: build, parse with the coverage check, bounds, the
    docstring's table).
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

    @cached_property
    def fields(self) -> core.ObservationLayout:
        n, d, k = self.dof, self.dim, self.n_slots
        return core.ObservationLayout(
            [
                ("sin_q", n, "-", "sine of the joint angles"),
                ("cos_q", n, "-", "cosine of the joint angles"),
                ("qdot", n, "rad/s", "joint rates applied last step"),
                ("points", (self.n_points, d), "m", "joint points, base first, gripper last"),
                ("fruit", d, "m", "fruit centre"),
                ("fruit_error", d, "m", "fruit centre - gripper"),
                ("obstacles", (k, self.obstacle_width), "m",
                 "per slot: ends a, b (b = a: sphere), radius, is_bar"),
                ("mask", k, "-", "1 for a present obstacle"),
                ("distances", (self.n_links, k), "m",
                 "clearance link l to obstacle k, clipped at 1 m (1 m if absent)"),
            ]
        )  # fmt: skip

    @property
    def slices(self) -> dict[str, slice]:
        return dict(self.fields.slices)

    @property
    def size(self) -> int:
        return self.fields.size

    def table(self) -> str:
        """The reStructuredText table of this layout (the docstring's, for the default arm)."""
        return self.fields.table()

    def bounds(self, speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Finite low/high bounds of every entry: (size,), (size,)."""
        p = POSITION_BOUND
        return self.fields.bounds(
            {
                "sin_q": (-1.0, 1.0),
                "cos_q": (-1.0, 1.0),
                "qdot": (-speeds, speeds),
                "points": (-p, p),
                "fruit": (-p, p),
                "fruit_error": (-2 * p, 2 * p),
                "obstacles": (-p, p),
                "mask": (0.0, 1.0),
                "distances": (-p, DISTANCE_CLIP),
            }
        )

    def parse(self, observation: np.ndarray) -> dict[str, np.ndarray]:
        """Named views of one observation (float64 copies, shaped)."""
        f = self.fields.parse(observation)
        d, obstacles = self.dim, f["obstacles"]
        return {
            "q": np.arctan2(f["sin_q"], f["cos_q"]),  # (n,) rad
            "qdot": f["qdot"],  # (n,) rad/s
            "points": f["points"],  # (P, dim) m
            "fruit": f["fruit"],  # (dim,) m
            "fruit_error": f["fruit_error"],  # (dim,) m, fruit - gripper
            "a": obstacles[:, :d],  # (K, dim) m
            "b": obstacles[:, d : 2 * d],  # (K, dim) m
            "radius": obstacles[:, 2 * d],  # (K,) m
            "is_bar": obstacles[:, 2 * d + 1] > 0.5,  # (K,)
            "mask": f["mask"] > 0.5,  # (K,)
            "distances": f["distances"],  # (L, K) m
        }
