"""The harvest-arm observation: one flat float32 Box described by a core layout.

:func:`arm_layout` builds the :class:`motiongym.envs.core.ObservationLayout`
of an arm (the task writes with it, the scripted policies and feature
extractors read with it, so all agree on every index); :func:`layout_for`
builds it from the environment's parameters; :func:`observation_views`
gives the derived views a policy reads (joint angles from their sine and
cosine, each obstacle slot's ends, radius and kind, the mask as booleans).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from motiongym.envs import core
from motiongym.envs.harvest_arm.model import ArmSpec, joint_points
from motiongym.envs.harvest_arm.params import HarvestArmParams

DISTANCE_CLIP = 1.0  # m, link-obstacle clearances are reported up to this (and for empty slots)
POSITION_BOUND = 2.0  # m, every position lies within +-this


def obstacle_width(dim: int) -> int:
    """Entries per obstacle slot: ends a, b (dim each), radius, is_bar."""
    return 2 * dim + 2


def point_count(arm: ArmSpec) -> int:
    """Joint points of ``arm`` base to gripper, ``P`` (the gripper last; ``P - 1`` links)."""
    return len(joint_points(arm)) + 1


def arm_layout(dof: int, dim: int, n_points: int, n_slots: int) -> core.ObservationLayout:
    """The observation of an arm of ``dof`` joints in ``dim`` (2 or 3) dimensions.

    ``n_points`` joint points base to gripper (``n_points - 1`` links) and
    ``n_slots`` obstacle slots.
    """
    n, d, k = dof, dim, n_slots
    return core.ObservationLayout(
        [
            ("sin_q", n, "-", "sine of the joint angles"),
            ("cos_q", n, "-", "cosine of the joint angles"),
            ("qdot", n, "rad/s", "joint rates applied last step"),
            ("points", (n_points, d), "m", "joint points, base first, gripper last"),
            ("fruit", d, "m", "fruit centre"),
            ("fruit_error", d, "m", "fruit centre - gripper"),
            ("obstacles", (k, obstacle_width(d)), "m",
             "per slot: ends a, b (b = a: sphere), radius, is_bar"),
            ("mask", k, "-", "1 for a present obstacle"),
            ("distances", (n_points - 1, k), "m",
             "clearance link l to obstacle k, clipped at 1 m (1 m if absent)"),
        ]
    )  # fmt: skip


def layout_for(params: HarvestArmParams) -> core.ObservationLayout:
    """The observation layout of the arm that ``params`` describe."""
    arm = params.arm
    return arm_layout(arm.dof, arm.dim, point_count(arm), params.n_obstacles)


def arm_bounds(layout: core.ObservationLayout, speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Finite low / high bounds of every entry (size,), (size,); ``speeds`` (n,) rad/s."""
    p = POSITION_BOUND
    return layout.bounds(
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


def observation_views(layout: core.ObservationLayout, observation: Any) -> dict[str, np.ndarray]:
    """Derived views of one observation (float64 copies, shaped).

    ``q`` (n,) rad from the sine and cosine; ``qdot`` (n,) rad/s; ``points``
    (P, dim) m; ``fruit`` and ``fruit_error`` (dim,) m; per obstacle slot
    ``a``, ``b`` (K, dim) m, ``radius`` (K,) m, ``is_bar`` (K,) bool;
    ``mask`` (K,) bool; ``distances`` (L, K) m.
    """
    f = layout.parse(observation)
    obstacles = f["obstacles"]
    d = (obstacles.shape[1] - 2) // 2
    return {
        "q": np.arctan2(f["sin_q"], f["cos_q"]),
        "qdot": f["qdot"],
        "points": f["points"],
        "fruit": f["fruit"],
        "fruit_error": f["fruit_error"],
        "a": obstacles[:, :d],
        "b": obstacles[:, d : 2 * d],
        "radius": obstacles[:, 2 * d],
        "is_bar": obstacles[:, 2 * d + 1] > 0.5,
        "mask": f["mask"] > 0.5,
        "distances": f["distances"],
    }
