"""Scripted policies of the harvest arm: the paper's three layers, and a plain baseline.

``potential-field`` (:class:`PotentialFieldPolicy`), the paper's method:

1. at the episode's first step, plan the gripper's safe path from its start
   to the fruit with the potential field (eq. 2-7, RK4,
   :mod:`.potential_field`; after a stall in a local minimum, our escape
   stands in for the paper's undescribed "virtual plane");
2. every step, the gripper's velocity ``X_dot`` follows that path (aim at the
   path point one control period ahead of the nearest one, at most
   ``|V_end_ref|``; past the path's end, straight at the fruit); the joint
   points' reference velocities combine trajectory following with the
   avoidance of point and bar obstacles (eq. 8-11, :mod:`.reference_velocity`);
3. the joint rates are eq. 1's weighted pseudo-inverse with the null-space
   term, within joint ranges and speed limits (:mod:`.redundancy`), all
   weights ``k_i = 1``.

``resolved-rate`` (:class:`ResolvedRatePolicy`): the gripper straight at the
fruit at ``|V_end_ref|``, joint rates by the ordinary pseudo-inverse of the
gripper Jacobian, no avoidance (Whitney's resolved motion-rate control).

Both act from the observation alone; the arm's link table is rebuilt from the
environment's keyword arguments.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from motiongym.baselines.harvest_arm.potential_field import plan_path
from motiongym.baselines.harvest_arm.redundancy import limited_rates
from motiongym.baselines.harvest_arm.reference_velocity import (
    bar_obstacle_terms,
    combine,
    point_obstacle_terms,
    trajectory_following,
)
from motiongym.baselines.policy import ScriptedPolicy
from motiongym.envs.harvest_arm.model import ArmKinematics, arm_spec
from motiongym.envs.harvest_arm.observation import ObservationLayout

GRIPPER_SPEED = 0.2  # m/s, |V_end_ref| (the paper does not give it) and every |V_i_ref|


class _ArmPolicy(ScriptedPolicy):
    """Common parts: the arm model and the observation layout from ``env_kwargs``."""

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        env_kwargs: dict[str, Any] | None = None,
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        kw = self.env_kwargs
        planar = bool(kw.get("planar", False))
        self.arm = arm_spec(int(kw.get("dof") or (5 if planar else 7)), planar)
        self.link_radius = float(kw.get("link_radius", 0.02))
        self.dt = float(kw.get("dt", 0.05))
        self.kin = ArmKinematics(self.arm, self.link_radius, self.dt)
        n_slots = int(kw.get("n_obstacles") or (8 if planar else 10))
        self.layout = ObservationLayout(self.arm.dof, self.arm.dim, self.kin.n_points, n_slots)
        if observation_space.shape != (self.layout.size,):
            raise ValueError(
                f"observation shape {observation_space.shape} does not match the arm "
                f"{self.arm.name} with {n_slots} obstacle slots ({self.layout.size},); "
                "pass the env's kwargs (dof, planar, n_obstacles)"
            )
        self.speeds = self.arm.speeds
        self.limits = self.arm.limits

    def _to_action(self, rates: np.ndarray) -> np.ndarray:
        return np.clip(rates / self.speeds, -1.0, 1.0).astype(np.float32)


class PotentialFieldPolicy(_ArmPolicy):
    """The paper's method: potential-field path, reference velocities, eq. 1."""

    interior_only = True  # the paper's applicability tests of eq. 9-10
    both_ends = False  # the paper's X_i: a link's terms go to its proximal point

    def new_memory(self) -> dict[str, Any]:
        return {"path": None, "index": 0}

    def plan(self, o: dict[str, np.ndarray], start: np.ndarray) -> np.ndarray:
        """The safe gripper path (N, dim) for the parsed observation ``o``."""
        mask = o["mask"]
        return plan_path(
            start,
            o["fruit"],
            o["a"][mask],
            o["b"][mask],
            o["radius"][mask],
            speed=GRIPPER_SPEED,
            step=self.dt,
            gripper_radius=self.link_radius,
        )

    def gripper_velocity(self, x: np.ndarray, memory: dict[str, Any]) -> np.ndarray:
        """``X_dot`` (dim,) that follows the planned path from ``x``."""
        path = memory["path"]
        i0 = memory["index"]
        window = path[i0 : i0 + 20]
        i = i0 + int(np.argmin(np.linalg.norm(window - x, axis=1)))
        memory["index"] = i
        aim = path[min(i + 1, len(path) - 1)]
        if i + 1 >= len(path) - 1:
            aim = memory["fruit"]
        x_dot = (aim - x) / self.dt
        speed = float(np.linalg.norm(x_dot))
        return x_dot * (GRIPPER_SPEED / speed) if speed > GRIPPER_SPEED else x_dot

    def act(self, observation: np.ndarray, memory: dict[str, Any]) -> np.ndarray:
        o = self.layout.parse(observation)
        points, jacs = self.kin.jacobians(o["q"])  # (P, dim), (P, dim, n)
        x = points[-1]
        if memory["path"] is None:
            memory["path"] = self.plan(o, x)
            memory["fruit"] = o["fruit"]
        x_dot = self.gripper_velocity(x, memory)
        speed = float(np.linalg.norm(x_dot))
        v = x_dot / speed if speed > 1e-9 else np.zeros_like(x_dot)
        refs = self.reference_velocities(o, points, v)
        refs[-1] = x_dot  # the gripper's own reference is its path velocity
        rates = limited_rates(
            jacs[-1],
            x_dot,
            jacs,
            refs,
            np.ones(len(points)),
            o["q"],
            self.limits,
            self.speeds,
            self.dt,
        )
        return self._to_action(rates)

    def reference_velocities(
        self, o: dict[str, np.ndarray], points: np.ndarray, v: np.ndarray
    ) -> np.ndarray:
        """Eq. 8-11: ``X_i_dot`` of every joint point (P, dim)."""
        mask = o["mask"]
        sphere = mask & ~o["is_bar"]
        bar = mask & o["is_bar"]
        w_d = trajectory_following(points, v)
        r, ext = (
            self.link_radius,
            {"interior_only": self.interior_only, "both_ends": self.both_ends},
        )
        w_ob = point_obstacle_terms(points, o["a"][sphere], o["radius"][sphere], r, **ext)
        w_ob += bar_obstacle_terms(points, o["a"][bar], o["b"][bar], o["radius"][bar], r, **ext)
        return combine(w_d, w_ob, GRIPPER_SPEED)


class ExtendedPotentialFieldPolicy(PotentialFieldPolicy):
    """The paper's method with our two extensions of eq. 9-10.

    A link's obstacle terms also go to its distal point, and they also act on
    obstacles beyond the link's ends (closest point of the segment).
    """

    interior_only = False
    both_ends = True


class ResolvedRatePolicy(_ArmPolicy):
    """Plain baseline: gripper straight at the fruit, ordinary pseudo-inverse, no avoidance."""

    def new_memory(self) -> None:
        return None

    def act(self, observation: np.ndarray, memory: None) -> np.ndarray:
        o = self.layout.parse(observation)
        points, jacs = self.kin.jacobians(o["q"])
        to_fruit = o["fruit"] - points[-1]
        d = float(np.linalg.norm(to_fruit))
        speed = min(GRIPPER_SPEED, d / self.dt)
        x_dot = to_fruit / d * speed if d > 1e-9 else np.zeros_like(to_fruit)
        rates = np.linalg.pinv(jacs[-1], rcond=1e-3) @ x_dot
        scale = min(1.0, float(np.min(self.speeds / np.maximum(np.abs(rates), 1e-12))))
        return self._to_action(rates * scale)
