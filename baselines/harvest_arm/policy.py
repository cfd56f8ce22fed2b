"""Scripted policies of the harvest arm: the paper's three layers, and a plain baseline.

``potential-field`` (:class:`PotentialFieldPolicy`), the paper's method:

1. at the episode's first step, plan the gripper's safe path from its start
   to the fruit with the potential field (eq. 2-7, RK4, the obstacle terms
   in the virtual plane normal to the way to the fruit,
   :mod:`.potential_field`);
2. every step, the gripper's velocity ``X_dot`` follows that path (aim at the
   path point one control period ahead of the nearest one, at most
   ``|V_end_ref|``; past the path's end, straight at the fruit); the joint
   points follow the leader (eq. 8) and every link point near an obstacle
   is pushed off it (eq. 9-11, :mod:`.reference_velocity`);
3. the joint rates are eq. 1's weighted pseudo-inverse with the null-space
   term, within joint ranges and speed limits (:mod:`.redundancy`), weights
   ``k_i = 1`` for the joint points and ``1 + |w_ob|`` for the link points.

``potential-field-extended`` (:class:`ExtendedPotentialFieldPolicy`): the
same plus our "vortex" escape from a local minimum of the path (not the
paper's; :func:`.potential_field.plan_path`).

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

from motiongym.baselines.goal import for_goal_env
from motiongym.baselines.harvest_arm.potential_field import field_direction, plan_path
from motiongym.baselines.harvest_arm.redundancy import limited_rates, relaxed_rates
from motiongym.baselines.harvest_arm.reference_velocity import (
    combine,
    follow_the_leader,
    link_avoidance,
)
from motiongym.baselines.policy import ScriptedPolicy
from motiongym.envs.core import check_bool, check_float, params_from_kwargs
from motiongym.envs.harvest_arm.model import ArmKinematics
from motiongym.envs.harvest_arm.observation import layout_for, observation_views
from motiongym.envs.harvest_arm.params import HarvestArmParams

GRIPPER_SPEED = 0.2  # m/s, |V_end_ref| (the paper does not give it) and every |V_i_ref|
JOINT_DAMPING = 1e-3  # eq. 1's S1 + JOINT_DAMPING trace(S1)/n I: a small cost on joint rates
"""Without it the null space drifts along near-free joint combinations (the 7-DOF
arm's waist and upper-arm roll) to their limits where the references cannot all
be met; the fruit then ends out of reach."""
ESCAPE_COSINE = 0.3
"""``markov`` with ``escape``: the vortex field acts where the plain field's cosine to the
fruit direction is below this."""
RELAXED_GRIPPER_WEIGHT = 10.0
"""``critical_clearance``: the gripper's ``k_i`` in the unconstrained eq. 1 (the joint
points' are 1, a link's control point's ``1 + |w_ob|``, 9 at 5 cm, 120 at 2 cm)."""


class _ArmPolicy(ScriptedPolicy):
    """Common parts: the arm model and the observation layout from ``env_kwargs``."""

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        env_kwargs: dict[str, Any] | None = None,
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        params = params_from_kwargs(HarvestArmParams, self.env_kwargs, ignore=("render_mode",))
        self.arm = params.arm
        self.link_radius, self.dt = params.link_radius, params.dt
        self.kin = ArmKinematics(self.arm, self.link_radius, self.dt)
        n_slots = params.n_obstacles
        self.layout = layout_for(params)
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
    """The paper's method: potential-field path, reference velocities, eq. 1.

    Keyword options switch each mechanism off for ablations (all on by
    default, except our escape): ``trajectory_following`` (eq. 8),
    ``link_avoidance`` (eq. 9-10), ``virtual_plane`` (the obstacle selection
    of the gripper's field), ``escape`` (our "vortex" escape from local
    minima, not the paper's; on in ``potential-field-extended``).

    ``markov`` (off by default, not the paper's): no planned path; every
    step the gripper's ``X_dot`` is eq. 7's field at its *current* position
    (``|V_end_ref|`` times :func:`.potential_field.field_direction`; within
    one control period of the fruit, straight onto it). The action is then
    a function of the observation alone, a teacher DAgger can be taught by
    (:mod:`motiongym.agents.training.dagger`); on its path the plan-keeping policy
    moves the same way (the plan is the RK4 integral of this field), off it
    the two differ. Its ``escape`` needs no memory: where the field leads
    less than :data:`ESCAPE_COSINE` towards the fruit (near a local
    minimum) the vortex field acts instead.

    ``critical_clearance`` (m, off by default, not the paper's): while a
    link's control point (they exist within the avoidance row's ``rho0``,
    0.2 m) is closer than this to an obstacle, eq. 1 is solved
    without its gripper constraint (:func:`.redundancy.relaxed_rates`, the
    gripper weighted :data:`RELAXED_GRIPPER_WEIGHT`), so the link's avoidance
    can take the gripper off its path; the paper's constraint leaves it only
    the null space, which near these contacts may hold no motion that moves
    the link away.

    :meth:`diagnostics` keys: ``path`` (N, dim) the planned gripper path,
    ``stalled`` (the path stopped in a local minimum), ``escapes`` (vortex
    escapes used), ``control_points`` (link points under eq. 9-10 this step).
    """

    default_escape = False

    def __init__(
        self,
        observation_space: gym.Space,
        action_space: gym.Space,
        env_kwargs: dict[str, Any] | None = None,
        *,
        trajectory_following: bool = True,
        link_avoidance: bool = True,
        virtual_plane: bool = True,
        escape: bool | None = None,
        markov: bool = False,
        critical_clearance: float | None = None,
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        self.markov = check_bool("markov", markov)
        self.critical_clearance = (
            None
            if critical_clearance is None
            else check_float("critical_clearance", critical_clearance, 0.0, low_open=True)
        )
        self.trajectory_following = check_bool("trajectory_following", trajectory_following)
        self.link_avoidance = check_bool("link_avoidance", link_avoidance)
        self.virtual_plane = check_bool("virtual_plane", virtual_plane)
        self.escape = self.default_escape if escape is None else check_bool("escape", escape)

    def new_memory(self) -> dict[str, Any]:
        return {"path": None, "index": 0, "plan": {}, "control_points": 0}

    def describe(self, memory: dict[str, Any]) -> dict[str, Any]:
        return {
            "path": memory["path"],
            "stalled": bool(memory["plan"].get("stalled", False)),
            "escapes": int(memory["plan"].get("escapes", 0)),
            "control_points": memory["control_points"],
        }

    def plan(self, o: dict[str, np.ndarray], start: np.ndarray, report: dict) -> np.ndarray:
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
            escape=self.escape,
            virtual_plane=self.virtual_plane,
            report=report,
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

    def field_velocity(self, o: dict[str, np.ndarray], x: np.ndarray) -> np.ndarray:
        """``X_dot`` (dim,) of the Markov option: eq. 7's field at the gripper ``x``."""
        to_fruit = o["fruit"] - x
        if float(np.linalg.norm(to_fruit)) <= GRIPPER_SPEED * self.dt:
            return to_fruit / self.dt
        mask = o["mask"]
        scene = (x, o["fruit"], o["a"][mask], o["b"][mask], o["radius"][mask], self.link_radius)
        direction = field_direction(*scene, virtual_plane=self.virtual_plane)
        if self.escape and direction @ to_fruit < ESCAPE_COSINE * np.linalg.norm(to_fruit):
            direction = field_direction(*scene, virtual_plane=self.virtual_plane, vortex=True)
        return GRIPPER_SPEED * direction

    def act(self, observation: np.ndarray, memory: dict[str, Any]) -> np.ndarray:
        o = observation_views(self.layout, observation)
        points, jacs = self.kin.jacobians(o["q"])  # (P, dim), (P, dim, n)
        if self.markov:
            x_dot = self.field_velocity(o, points[-1])
        else:
            if memory["path"] is None:
                memory["path"] = self.plan(o, points[-1], memory["plan"])
                memory["fruit"] = o["fruit"]
            x_dot = self.gripper_velocity(points[-1], memory)
        jn = jacs[-1]  # (dim, n) the gripper's
        jacs, refs, weights = self.reference_velocities(o, points, jacs, x_dot, memory)
        critical = self.critical_clearance
        if critical is not None and memory["min_clearance"] < critical:
            weights[len(points) - 1] = RELAXED_GRIPPER_WEIGHT  # the gripper's k_i
            rates = relaxed_rates(
                jacs, refs, weights, o["q"], self.limits, self.speeds, self.dt, JOINT_DAMPING
            )
            return self._to_action(rates)
        rates = limited_rates(
            jn,
            x_dot,
            jacs,
            refs,
            weights,
            o["q"],
            self.limits,
            self.speeds,
            self.dt,
            JOINT_DAMPING,
        )
        return self._to_action(rates)

    def reference_velocities(
        self,
        o: dict[str, np.ndarray],
        points: np.ndarray,
        jacs: np.ndarray,
        x_dot: np.ndarray,
        memory: dict[str, Any],
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Eq. 8-11: the weighted points' Jacobians (M, dim, n), references (M, dim), ``k_i`` (M,).

        The joint points (gripper last) follow the leader (eq. 8), weight 1;
        then one control point per link near an obstacle (eq. 9-10, eq. 11),
        weight ``1 + |w_ob|`` (the paper's ``k_i`` are not given; ours make a
        point's avoidance outweigh path following as its clearance closes,
        as eq. 5's magnitude grows).
        """
        if self.trajectory_following:
            refs = follow_the_leader(points, x_dot)
        else:
            refs = np.zeros_like(points)
            refs[-1] = x_dot
        memory["control_points"] = 0
        memory["min_clearance"] = np.inf
        weights = np.ones(len(points))
        if not self.link_avoidance:
            return jacs, refs, weights
        mask = o["mask"]
        cp = link_avoidance(
            points,
            o["a"][mask],
            o["b"][mask],
            o["radius"][mask],
            o["is_bar"][mask],
            self.link_radius,
        )
        memory["control_points"] = len(cp)
        if not len(cp):
            return jacs, refs, weights
        memory["min_clearance"] = float(cp.clearance.min())
        cp_refs = combine(cp.interpolate(refs) / GRIPPER_SPEED, cp.w_ob, GRIPPER_SPEED)
        return (
            np.concatenate([jacs, cp.jacobians(jacs)]),
            np.concatenate([refs, cp_refs]),
            np.concatenate([weights, 1.0 + np.linalg.norm(cp.w_ob, axis=1)]),
        )


class ExtendedPotentialFieldPolicy(PotentialFieldPolicy):
    """The paper's method plus our "vortex" escape from local minima of the path."""

    default_escape = True


class ResolvedRatePolicy(_ArmPolicy):
    """Plain baseline: gripper straight at the fruit, ordinary pseudo-inverse, no avoidance."""

    def new_memory(self) -> None:
        return None

    def act(self, observation: np.ndarray, memory: None) -> np.ndarray:
        o = observation_views(self.layout, observation)
        points, jacs = self.kin.jacobians(o["q"])
        to_fruit = o["fruit"] - points[-1]
        d = float(np.linalg.norm(to_fruit))
        speed = min(GRIPPER_SPEED, d / self.dt)
        x_dot = to_fruit / d * speed if d > 1e-9 else np.zeros_like(to_fruit)
        rates = np.linalg.pinv(jacs[-1], rcond=1e-3) @ x_dot
        scale = min(1.0, float(np.min(self.speeds / np.maximum(np.abs(rates), 1e-12))))
        return self._to_action(rates * scale)


# The same policies on the goal-conditioned IDs (HarvestArmGoal-v1, ...).
GoalPotentialFieldPolicy = for_goal_env(PotentialFieldPolicy, __name__)
GoalExtendedPotentialFieldPolicy = for_goal_env(ExtendedPotentialFieldPolicy, __name__)
GoalResolvedRatePolicy = for_goal_env(ResolvedRatePolicy, __name__)
