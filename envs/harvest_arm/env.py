"""The harvest-arm environment: a redundant arm reaching a fruit among obstacles."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium import spaces

from motiongym.envs.actions import checked_box_action
from motiongym.envs.core import (
    ArgumentError,
    NeedsReset,
    check_options,
    check_render_mode,
    check_shape,
    reward_and_info,
    zero_terms,
)
from motiongym.envs.harvest_arm.observation import ObservationLayout
from motiongym.envs.harvest_arm.params import HarvestArmParams
from motiongym.envs.harvest_arm.task import (
    Scene,
    check_position,
    sample_scene,
    scene_from_obstacles,
)
from motiongym.envs.harvest_arm.world import HarvestArmWorld
from motiongym.envs.rendering import OwnsRenderer


class HarvestArmEnv(NeedsReset, OwnsRenderer, gym.Env):
    """Bring a redundant arm's gripper to a fruit while its links keep clear.

    The arm of Ryu et al. (fruit-harvesting redundant robot) among immature
    fruit (spheres) and branches (bars). The arm is kinematic: joint velocity
    commands are integrated over the control period ``dt`` (no dynamics), the
    pose is evaluated with ``mj_kinematics`` and every link-obstacle clearance
    with ``mj_collision`` on explicit pairs (exact for spheres and capsules).
    Arms, ranges and speeds: :mod:`motiongym.envs.harvest_arm.model`; scenes:
    :mod:`motiongym.envs.harvest_arm.task`.

    Variants: ``planar=False`` with ``dof`` 5 (CRS A465 with the added wrist
    link), 6, 7 (default) and 10 obstacles of which 3 bars; ``planar=True``
    with ``dof`` 3, 4, 5 (default) and 8 spherical obstacles (coordinates x,
    y). Links are capsules of radius ``link_radius``; the control period is
    ``dt`` (registered IDs: 300 steps, 15 s).

    Action (Box(-1, 1, (n,))): joint ``j``'s velocity as a fraction of its
    speed limit (rad/s); the pose is clipped to the joint ranges.

    Observation (Box float32, ``dim`` = 2 planar or 3 spatial, ``P`` joint
    points base to gripper, ``L = P - 1`` links, ``K`` obstacle slots; the
    slices are named by :class:`ObservationLayout`):

    | slice | meaning | unit | frame |
    |---|---|---|---|
    | sin_q (n), cos_q (n) | joint angles | - | joint |
    | qdot (n) | joint rates applied last step | rad/s | joint |
    | points (P * dim) | joint points, base first, gripper last | m | world |
    | fruit (dim) | fruit centre | m | world |
    | fruit_error (dim) | fruit centre - gripper (as Reacher's fingertip - target) | m | world |
    | obstacles (K * (2 dim + 2)) | per slot: ends a, b (b = a: sphere), radius, is_bar | m | - |
    | mask (K) | 1 for a present obstacle | - | - |
    | distances (L * K) | clearance link l to obstacle k, clipped at 1 m (1 m if absent) | m | - |

    Reward, the sum of the terms (weights are keyword arguments of the same
    name): ``progress`` * decrease of the gripper-fruit distance (m);
    ``- clearance`` * max(0, 1 - d_min / safety_distance); ``- collision`` on
    contact (d_min <= 0); ``- effort`` * mean(action^2); ``success`` on arrival;
    ``- distance`` * gripper-fruit distance (m) every step, 0 in the registered
    IDs: a dense shaping that training configurations switch on (the progress
    term telescopes, so a policy parked 0.5 m short loses only 5 in all). Being
    negative, it makes ending an episode on an obstacle cheaper than a long
    miss; ``terminate_on_collision=False`` removes that way out (the configs
    record how each choice trained).

    Termination: the gripper within ``success_tolerance`` of the fruit centre,
    or a collision (if ``terminate_on_collision``). Truncation: the
    ``max_episode_steps`` of the registration (TimeLimit).

    ``info``: ``distance_to_fruit`` (m), ``min_distance`` (smallest
    link-obstacle clearance this step, m), ``min_distance_so_far`` (m),
    ``close_approach`` (d_min < safety_distance), ``collision`` (d_min <= 0,
    or with ``self_collision`` two non-adjacent links touching), ``cost``
    (1.0 on a close approach or a collision), ``is_success``,
    ``reward_<term>``; with ``self_collision`` also ``self_distance`` (m,
    smallest surface distance between two links that share no joint point,
    clipped at 1 m) and ``self_collision`` (it is <= 0).

    Keyword arguments and their limits: :class:`HarvestArmParams` (one
    frozen dataclass that the scripted policies build too).

    Reset options (validated; an :class:`~motiongym.envs.core.ArgumentError`
    names the option otherwise): ``fruit`` (dim,) and ``obstacles`` (list of
    ``{"center", "radius"}`` or ``{"a", "b", "radius"}``, finite coordinates
    within +-2 m, radius in (0, 0.2] m, at most the env's sphere and bar
    slots) together give an explicit scene; an obstacle that overlaps the
    fruit sphere is refused. ``q`` (n,) a finite start pose (default the
    arm's home pose), clipped to the joint ranges. A fruit out of the arm's
    reach is accepted: the episode runs until the time limit (truncation)
    with ``is_success`` False.

    Version history:

    * v1: ``self_collision=True``: two non-adjacent links touching is a
      collision (``info["collision"]``, the cost, the collision reward term and,
      with ``terminate_on_collision``, termination), measured by MuJoCo on
      explicit link-link pairs. Observation and scenes as v0.
    * v0 (initial): only link-obstacle contact is a collision.
    """

    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": 20,
        "info_measures": {
            "is_success": "last",
            "cost": "sum",
            "collision": "max",
            "close_approach": "max",
            "min_distance": "min",
            "distance_to_fruit": "last",
        },
    }

    def __init__(
        self,
        dof: int | None = None,  # default 5 planar, 7 spatial
        planar: bool = False,
        n_obstacles: int | None = None,  # default 8 planar, 10 spatial
        n_bars: int | None = None,  # default 0 planar, 3 spatial
        link_radius: float = 0.02,  # m
        dt: float = 0.05,  # s, control period
        safety_distance: float = 0.03,  # m, the paper's collision-risk distance
        success_tolerance: float = 0.02,  # m, gripper to fruit centre
        terminate_on_collision: bool = True,
        self_collision: bool = False,
        progress: float = 10.0,
        clearance: float = 1.0,
        collision: float = 10.0,
        effort: float = 0.01,
        success: float = 10.0,
        distance: float = 0.0,
        render_mode: str | None = None,
        width: int = 480,
        height: int = 360,
    ) -> None:
        p = HarvestArmParams(
            dof, planar, n_obstacles, n_bars, link_radius, dt, safety_distance,
            success_tolerance, terminate_on_collision, self_collision, progress, clearance,
            collision, effort, success, distance, width, height,
        )  # fmt: skip
        self.params = p
        self.render_mode = check_render_mode(render_mode, self.metadata["render_modes"])
        self.world = HarvestArmWorld(p)
        self.spec_arm, self.kinematics = self.world.arm, self.world.kinematics
        self.n_obstacles, self.n_bars = p.n_obstacles, p.n_bars
        self.link_radius, self.dt = p.link_radius, p.dt
        self.weights = p.weights
        n, self.dim = self.spec_arm.dof, self.spec_arm.dim
        self.layout = ObservationLayout(n, self.dim, self.world.n_points, p.n_obstacles)
        self._limits = self.spec_arm.limits
        self._step_size = self.spec_arm.speeds * p.dt  # rad per unit action
        low, high = self.layout.bounds(self.spec_arm.speeds)
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, (n,), dtype=np.float32)
        self._obs = np.zeros(self.layout.size, dtype=np.float32)
        s = self.layout.slices
        self._s_sin, self._s_cos, self._s_qdot = s["sin_q"], s["cos_q"], s["qdot"]
        self._s_points, self._s_dist = s["points"], s["distances"]
        self._s_fruit_error = s["fruit_error"]
        self._q = np.zeros(n)
        self._renderer: mujoco.Renderer | None = None
        self._path: list[np.ndarray] = []
        self._was_reset = False

    @property
    def scene(self) -> Scene | None:
        """The current scene (None before the first reset)."""
        return self.world.scene

    # ------------------------------------------------------------------ reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        n = self.spec_arm.dof
        options = check_options(
            options,
            {
                "fruit": lambda name, v: check_position(name, v, self.dim),
                "obstacles": lambda name, v: v,  # checked with the fruit, below
                "q": lambda name, v: check_shape(name, v, (n,)),
            },
        )
        if ("fruit" in options) != ("obstacles" in options):
            raise ArgumentError("reset options 'fruit' and 'obstacles' must be given together")
        if "fruit" in options:
            scene = scene_from_obstacles(
                options["fruit"], options["obstacles"], self.dim,
                (self.n_obstacles - self.n_bars, self.n_bars),
            )  # fmt: skip
        else:
            scene = sample_scene(
                self.np_random, self.kinematics, self.n_obstacles, self.n_bars, self.link_radius
            )
        q = options.get("q", np.array(self.spec_arm.home, float))
        rows, mask = self.world.set_scene(scene, self.layout.obstacle_width)
        s = self.layout.slices
        self._obs[s["fruit"]] = scene.fruit
        self._obs[s["obstacles"]] = rows.ravel()
        self._obs[s["mask"]] = mask
        self._fruit = scene.fruit.copy()
        self._q = np.clip(q, -self._limits, self._limits)
        self._update(np.zeros(n))
        self._d_fruit = self._distance_to_fruit()
        self._min_so_far = self.world.min_distance
        self._path = [self.world.gripper_3d()]
        self._was_reset = True
        return self._obs.copy(), self._info(False, False, zero_terms(self.weights))

    # ------------------------------------------------------------------- step
    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        a = checked_box_action(action, self.action_space.shape, "one rate per joint")
        self._require_reset("step")
        a = np.minimum(np.maximum(a, -1.0), 1.0)
        q_old = self._q
        q = q_old + a * self._step_size  # rad
        self._q = np.minimum(np.maximum(q, -self._limits), self._limits)
        self._update((self._q - q_old) / self.dt)
        d_fruit = self._distance_to_fruit()
        min_d = self.world.min_distance
        self._min_so_far = min(self._min_so_far, min_d)
        collided = min_d <= 0.0 or self.world.self_distance <= 0.0
        arrived = d_fruit <= self.params.success_tolerance
        w = self.weights
        terms = {
            "progress": w["progress"] * (self._d_fruit - d_fruit),
            "clearance": -w["clearance"] * max(0.0, 1.0 - min_d / self.params.safety_distance),
            "collision": -w["collision"] * float(collided),
            "effort": -w["effort"] * float(np.dot(a, a)) / len(a),
            "success": w["success"] * float(arrived),
            "distance": -w["distance"] * d_fruit,
        }
        self._d_fruit = d_fruit
        if self.render_mode is not None:
            self._path.append(self.world.gripper_3d())
        terminated = bool(arrived or (collided and self.params.terminate_on_collision))
        reward, info = self._reward_and_info(arrived, collided, terms)
        return self._obs.copy(), reward, terminated, False, info

    def _update(self, qdot: np.ndarray) -> None:
        """Pose the world; write the per-step part of the observation."""
        world, obs, q = self.world, self._obs, self._q
        world.pose(q)
        obs[self._s_sin] = np.sin(q)
        obs[self._s_cos] = np.cos(q)
        obs[self._s_qdot] = qdot
        points = world.points
        obs[self._s_points] = points.ravel()
        obs[self._s_fruit_error] = self._fruit - points[-1]
        obs[self._s_dist] = world.clearances
        self._gripper = points[-1]

    def _distance_to_fruit(self) -> float:
        g = self._gripper - self._fruit
        return float(np.sqrt(g @ g))

    def _reward_and_info(
        self, arrived: bool, collided: bool, terms: dict[str, float]
    ) -> tuple[float, dict[str, Any]]:
        world = self.world
        close = world.min_distance < self.params.safety_distance
        measures: dict[str, Any] = {
            "distance_to_fruit": self._d_fruit,
            "min_distance": world.min_distance,
            "min_distance_so_far": self._min_so_far,
            "close_approach": bool(close),
            "collision": bool(collided),
        }
        if self.params.self_collision:
            measures["self_distance"] = world.self_distance
            measures["self_collision"] = bool(world.self_distance <= 0.0)
        return reward_and_info(
            terms, cost=1.0 if close or collided else 0.0, is_success=arrived, **measures
        )

    def _info(self, arrived: bool, collided: bool, terms: dict[str, float]) -> dict[str, Any]:
        return self._reward_and_info(arrived, collided, terms)[1]

    # ----------------------------------------------------------------- render
    def render(self) -> np.ndarray | None:
        self._require_reset("render")
        if self.render_mode != "rgb_array":
            return None
        if self._renderer is None:
            self._renderer = mujoco.Renderer(
                self.world.model, self.params.height, self.params.width
            )
        return self.world.render(self._renderer, self._path)
