"""Scripted reference policies for the excavator: reach, and one dig cycle.

Both act from the observation alone (sliced by name with
:func:`motiongym.envs.excavator.observation.layout`), build the environment's
parameters from ``env_kwargs`` as the environment does
(:func:`motiongym.envs.excavator.params.params_for`: the machine, the step,
the safety distance, the physics; no default copied), turn bucket poses into
joint angles with the Newton-Raphson IK (:mod:`.newton_raphson`, eq. 9-13)
and track them with joint rates within the hydraulic limits
(:mod:`.tracking`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from motiongym.baselines.excavator import bucket_path as bp
from motiongym.baselines.excavator.tracking import solve_pose, track
from motiongym.baselines.goal import for_goal_env
from motiongym.baselines.policy import ScriptedPolicy
from motiongym.envs.core import check_bool, check_float
from motiongym.envs.excavator.kinematics import base_pose, base_rotation
from motiongym.envs.excavator.observation import PROFILE_RADII, layout
from motiongym.envs.excavator.params import params_for

REACHED = 2e-3  # rad: a waypoint counts as reached
STALL_STEPS = 2  # steps without motion short of the goal: stopped by the ground
BOOM_RAISE = 0.1  # rad: the boom alone raised before curling anew


class _ExcavatorPolicy(ScriptedPolicy):
    TASK = "reach"

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        env_kwargs: dict[str, Any] | None = None,
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        self.params = params_for(self.TASK, self.env_kwargs)
        self.m = self.params.machine
        self.dt = self.params.dt
        self.safety = self.params.pipe_safety
        self.lay = layout(self.TASK, self.params.physics)

    def _goal(
        self, wp: bp.Waypoint, q_start: np.ndarray, base: np.ndarray | None = None
    ) -> np.ndarray:
        result = solve_pose(np.array(wp.tip), wp.beta, self.m, q_start, base=base)
        # A pose beyond the limits is tracked as far as the joints go.
        return np.clip(result.q, self.m.q_min, self.m.q_max)

    def _follow(self, obs: np.ndarray, memory: dict) -> np.ndarray:
        """Track the memory's joint goals in order; hold the last one.

        Under physics v1 the tracking also respects the acceleration limits
        (from the observed rates) and the shared pump flow.
        """
        q = obs[self.lay["q"]]
        goals = memory["goals"]
        while memory["index"] < len(goals) - 1 and np.max(
            np.abs(goals[memory["index"]] - q)
        ) < memory.get("tolerance", REACHED):
            memory["index"] += 1
        goal = goals[memory["index"]]
        if self.params.physics == "v0":
            return track(q, goal, self.m, self.dt)
        qdot = obs[self.lay["qdot"]]
        return track(q, goal, self.m, self.dt, qdot, self.m.accel_max, self.m.pump_share)


class ReachPolicy(_ExcavatorPolicy):
    """IK to the target pose (approached from 1 m above), joint-rate tracking.

    Args:
        replan: re-plan from every observation (default False: plan once, at
            the episode's first observation). The plan made once (1 m above,
            then the target, the second goal switched to within 0.05 rad of
            the first) depends on where the episode began and on whether the
            first goal was reached: a learner that sees only the current
            observation meets the same state labelled "up" in one episode and
            "down" in another, and its mean-squared fit averages them to a
            stall (docs/experiments/ExcavatorReach-v0.md). With ``replan`` the
            goal is the tip ``h = min(1 m, d)`` above the target, ``d`` the
            horizontal distance from the tip to it (the approach from above as
            a funnel: 1 m above while far, down as the tip comes over the
            target), solved by IK from the current joints at every step: the
            action is a function of the observation alone, the labels a
            DAgger learner needs (:mod:`motiongym.agents.training.dagger`).
    """

    TASK = "reach"
    FUNNEL_HEIGHT = 1.0  # m: the goal's height above the target while far from it

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        env_kwargs: dict[str, Any] | None = None,
        replan: bool = False,
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        self.replan = check_bool("replan", replan)

    def new_memory(self) -> dict:
        return {"goals": None, "index": 0}

    def describe(self, memory: dict) -> dict:
        """``planned`` (the IK goals are set) and ``waypoint`` (0: above, 1: target)."""
        return {"planned": memory["goals"] is not None, "waypoint": memory["index"]}

    def _base(self, obs: np.ndarray) -> np.ndarray | None:
        """The base pose ``H_M^O`` on a slope (v1: the IK takes it; the target is in O)."""
        if "base" not in self.lay:
            return None
        return base_pose(rpy=(*(float(v) for v in obs[self.lay["base"]]), 0.0))

    def act(self, observation: np.ndarray, memory: dict) -> np.ndarray:
        obs = np.asarray(observation, dtype=np.float64)
        q = obs[self.lay["q"]]
        target = obs[self.lay["target"]]
        if self.replan:
            error = obs[self.lay["target_error"]]
            height = min(self.FUNNEL_HEIGHT, math.hypot(float(error[0]), float(error[1])))
            point = (float(target[0]), float(target[1]), float(target[2]) + height)
            funnel = bp.Waypoint("funnel", point, float(target[3]))
            memory.update(goals=[self._goal(funnel, q, self._base(obs))], index=0)
        elif memory["goals"] is None:
            base = self._base(obs)
            tip, beta = target[:3], float(target[3])
            above = bp.Waypoint("above", (tip[0], tip[1], tip[2] + 1.0), beta)
            q_above = self._goal(above, q, base)
            q_target = self._goal(bp.Waypoint("target", tuple(tip), beta), q_above, base)
            memory["goals"] = [q_above, q_target]
            memory["tolerance"] = 0.05
        return self._follow(obs, memory)


class DigCyclePolicy(_ExcavatorPolicy):
    """Bucket-path generator for one cycle, IK at each waypoint, joint-rate tracking.

    Stages (re-planned from the observation as the machine gets there):
    ``approach`` (swing to the zone, bucket over its far end), ``dig`` (read
    the ground profile in the boom plane, choose the cut depth clear of the
    pipe, penetrate and drag), ``curl``/``lift`` (as soon as the bucket is
    full or the drag is over), ``carry``/``swing``/``dump`` (over the truck,
    then wait for the bucket to empty).

    The path's style follows the environment's physics
    (:data:`.bucket_path.V0_STYLE`, :data:`.bucket_path.V1_STYLE`); under v1
    the plan is made in the base frame M (the slope's roll and pitch read from
    the observation), the curl and lift rise along the world's vertical, and a
    curl that the ground stops (no motion for ``STALL_STEPS`` steps) is
    answered by raising the boom alone (stage ``raise``) and curling anew.

    Args:
        tolerance: a joint goal counts as reached when every joint is within
            this many radians of it (default ``REACHED``, 2 mrad). The plan is
            followed goal by goal, each passed only once reached, so an action
            changed after the policy chose it (a residual agent's correction,
            :mod:`motiongym.agents.training.residual`) must not move the joints by more
            than the tolerance in a step: the dead-beat tracking
            (:func:`.tracking.track`) leaves the joints ``c * rate_max * dt``
            past the goal after a step with correction ``c``, so with the
            default a steady correction above ~35 % of a 0.05-scale residual's
            range (swing: 0.05 x 1.15 rad/s x 0.1 s = 5.75 mrad) never lets
            the plan advance (docs/experiments/Excavator-v1.md). Residual
            agents take ``REACHED + scale * max(rate_max) * dt`` or more
            (the shipped ones: 0.01 at scale 0.05).
    """

    TASK = "dig"

    def __init__(
        self, observation_space, action_space, env_kwargs=None, tolerance: float = REACHED
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        self.style = bp.V1_STYLE if self.params.physics == "v1" else bp.V0_STYLE
        self.tolerance = check_float("tolerance", tolerance, 0.0, 0.5, low_open=True)

    def new_memory(self) -> dict:
        return {
            "stage": None,
            "goals": None,
            "index": 0,
            "depth": None,
            "still": 0,
            "replans": 0,
            "tolerance": self.tolerance,
        }

    def _stalled(self, obs: np.ndarray, memory: dict) -> bool:
        """Whether the machine has not moved for ``STALL_STEPS`` steps short of its goal
        (physics v1: the ground stopped it)."""
        moving = np.max(np.abs(obs[self.lay["qdot"]])) > 1e-4
        memory["still"] = (
            0 if moving or self._done(obs[self.lay["q"]], memory) else memory["still"] + 1
        )
        return memory["still"] >= STALL_STEPS

    def describe(self, memory: dict) -> dict:
        """``stage`` (None, "approach", "dig", "lift", "raise", "dump"), ``cut_depth`` (m, None
        before the dig is planned), ``waypoint`` (index of the goal tracked) and
        ``replans`` (curls started anew after the ground stopped the bucket)."""
        return {
            "stage": memory["stage"],
            "cut_depth": memory["depth"],
            "waypoint": memory["index"],
            "replans": memory["replans"],
        }

    def _set(self, memory: dict, stage: str, waypoints: list[bp.Waypoint], q: np.ndarray):
        goals, q_prev = [], q
        for wp in waypoints:
            q_prev = self._goal(wp, q_prev)
            goals.append(q_prev)
        memory.update(stage=stage, goals=goals, index=0, waypoints=waypoints)

    def _done(self, q: np.ndarray, memory: dict) -> bool:
        return memory["index"] == len(memory["goals"]) - 1 and (
            np.max(np.abs(memory["goals"][-1] - q)) < memory["tolerance"]
        )

    def _scene(self, obs: np.ndarray) -> dict:
        """The zone, truck and pipe in the base frame M (the observation is in frame O).

        On a slope (v1's ``base`` roll and pitch, the paper's ``H_M^O``) every
        position is turned by ``R^T``: in frame M the tracks' ground plane is
        level, and the plan of v0 applies. The truck's rim is its highest
        corner in frame M.
        """
        rot = np.eye(3)
        if "base" in self.lay:
            roll, pitch = (float(v) for v in obs[self.lay["base"]])
            rot = base_rotation(roll, pitch, 0.0)
        gx, gy = -rot[0, 2] / rot[2, 2], -rot[1, 2] / rot[2, 2]  # the tracks' plane in O

        def to_m(x: float, y: float, z: float | None = None) -> np.ndarray:
            return rot.T @ np.array([x, y, gx * x + gy * y if z is None else z])

        zone = obs[self.lay["zone"]].copy()
        zone[0:2], zone[2:4] = to_m(*zone[0:2])[:2], to_m(*zone[2:4])[:2]
        truck = obs[self.lay["truck"]].copy()
        cx, cy, yaw, hl, hw, rim = (float(v) for v in truck)
        c, s = math.cos(yaw), math.sin(yaw)
        corners = [
            to_m(cx + c * a - s * b, cy + s * a + c * b, rim) for a in (-hl, hl) for b in (-hw, hw)
        ]
        truck[0:2] = to_m(cx, cy, rim)[:2]
        truck[5] = max(p[2] for p in corners)
        pipe = obs[self.lay["pipe"]].copy()
        pipe[0:3], pipe[3:6] = to_m(*pipe[0:3]), to_m(*pipe[3:6])
        return {"rot": rot, "to_m": to_m, "zone": zone, "truck": truck, "pipe": pipe}

    def _surface(self, obs: np.ndarray, scene: dict):
        """Ground height in frame M along the boom plane, ``surface(r)`` (r in frame M)."""
        q1 = float(obs[self.lay["q"]][0])
        points = np.array(
            [
                scene["to_m"](r * math.cos(q1), r * math.sin(q1), h)
                for r, h in zip(PROFILE_RADII, obs[self.lay["profile"]], strict=True)
            ]
        )
        radii, heights = np.hypot(points[:, 0], points[:, 1]), points[:, 2]
        order = np.argsort(radii)
        radii, heights = radii[order], heights[order]

        def surface(r: float) -> float:
            return float(np.interp(r, radii, heights))

        return surface

    def act(self, observation: np.ndarray, memory: dict) -> np.ndarray:
        obs = np.asarray(observation, dtype=np.float64)
        q = obs[self.lay["q"]]
        if memory["stage"] is None:
            memory["scene"] = self._scene(obs)
        scene = memory["scene"]
        zone = scene["zone"]
        fill = float(obs[self.lay["fill"]][0])
        azimuth = math.atan2(zone[3], zone[2])
        r_near, r_far = math.hypot(zone[0], zone[1]), math.hypot(zone[2], zone[3])
        if memory["stage"] is None:
            # Approach: bucket 2 m above the far end (the ground there is read later).
            first = bp.dig_path(azimuth, r_near, r_far, 0.0, _flat, self.style)[:1]
            self._set(memory, "approach", first, q)
        stage = memory["stage"]
        if stage == "approach" and self._done(q, memory):
            surface = self._surface(obs, scene)
            ground = max(surface(r) for r in np.linspace(r_near, r_far, 8))
            depth = bp.allowed_depth(zone, scene["pipe"], self.m, self.safety, ground)
            memory["depth"] = depth
            memory["surface"] = surface
            path = bp.dig_path(azimuth, r_near, r_far, depth, surface, self.style)
            self._set(memory, "dig", path[1:], q)
        elif stage in ("lift", "raise") and self._stalled(obs, memory):
            # The ground stopped the curling bucket (soil beside the cut, a pile
            # pushed ahead): raise the boom alone (every part moves up), then curl anew.
            memory["replans"] += 1
            goal = np.clip(q + [0.0, BOOM_RAISE, 0.0, 0.0], self.m.q_min, self.m.q_max)
            memory.update(stage="raise", goals=[goal], index=0, still=0)
        elif (
            stage == "dig" and (fill >= 0.97 * self.m.bucket_capacity or self._done(q, memory))
        ) or (stage == "raise" and self._done(q, memory)):
            tip = scene["rot"].T @ obs[self.lay["tip"]]
            beta = float(obs[self.lay["bucket"]][0])
            here = memory["surface"](math.hypot(tip[0], tip[1]))
            up = tuple(scene["rot"][2])  # the world's vertical in frame M
            path = bp.curl_lift_path(tip, beta, here, self.m, self.style, up)
            self._set(memory, "lift", path, q)
        elif stage == "lift" and self._done(q, memory):
            waypoints, _ = bp.carry_dump_path(azimuth, scene["truck"], self.m)
            self._set(memory, "dump", waypoints, q)
        return self._follow(obs, memory)


def _flat(r: float) -> float:
    return 0.0


# The reach policy on the goal-conditioned ID (ExcavatorReachGoal-v1).
GoalReachPolicy = for_goal_env(ReachPolicy, __name__)
