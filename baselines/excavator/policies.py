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
from motiongym.baselines.policy import ScriptedPolicy
from motiongym.envs.excavator.observation import PROFILE_RADII, layout
from motiongym.envs.excavator.params import params_for

REACHED = 2e-3  # rad: a waypoint counts as reached


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

    def _goal(self, wp: bp.Waypoint, q_start: np.ndarray) -> np.ndarray:
        result = solve_pose(np.array(wp.tip), wp.beta, self.m, q_start)
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
    """IK to the target pose (approached from 1 m above), joint-rate tracking."""

    TASK = "reach"

    def new_memory(self) -> dict:
        return {"goals": None, "index": 0}

    def describe(self, memory: dict) -> dict:
        """``planned`` (the IK goals are set) and ``waypoint`` (0: above, 1: target)."""
        return {"planned": memory["goals"] is not None, "waypoint": memory["index"]}

    def act(self, observation: np.ndarray, memory: dict) -> np.ndarray:
        obs = np.asarray(observation, dtype=np.float64)
        q = obs[self.lay["q"]]
        if memory["goals"] is None:
            target = obs[self.lay["target"]]
            tip, beta = target[:3], float(target[3])
            above = bp.Waypoint("above", (tip[0], tip[1], tip[2] + 1.0), beta)
            q_above = self._goal(above, q)
            q_target = self._goal(bp.Waypoint("target", tuple(tip), beta), q_above)
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
    """

    TASK = "dig"

    def new_memory(self) -> dict:
        return {"stage": None, "goals": None, "index": 0, "depth": None}

    def describe(self, memory: dict) -> dict:
        """``stage`` (None, "approach", "dig", "lift", "dump"), ``cut_depth`` (m, None
        before the dig is planned) and ``waypoint`` (index of the goal tracked)."""
        return {"stage": memory["stage"], "cut_depth": memory["depth"], "waypoint": memory["index"]}

    def _set(self, memory: dict, stage: str, waypoints: list[bp.Waypoint], q: np.ndarray):
        goals, q_prev = [], q
        for wp in waypoints:
            q_prev = self._goal(wp, q_prev)
            goals.append(q_prev)
        memory.update(stage=stage, goals=goals, index=0, waypoints=waypoints)

    def _done(self, q: np.ndarray, memory: dict) -> bool:
        return memory["index"] == len(memory["goals"]) - 1 and (
            np.max(np.abs(memory["goals"][-1] - q)) < REACHED
        )

    def act(self, observation: np.ndarray, memory: dict) -> np.ndarray:
        obs = np.asarray(observation, dtype=np.float64)
        q = obs[self.lay["q"]]
        zone = obs[self.lay["zone"]]
        fill = float(obs[self.lay["fill"]][0])
        azimuth = math.atan2(zone[3], zone[2])
        r_near, r_far = math.hypot(zone[0], zone[1]), math.hypot(zone[2], zone[3])
        if memory["stage"] is None:
            # Approach: bucket 2 m above the far end (the ground there is read later).
            self._set(memory, "approach", bp.dig_path(azimuth, r_near, r_far, 0.0, _flat)[:1], q)
        stage = memory["stage"]
        if stage == "approach" and self._done(q, memory):
            profile = obs[self.lay["profile"]]

            def surface(r: float) -> float:
                return float(np.interp(r, PROFILE_RADII, profile))

            ground = max(surface(r) for r in np.linspace(r_near, r_far, 8))
            depth = bp.allowed_depth(zone, obs[self.lay["pipe"]], self.m, self.safety, ground)
            memory["depth"] = depth
            memory["surface"] = surface
            self._set(memory, "dig", bp.dig_path(azimuth, r_near, r_far, depth, surface)[1:], q)
        elif stage == "dig" and (fill >= 0.97 * self.m.bucket_capacity or self._done(q, memory)):
            tip = obs[self.lay["tip"]]
            beta = float(obs[self.lay["bucket"]][0])
            here = memory["surface"](math.hypot(tip[0], tip[1]))
            self._set(memory, "lift", bp.curl_lift_path(tip, beta, here, self.m), q)
        elif stage == "lift" and self._done(q, memory):
            waypoints, _ = bp.carry_dump_path(azimuth, obs[self.lay["truck"]], self.m)
            self._set(memory, "dump", waypoints, q)
        return self._follow(obs, memory)


def _flat(r: float) -> float:
    return 0.0
