"""Excavator scripted policies: reach and dig cycle success rates; path generator; tracking."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.evaluation import evaluate_policy

import motiongym  # noqa: F401
from motiongym.agents.environments import resolved_env_kwargs
from motiongym.agents.evaluation.episodes import run_episode
from motiongym.baselines.excavator import bucket_path as bp
from motiongym.baselines.excavator.tracking import solve_pose, track
from motiongym.baselines.registry import make_policy
from motiongym.envs.excavator.config import DEFAULT_MACHINE as M
from motiongym.envs.excavator.kinematics import bucket_angle, forward

CONTACTS = ("pipe_contact", "truck_contact", "ground_contact", "self_contact")


def _episodes(env_id: str, name: str, seeds, style=None) -> list[dict]:
    """Episodes through the one episode loop; the last info, cost and contacts summed."""
    env = gym.make(env_id)
    kwargs = resolved_env_kwargs(env_id, None)
    policy = make_policy(env_id, name, env.observation_space, env.action_space, kwargs)
    if style is not None:
        policy.style = style
    out = []
    for seed in seeds:
        seen = {"cost_sum": 0.0, "min_pipe": np.inf, **dict.fromkeys(CONTACTS, 0.0)}

        def hook(step, seen=seen) -> None:
            seen["info"] = step.info
            seen["cost_sum"] += step.info["cost"]
            seen["min_pipe"] = min(seen["min_pipe"], step.info["pipe_clearance"])
            for kind in CONTACTS:
                seen[kind] += step.info.get(kind, 0.0)

        run_episode(env, policy, seed, hook=hook)
        out.append({**seen.pop("info"), **seen})
    return out


def test_reach_policy_succeeds_on_every_scene():
    results = _episodes("motiongym/ExcavatorReach-v0", "newton-raphson-reach", range(12))
    assert all(r["is_success"] for r in results)
    assert all(r["cost_sum"] == 0.0 for r in results)


def test_dig_cycle_policy_delivers_without_touching_the_pipe():
    results = _episodes("motiongym/Excavator-v0", "dig-cycle", range(6))
    assert all(r["is_success"] for r in results)
    assert all(r["pipe_contact"] == 0.0 and r["cost_sum"] == 0.0 for r in results)
    assert all(r["min_pipe"] >= 0.5 for r in results)
    assert np.mean([r["truck_soil"] for r in results]) >= 0.8 * M.bucket_capacity
    assert all(r["spill"] <= 0.05 for r in results)
    assert all(r["outside_zone"] <= 0.01 for r in results)
    assert all(r["elapsed"] < 30.0 for r in results)


def test_policies_work_through_sb3_vector_envs():
    vec = make_vec_env("motiongym/ExcavatorReach-v0", n_envs=2, seed=0)
    policy = make_policy(
        "motiongym/ExcavatorReach-v0",
        "newton-raphson-reach",
        vec.observation_space,
        vec.action_space,
        {},
    )
    mean_reward, _ = evaluate_policy(policy, vec, n_eval_episodes=4)
    assert mean_reward > 0.0


def test_allowed_depth_keeps_the_bucket_above_a_pipe_under_the_zone():
    zone = np.array([5.0, 0.0, 8.0, 0.0, 1.0])
    under = np.array([6.5, -8.0, -2.0, 6.5, 8.0, -2.0, 0.15])  # crossing under the strip
    depth = bp.allowed_depth(zone, under, M, safety=0.5)
    lowest = -depth - M.link_radius[2]  # bucket capsule bottom at the cut depth
    assert lowest - (-2.0 + 0.15) == pytest.approx(0.5 + bp.PIPE_MARGIN)
    away = np.array([20.0, -8.0, -2.0, 20.0, 8.0, -2.0, 0.15])
    assert bp.allowed_depth(zone, away, M, safety=0.5) == 1.0
    deep = np.array([6.5, -8.0, -6.0, 6.5, 8.0, -6.0, 0.15])
    assert bp.allowed_depth(zone, deep, M, safety=0.5) == 1.0


def test_dig_path_follows_the_surface_at_the_cut_depth():
    path = bp.dig_path(0.3, 5.0, 8.0, 0.7, lambda r: 0.1 * r)
    drag = [w for w in path if w.phase == "drag"]
    for w in drag:
        r = np.hypot(w.tip[0], w.tip[1])
        assert w.tip[2] == pytest.approx(0.1 * r - 0.7)
        assert np.arctan2(w.tip[1], w.tip[0]) == pytest.approx(0.3)
    assert np.hypot(*drag[-1].tip[:2]) == pytest.approx(5.0)
    gaps = np.diff([np.hypot(*w.tip[:2]) for w in drag])
    assert np.all(np.abs(gaps) <= bp.DRAG_STEP + 1e-9)


def test_tracking_is_synchronised_and_dead_beat():
    q, goal = np.zeros(4), np.array([0.5, -0.03, 0.02, 0.0])
    a = track(q, goal, M, 0.1)
    assert np.max(np.abs(a)) == pytest.approx(1.0)
    step = a * np.array(M.rate_max) * 0.1
    assert step / np.linalg.norm(step) == pytest.approx(goal / np.linalg.norm(goal))
    small = np.array([0.01, 0.0, -0.02, 0.03])
    np.testing.assert_allclose(track(q, small, M, 0.1) * np.array(M.rate_max) * 0.1, small)


def test_solve_pose_handles_large_bucket_turns_near_90_degrees_of_swing():
    q = np.array([1.8, 0.9, -1.5, 0.2])
    h = forward(q, M)
    result = solve_pose(h[:3, 3], bucket_angle(q), M, q_start=np.array([1.8, 0.9, -1.5, -2.0]))
    assert result.converged


def test_policies_rebuild_a_different_machine_from_env_kwargs():
    kwargs = {"machine": {"L2": 6.2, "L3": 3.1, "d1": 2.2}}
    env = gym.make("motiongym/ExcavatorReach-v0", **kwargs)
    policy = make_policy(
        "motiongym/ExcavatorReach-v0",
        "newton-raphson-reach",
        env.observation_space,
        env.action_space,
        kwargs,
    )
    for seed in range(4):
        obs, _ = env.reset(seed=seed)
        start, done = True, False
        while not done:
            action, _ = policy.predict(obs, episode_start=start)
            start = False
            obs, _, terminated, truncated, info = env.step(action)
            done = terminated or truncated
        assert info["is_success"]


def test_tracking_with_acceleration_limits_ramps_and_stops_at_the_goal():
    # A double integrator within the limits reaches the goal without overshoot.
    accel = np.array([0.6, 0.5, 0.6, 1.0])
    dt, rate_max = 0.1, np.array(M.rate_max)
    q, qdot, goal = np.zeros(4), np.zeros(4), np.array([1.0, -0.4, 0.5, 0.8])
    for _ in range(200):
        a = track(q, goal, M, dt, qdot=qdot, accel_max=accel)
        rate = a * rate_max
        assert np.all(np.abs(rate - qdot) <= accel * dt + 1e-6)
        assert np.all(np.abs(rate) <= rate_max + 1e-6)
        qdot = rate
        q = q + rate * dt
        assert np.all(np.sign(goal) * (goal - q) >= -1e-3)  # never past the goal (by 1 mrad)
    np.testing.assert_allclose(q, goal, atol=1e-3)
    # Ablation: without the limits the first step asks for full rate at once.
    first = track(np.zeros(4), goal, M, dt) * rate_max
    assert np.max(np.abs(first) / accel) / dt > 10.0


def _executed_tip_path(waypoints, q_start):
    """Tip (r, z) and bucket angle along the joint-space straight lines the tracker follows."""
    from motiongym.envs.excavator.kinematics import arm_points

    q_prev, out = q_start, []
    for wp in waypoints:
        q_goal = solve_pose(np.array(wp.tip), wp.beta, M, q_prev).q
        for s in np.linspace(0.0, 1.0, 21)[1:]:
            q = q_prev + s * (q_goal - q_prev)
            tip = arm_points(*q, M)[3]
            out.append((np.hypot(tip[0], tip[1]), tip[2], float(q[1:].sum())))
        q_prev = q_goal
    return np.array(out), q_prev


def test_the_bucket_cuts_only_with_its_opening_ahead():
    rng = np.random.default_rng(5)
    worst = np.inf
    for _ in range(20):
        r_far = rng.uniform(7.0, 8.5)
        r_near = r_far - rng.uniform(2.5, 3.5)
        depth = rng.uniform(0.3, 1.0)
        tilt = rng.uniform(-0.03, 0.03)
        surface = lambda r, t=tilt: t * (r - 6.0)  # noqa: E731
        path = bp.dig_path(rng.uniform(-0.6, 0.6), r_near, r_far, depth, surface)
        rzb, q_end = _executed_tip_path(path, np.array(M.q_ready))
        tip = np.array(path[-1].tip)
        curl = bp.curl_lift_path(tip, path[-1].beta, surface(np.hypot(*tip[:2])), M)
        rzb2, _ = _executed_tip_path(curl[:1], q_end)
        rzb = np.vstack([rzb, rzb2])
        motion = np.diff(rzb[:, :2], axis=0)
        length = np.linalg.norm(motion, axis=1)
        n = np.stack([np.sin(rzb[1:, 2]), -np.cos(rzb[1:, 2])], axis=1)
        in_soil = (rzb[1:, 1] < surface(rzb[1:, 0]) - 0.02) & (length > 1e-6)
        cosine = np.sum(n * motion, axis=1)[in_soil] / length[in_soil]
        worst = min(worst, float(cosine.min()))
    assert worst > 0.3  # never heel first or sideways: within 73 deg of the opening


def test_policies_read_the_environment_parameters_not_copies():
    from motiongym.baselines.excavator.policies import DigCyclePolicy

    kwargs = {"dt": 0.05, "pipe_safety": 0.7, "machine": {"L3": 3.1}}
    env = gym.make("motiongym/Excavator-v0", **kwargs)
    policy = DigCyclePolicy(env.observation_space, env.action_space, kwargs)
    assert policy.params == env.unwrapped.params
    plain = DigCyclePolicy(env.observation_space, env.action_space, {})
    assert (plain.dt, plain.safety) == (gym.make("motiongym/Excavator-v0").unwrapped.dt, 0.5)


def test_solve_pose_on_a_slope():
    from motiongym.envs.excavator.kinematics import base_pose

    base = base_pose((0.5, -0.3, 0.2), (0.08, -0.12, 0.3))  # about 8 deg of roll, 7 of pitch
    rng = np.random.default_rng(9)
    for q in rng.uniform(np.array(M.q_min) + 0.1, np.array(M.q_max) - 0.1, size=(30, 4)):
        h = forward(q, M, base)
        result = solve_pose(h[:3, 3], bucket_angle(q), M, base=base)
        assert result.converged
        np.testing.assert_allclose(forward(result.q, M, base)[:3, 3], h[:3, 3], atol=1e-3)


def test_tracking_keeps_the_shared_pump_within_its_flow():
    share = np.array([0.45, 0.95, 0.95, 0.45])
    goal = np.array([0.8, 0.5, -0.6, 0.9])
    a = track(np.zeros(4), goal, M, 0.1, pump_share=share)
    assert np.sum(np.abs(a) * share) == pytest.approx(1.0)
    step = a * np.array(M.rate_max)
    assert step / np.linalg.norm(step) == pytest.approx(goal / np.linalg.norm(goal))
    # Ablation: without it all four at once ask for 2.8 times the pump's flow.
    assert np.sum(np.abs(track(np.zeros(4), goal, M, 0.1)) * share) > 1.5


def _clean(r: dict) -> bool:
    return r["truck_soil"] >= 0.8 and all(r[kind] == 0.0 for kind in CONTACTS)


def test_dig_cycle_on_v1_delivers_without_any_contact():
    # Slope, hydraulics, a ground that stops every part but a cutting edge.
    results = _episodes("motiongym/Excavator-v1", "dig-cycle", range(2000, 2010))
    assert all(r["is_success"] and _clean(r) for r in results)


def test_ablation_the_v0_path_on_v1_is_stopped_by_the_ground():
    # The v0 plunge (steep entry, pin fixed while curling) on the v1 world.
    results = _episodes("motiongym/Excavator-v1", "dig-cycle", range(2000, 2010), bp.V0_STYLE)
    assert sum(_clean(r) for r in results) <= 2  # measured: 0 of 10 (v1 style: 10 of 10)
    assert sum(r["ground_contact"] > 0 for r in results) >= 3  # measured: 5 of 10


def test_reach_policy_on_v1():
    results = _episodes("motiongym/ExcavatorReach-v1", "newton-raphson-reach", range(20))
    clean = [r["is_success"] and all(r[k] == 0.0 for k in CONTACTS) for r in results]
    assert sum(clean) >= 17


@pytest.mark.parametrize(
    ("env_id", "seeds"),
    [("motiongym/ExcavatorReach-v0", range(8)), ("motiongym/ExcavatorReach-v1", range(4))],
)
def test_replanning_reach_acts_from_the_observation_alone(env_id, seeds):
    """``replan``: a fresh policy (no memory) gives the same action as the one that has run
    the episode, at every step; the plan made once does not (the ablation: after its first
    goal is reached a fresh plan heads 1 m above again); both reach every target here (50
    held-out scenes, docs/experiments/ExcavatorReach-v0.md: replan 100 % on v0, 94 % on v1,
    the plan-once policy's failures)."""
    env = gym.make(env_id)
    make = lambda **kw: make_policy(  # noqa: E731
        env_id,
        "newton-raphson-reach",
        env.observation_space,
        env.action_space,
        env.spec.kwargs,
        **kw,
    )
    gaps = {True: [], False: []}
    for replan in (True, False):
        running = make(replan=replan)
        for seed in seeds:
            obs, _ = env.reset(seed=seed)
            running.reset()
            done = False
            while not done:
                action, _ = running.predict(obs)
                fresh, _ = make(replan=replan).predict(obs)
                gaps[replan].append(float(np.max(np.abs(action - fresh))))
                obs, _, terminated, truncated, info = env.step(action)
                done = terminated or truncated
            assert info["is_success"], (replan, seed)
    assert max(gaps[True]) == 0.0
    assert max(gaps[False]) > 0.3


def test_replan_must_be_a_bool():
    env = gym.make("motiongym/ExcavatorReach-v0")
    with pytest.raises(ValueError, match="replan"):
        make_policy(
            "motiongym/ExcavatorReach-v0",
            "newton-raphson-reach",
            env.observation_space,
            env.action_space,
            env.spec.kwargs,
            replan="yes",
        )


def test_dig_cycle_tolerance_is_checked_and_defaults_to_reached():
    from motiongym.baselines.excavator.policies import REACHED

    env = gym.make("motiongym/Excavator-v1")
    make = lambda **kw: make_policy(  # noqa: E731
        "motiongym/Excavator-v1",
        "dig-cycle",
        env.observation_space,
        env.action_space,
        env.spec.kwargs,
        **kw,
    )
    assert make().tolerance == REACHED == 2e-3
    assert make(tolerance=0.01).new_memory()["tolerance"] == 0.01
    for bad in (0.0, -0.01, 0.6, float("nan"), "0.01"):
        with pytest.raises(ValueError, match="tolerance must be a finite number in"):
            make(tolerance=bad)
