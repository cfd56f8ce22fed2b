"""The dual-arm schedules as scripted policies acting from the observation.

At an episode's first step each policy rebuilds both arms' trajectories from
the tasks in the observation (``task.tasks_from_observation``), builds the
collision map (``N_l = 100`` by default, the environment's ``safety_margin``
plus an optional ``plan_margin``) and plans robot 2's schedule; then each step
it reads the step index from the observation's elapsed time and returns the
planned advances: robot 1 always 1 (its nominal schedule, as in the paper),
robot 2 the schedule's 0 or 1. Works for ``control="both"`` (action (2,)) and
``control="robot_2"`` (action (1,)).

Policies: ``boundary-following`` (the paper; falls back to sequential
operation where the method fails, and says so in the memory; on v1 the exact
minimum pure delay, :mod:`.bracket`), ``exhaustive-delay``
(minimum delay over the full map), ``sequential`` (robot 2 starts when robot 1
ends), ``min-makespan`` (robot 2 pauses and resumes on a shortest monotone
path, beyond the paper), ``undelayed`` (both start together: collides on the
sampled "colliding" pairs; a reference only), ``either-waits`` (beyond the
paper: either robot may be the one that waits, whichever finishes first;
``control="both"`` only).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from motiongym.baselines.dual_arm import exact_delay, schedules
from motiongym.baselines.dual_arm.boundary_following import boundary_following
from motiongym.baselines.dual_arm.bracket import exact_delay_search
from motiongym.baselines.dual_arm.collision_map import CollisionMap
from motiongym.baselines.dual_arm.lag_map import LagMap
from motiongym.baselines.policy import ScriptedPolicy
from motiongym.envs.core import check_bool
from motiongym.envs.dual_arm import collision
from motiongym.envs.dual_arm.params import params_for
from motiongym.envs.dual_arm.task import DT, LAYOUT, tasks_from_observation

_ELAPSED = LAYOUT["elapsed"].start


def environment_check(env_kwargs: dict[str, Any], env_id: str | None = None) -> tuple[float, str]:
    """``(safety_margin, check)`` of the environment made with ``env_kwargs``: its margin
    (m) and its ``collision_check`` (``"swept"``: the motion between samples, v1;
    ``"samples"``: the samples, v0), the rule of :mod:`motiongym.envs.dual_arm.collision`.

    With ``env_id``, the ID's registered keywords stand wherever ``env_kwargs`` does not
    give one: a policy told only ``{"control": ...}`` of ``DualArmCell-v1`` plans on v1's
    check, not on the parameters' defaults (v0's samples, whose minimum delay can collide
    between samples on v1)."""
    registered = dict(gym.spec(env_id).kwargs) if env_id else {}
    params = params_for({**registered, **env_kwargs})
    return params.safety_margin, params.collision_check


class _EnvironmentCheck:
    """``safety_margin`` and ``check`` of the environment a policy acts in, read from its
    ``env_kwargs`` and, once :func:`motiongym.baselines.make_policy` has set it, the
    registered keywords of its ``env_id`` (:func:`environment_check`)."""

    env_kwargs: dict[str, Any]
    env_id: str | None

    def _environment(self) -> tuple[float, str]:
        key = self.env_id
        cached = self.__dict__.get("_environment_of")
        if cached is None or cached[0] != key:
            cached = (key, environment_check(self.env_kwargs, key))
            self.__dict__["_environment_of"] = cached
        return cached[1]

    @property
    def safety_margin(self) -> float:
        """The environment's ``safety_margin`` (m)."""
        return self._environment()[0]

    @property
    def check(self) -> str:
        """The environment's ``collision_check``."""
        return self._environment()[1]


class SchedulePolicy(_EnvironmentCheck, ScriptedPolicy):
    """Base: plan robot 2's schedule on the episode's first step, then replay it.

    Args:
        n_levels: ``N_l``, robot 2's length divisions on the map.
        plan_margin: extra clearance (m) the planner demands beyond the
            environment's ``safety_margin``.
        verify: check the plan at the arms' actual samples
            (:func:`motiongym.envs.dual_arm.collision.schedule_collides` on the
            environment's check); where the map's length
            discretisation hid a graze, plan again with the map's margin raised
            by ``replan_step`` (m), at most ``max_replans`` times, then fall back
            to sequential operation (v1: to the exact minimum pure delay). The
            memory records ``margin`` and ``replans`` (the guard's firings); a
            plan that says no pure delay exists (``reason``) is not re-planned.
    """

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        env_kwargs: dict[str, Any] | None = None,
        n_levels: int = 100,
        plan_margin: float = 0.0,
        verify: bool = True,
        replan_step: float = 0.005,
        max_replans: int = 10,
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        if action_space.shape not in ((1,), (2,)):
            raise ValueError(f"expected an action of shape (1,) or (2,), got {action_space.shape}")
        self.n_levels = int(n_levels)
        self.plan_margin = float(plan_margin)
        self._environment()  # a bad keyword is an error when the policy is made
        self.verify, self.replan_step, self.max_replans = verify, replan_step, max_replans

    verifiable = True  # False: the schedule is not meant to be collision free

    @property
    def margin(self) -> float:
        """The clearance the planner demands: ``safety_margin + plan_margin`` (m)."""
        return self.safety_margin + self.plan_margin

    def new_memory(self) -> dict[str, Any]:
        return {"schedule": None, "map": None}

    def plan(self, cmap: CollisionMap, memory: dict[str, Any]) -> schedules.Schedule:
        raise NotImplementedError

    def _plan_verified(self, traj1, traj2, memory: dict[str, Any]) -> schedules.Schedule:
        margin = self.margin
        for replans in range(self.max_replans + 1):
            cmap = CollisionMap.from_tasks(traj1, traj2, self.n_levels, margin, self.check)
            memory.update(margin=margin)
            plan = self.plan(cmap, memory)
            memory.update(map=cmap, replans=replans)
            if memory.get("reason"):  # no pure delay exists: nothing to re-plan
                return plan
            if memory.get("exact"):  # decided step by step on the environment's own rule
                return plan
            if not (self.verify and self.verifiable) or not collision.schedule_collides(
                self.check, traj1, traj2, plan.advances, self.safety_margin
            ):
                return plan
            margin += self.replan_step
        memory["fallback"] = True
        return self._fallback(traj1, traj2, cmap)

    def _fallback(self, traj1, traj2, cmap: CollisionMap) -> schedules.Schedule:
        """Sequential operation on v0; on v1 the exact minimum pure delay, which exists
        whenever sequential operation is collision free (never sequential while a
        shorter pure delay would do)."""
        if self.check == collision.SWEPT:
            delay = exact_delay.true_min_delay(traj1, traj2, self.safety_margin)
            if delay is not None:
                return schedules.delay_schedule(cmap, delay)
        return schedules.sequential(cmap)

    def describe(self, memory: dict[str, Any]) -> dict[str, Any]:
        """``delay`` (samples, None for a schedule that is not a pure delay), ``replans``
        (how often the verification raised the map's margin: the guard's firings),
        ``fallback`` (the plan did not come from the policy's own method),
        ``reason`` (why the policy's method found no delay, "" otherwise)."""
        plan = memory.get("schedule")
        return {
            "delay": None if plan is None else plan.delay,
            "replans": memory.get("replans", 0),
            "fallback": bool(memory.get("fallback", False)),
            "reason": memory.get("reason", ""),
        }

    def act(self, observation: Any, memory: dict[str, Any]) -> np.ndarray:
        obs = np.asarray(observation, dtype=float)
        if memory["schedule"] is None:
            memory["tasks"] = tasks_from_observation(obs)
            traj1, traj2 = memory["tasks"]
            memory["schedule"] = self._plan_verified(traj1, traj2, memory)
        step = int(round(float(obs[_ELAPSED]) / DT))
        adv = memory["schedule"].advances
        a2 = float(adv[step]) if step < len(adv) else 1.0
        if self.action_space.shape == (2,):
            return np.array([1.0, a2], dtype=np.float32)
        return np.array([a2], dtype=np.float32)


class BoundaryFollowingPolicy(SchedulePolicy):
    """The paper's minimum start delay by boundary following (section III).

    On v0 on the paper's map. On v1 boundary following runs on a map of the
    environment's own step check and its delay is then made exact
    (:func:`.bracket.exact_delay_search`): the minimum pure delay on v1's
    check, each of its steps decided by the environment's own rule, so it is
    not verified again (the verification's halving alone would only repeat
    it, at twice the search's cost); where none exists (``reason`` in the
    memory: e.g. the arms collide at rest) robot 2 starts when robot 1 ends,
    reported as a fallback.

    ``replan`` (not the paper's; for a DAgger teacher): instead of replaying
    the planned schedule by the clock, every step asks of the current state
    (robot 1's and robot 2's progress in the observation) whether "go now at
    full speed" is collision free to the end on the environment's own check
    (:class:`.lag_map.LagMap`, v0's or v1's), and advances robot 2 only then.
    From its own start that is the minimum pure delay on that check (on v0,
    the exhaustive one, not the paper's map's); from a state a learner
    reached (robot 2 started early, or stopped part-way) it answers for that
    state, where a replayed schedule would only read the clock.
    """

    def __init__(self, observation_space, action_space, env_kwargs=None, replan=False, **kwargs):
        super().__init__(observation_space, action_space, env_kwargs, **kwargs)
        self.replan = check_bool("replan", replan)

    def new_memory(self) -> dict[str, Any]:
        return {**super().new_memory(), "lag_map": None}

    def act(self, observation: Any, memory: dict[str, Any]) -> np.ndarray:
        if not self.replan:
            return super().act(observation, memory)
        obs = np.asarray(observation, dtype=float)
        if memory["lag_map"] is None:
            traj1, traj2 = tasks_from_observation(obs)
            memory["lag_map"] = LagMap(traj1, traj2, self.safety_margin, self.check)
        lag_map = memory["lag_map"]
        x, p2 = lag_map.state(obs)
        a2 = 1.0 if lag_map.clear_now(x, p2) else 0.0
        if self.action_space.shape == (2,):
            return np.array([1.0, a2], dtype=np.float32)
        return np.array([a2], dtype=np.float32)

    def plan(self, cmap: CollisionMap, memory: dict[str, Any]) -> schedules.Schedule:
        if self.check == collision.SWEPT:
            traj1, traj2 = memory["tasks"]
            found = exact_delay_search(traj1, traj2, self.n_levels, memory["margin"])
            memory.update(result=found, fallback=found.delay is None, reason=found.reason)
            memory["exact"] = found.delay is not None
            if found.delay is None:
                return schedules.sequential(cmap)
            return schedules.delay_schedule(cmap, found.delay)
        result = boundary_following(cmap)
        memory["result"] = result
        memory["fallback"] = result.delay is None
        if result.delay is None:
            traj1, traj2 = memory["tasks"]
            return self._fallback(traj1, traj2, cmap)
        return schedules.delay_schedule(cmap, result.delay)


class ExhaustiveDelayPolicy(SchedulePolicy):
    """Minimum start delay by scanning every delay on the full map."""

    def plan(self, cmap: CollisionMap, memory: dict[str, Any]) -> schedules.Schedule:
        if self.check == collision.SWEPT:  # v1: the exact minimum on its check, not a map
            traj1, traj2 = memory["tasks"]
            delay = exact_delay.true_min_delay(traj1, traj2, self.safety_margin)
        else:
            delay = schedules.exhaustive_min_delay(cmap)
        return schedules.delay_schedule(cmap, cmap.n1 if delay is None else delay)


class SequentialPolicy(SchedulePolicy):
    """Robot 2 starts when robot 1 has finished."""

    def plan(self, cmap: CollisionMap, memory: dict[str, Any]) -> schedules.Schedule:
        return schedules.sequential(cmap)


class MinMakespanPolicy(SchedulePolicy):
    """Robot 2 pauses and resumes on the shortest monotone path through free cells."""

    def plan(self, cmap: CollisionMap, memory: dict[str, Any]) -> schedules.Schedule:
        found = schedules.min_makespan(cmap)
        return found if found is not None else schedules.sequential(cmap)


class EitherWaitsPolicy(_EnvironmentCheck, ScriptedPolicy):
    """Either robot may wait: the shortest makespan over both robots' pure delays.

    Not the paper's method. The paper keeps robot 1 on its nominal schedule
    and delays robot 2; whenever robot 1 waiting for robot 2 finishes sooner,
    this policy lets robot 1 yield instead. Every step, from the current state
    (both arms' progress in the observation), it reads both orders' lag maps
    (:class:`.lag_map.LagMap`, on the environment's own check, v0's or v1's)
    for each order's smallest collision-free wait ``w`` ("the yielding robot
    waits ``w`` more steps, then both run at full speed") and when both arms
    would be done after it (:meth:`.lag_map.LagMap.finish`), and takes the order
    that ends first, robot 2 yielding on a tie (the paper's order).
    The running robot advances; the yielding one only when its ``w`` is 0.

    Makespan. Following the chosen order for one step leaves that order's
    plan, one step shorter, open from the next state, so the best finishing
    time never moves later: the episode takes at most
    ``min(max(N1, D2 + N2), max(N2, D1 + N1))`` steps, ``D2`` and ``D1`` each
    order's minimum pure delay (:func:`.exact_delay.true_min_delay` in either
    order; an order without one drops out). That is the makespan exactly
    while one robot does all the waiting (tested against brute force in the
    environment). It is shorter where, part-way, the other order finishes
    sooner from the state reached: the policy then switches, and both robots
    wait in the episode (robot 2 first, then robot 1, say). No closed form
    covers those episodes: their makespan is what the re-planning reaches,
    never more than the bound. Where neither order has a free wait (the arms
    collide at rest) robot 1 runs and robot 2 waits.

    Needs ``control="both"``: under ``control="robot_2"`` robot 1 cannot yield.
    It plans on no map, so it takes none of the map policies' settings.
    """

    def __init__(
        self,
        observation_space: spaces.Space,
        action_space: spaces.Space,
        env_kwargs: dict[str, Any] | None = None,
    ) -> None:
        super().__init__(observation_space, action_space, env_kwargs)
        if action_space.shape != (2,):
            raise ValueError(
                f"either-waits moves both robots: it needs control='both' (an action of "
                f"shape (2,)), got an action of shape {action_space.shape}"
            )
        self._environment()  # a bad keyword is an error when the policy is made

    def new_memory(self) -> dict[str, Any]:
        return {"lag_maps": None, "yields": None}

    def act(self, observation: Any, memory: dict[str, Any]) -> np.ndarray:
        obs = np.asarray(observation, dtype=float)
        if memory["lag_maps"] is None:
            traj1, traj2 = tasks_from_observation(obs)
            memory["lag_maps"] = (
                LagMap(traj1, traj2, self.safety_margin, self.check),  # robot 2 yields
                LagMap(traj2, traj1, self.safety_margin, self.check),  # robot 1 yields
            )
        best = None  # (steps, yielding robot, wait)
        for lag_map in memory["lag_maps"]:
            found = lag_map.finish(*lag_map.state(obs))
            if found is not None and (best is None or found[1] < best[0]):
                best = (found[1], lag_map.wait, found[0])
        if best is None:
            return np.array([1.0, 0.0], dtype=np.float32)
        _, yielding, wait = best
        memory["yields"] = yielding
        action = np.ones(2, dtype=np.float32)
        action[yielding] = 1.0 if wait == 0 else 0.0
        return action

    def describe(self, memory: dict[str, Any]) -> dict[str, Any]:
        """``yields``: the robot (0: robot 1, 1: robot 2) that the last step's chosen order
        had wait, None before the first step or where neither order had a free wait."""
        return {"yields": memory.get("yields")}


class UndelayedPolicy(SchedulePolicy):
    """Both arms start together and run at nominal speed (no coordination)."""

    verifiable = False

    def plan(self, cmap: CollisionMap, memory: dict[str, Any]) -> schedules.Schedule:
        return schedules.delay_schedule(cmap, 0)
