"""The harvest-arm algorithms (paper eq. 1-11) and the scripted policies."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from scipy.optimize import minimize

import motiongym  # noqa: F401
from motiongym.baselines import make_policy, scripted_policies
from motiongym.baselines.harvest_arm.potential_field import (
    AVOIDANCE,
    TARGET,
    TRAJECTORY,
    eta_from_eq6,
    field_direction,
    obstacle_magnitude,
    plan_path,
    target_magnitude,
)
from motiongym.baselines.harvest_arm.redundancy import limited_rates, weighted_rates
from motiongym.baselines.harvest_arm.reference_velocity import (
    bar_obstacle_terms,
    combine,
    point_obstacle_terms,
    trajectory_following,
)
from motiongym.envs.geometry import closest_point_on_segment, closest_points_between_segments
from motiongym.envs.harvest_arm.model import ArmKinematics, arm_spec

SPEED, DT, LINK_R = 0.2, 0.05, 0.02


# ---------------------------------------------------------------- eq. 4-7
@pytest.mark.parametrize("params", [TRAJECTORY, TARGET, AVOIDANCE])
def test_eq6_eta_gives_m_at_k_rho0(params):
    assert obstacle_magnitude(params.k_rho0, params) == pytest.approx(params.m)
    assert obstacle_magnitude(params.rho0 + 1e-9, params) == 0.0
    assert obstacle_magnitude(params.rho0, params) == pytest.approx(0.0, abs=1e-12)
    assert params.eta == pytest.approx(eta_from_eq6(params.m, params.k_rho0, params.rho0))


def test_table_1_values_and_the_target_term():
    assert TRAJECTORY.eta == pytest.approx(0.6 * 0.1**2 / (10 - 5))
    assert target_magnitude(0.2) == pytest.approx(1.0 + 1.0)  # 1 + m at k d0
    assert target_magnitude(0.5) == 1.0
    with pytest.raises(ValueError, match="k\\*rho0"):
        eta_from_eq6(0.6, 0.3, 0.2)


def test_path_without_obstacles_is_the_straight_line_with_even_steps():
    empty = np.zeros((0, 3))
    path = plan_path(np.zeros(3), np.array([0.3, 0.4, 0.0]), empty, empty, np.zeros(0))
    np.testing.assert_allclose(path[-1], [0.3, 0.4, 0.0])
    assert np.abs(np.cross(path, [0.6, 0.8, 0.0])).max() < 1e-9  # on the line
    steps = np.linalg.norm(np.diff(path[:-1], axis=0), axis=1)
    np.testing.assert_allclose(steps, SPEED * DT, rtol=1e-6)


def test_path_goes_around_a_sphere_on_the_straight_line():
    start, fruit = np.array([0.0, 0.0]), np.array([0.6, 0.0])
    centre, r = np.array([[0.3, 0.01]]), np.array([0.02])
    path = plan_path(start, fruit, centre, centre, r, gripper_radius=LINK_R)
    np.testing.assert_allclose(path[-1], fruit)
    clearance = np.linalg.norm(path - centre, axis=1) - r - LINK_R
    assert clearance.min() > 0.05  # the straight line would hit it
    # the field pushes away from the obstacle: below it (it sits above the line)
    assert path[:, 1].min() < -0.05
    v = field_direction(np.array([0.2, 0.0]), fruit, centre, centre, r, LINK_R)
    assert np.linalg.norm(v) == pytest.approx(1.0) and v[1] < 0


def test_a_local_minimum_is_escaped_or_reported():
    """An obstacle exactly between gripper and fruit: eq. 7 alone stalls before it."""
    start, fruit = np.array([0.0, 0.0]), np.array([0.6, 0.0])
    centre, r = np.array([[0.4, 0.0]]), np.array([0.03])
    stuck = plan_path(start, fruit, centre, centre, r, gripper_radius=LINK_R, escape=False)
    assert np.linalg.norm(stuck[-1] - fruit) > 0.1  # stopped in front of the obstacle
    assert stuck[-1][0] < 0.4
    path = plan_path(start, fruit, centre, centre, r, gripper_radius=LINK_R)
    np.testing.assert_allclose(path[-1], fruit)
    clearance = np.linalg.norm(path - centre, axis=1) - r - LINK_R
    assert clearance.min() > 0.03
    assert np.linalg.norm(np.diff(path, axis=0), axis=1).max() < 2 * SPEED * DT


def test_path_keeps_clear_of_a_bar_across_the_way():
    a, b = np.array([[0.3, -0.1, 0.05]]), np.array([[0.3, 0.2, 0.05]])
    path = plan_path(np.zeros(3), np.array([0.6, 0.0, 0.0]), a, b, np.array([0.008]))
    dist, _ = closest_point_on_segment(path, a, b)
    assert dist.min() - 0.008 > 0.04
    np.testing.assert_allclose(path[-1], [0.6, 0.0, 0.0])


# ---------------------------------------------------------------- eq. 1
def _random_problem(rng, n=7, m=5, dim=3):
    jacs = rng.normal(size=(m, dim, n))
    refs = rng.normal(size=(m, dim))
    weights = rng.uniform(0.5, 2.0, m)
    return jacs[-1], rng.normal(size=dim), jacs, refs, weights


def test_weighted_pseudo_inverse_meets_the_gripper_velocity_exactly():
    rng = np.random.default_rng(0)
    for _ in range(5):
        jn, x_dot, jacs, refs, w = _random_problem(rng)
        theta = weighted_rates(jn, x_dot, jacs, refs, w)
        np.testing.assert_allclose(jn @ theta, x_dot, atol=1e-9)


def test_weighted_pseudo_inverse_is_the_constrained_least_squares_optimum():
    rng = np.random.default_rng(1)
    jn, x_dot, jacs, refs, w = _random_problem(rng)

    def cost(theta):
        return sum(k * np.sum((j @ theta - r) ** 2) for k, j, r in zip(w, jacs, refs, strict=True))

    generic = minimize(
        cost,
        np.zeros(jn.shape[1]),
        method="SLSQP",
        constraints=[{"type": "eq", "fun": lambda t: jn @ t - x_dot}],
        options={"ftol": 1e-14, "maxiter": 500},
    )
    ours = weighted_rates(jn, x_dot, jacs, refs, w)
    np.testing.assert_allclose(ours, generic.x, atol=1e-5)
    assert cost(ours) <= generic.fun + 1e-9
    # eq. 1 literally: J* X_dot + (I - J* Jn) S1^-1 S2
    s1 = sum(2 * k * j.T @ j for k, j in zip(w, jacs, strict=True))
    s2 = sum(2 * k * j.T @ r for k, j, r in zip(w, jacs, refs, strict=True))
    a = np.linalg.inv(s1)
    j_star = a @ jn.T @ np.linalg.inv(jn @ a @ jn.T)
    literal = j_star @ x_dot + (np.eye(len(a)) - j_star @ jn) @ a @ s2
    np.testing.assert_allclose(ours, literal, atol=1e-8)


def test_singular_pose_stays_finite_and_within_limits():
    spec = arm_spec(5, planar=True)
    kin = ArmKinematics(spec)
    q = np.zeros(5)  # stretched: Jn has rank 1
    points, jacs = kin.jacobians(q)
    for x_dot in ([SPEED, 0.0], [0.0, SPEED], [SPEED, SPEED]):  # along, across, both
        refs = np.zeros_like(points)
        refs[-1] = x_dot
        rates = limited_rates(
            jacs[-1],
            np.array(x_dot),
            jacs,
            refs,
            np.ones(len(points)),
            q,
            spec.limits,
            spec.speeds,
            DT,
        )
        assert np.isfinite(rates).all()
        assert (np.abs(rates) <= spec.speeds + 1e-9).all()
    # drive the gripper outwards through the stretched pose and back: always finite
    spatial = arm_spec(7, planar=False)
    kin = ArmKinematics(spatial)
    q = np.zeros(7)
    for step in range(40):
        points, jacs = kin.jacobians(q)
        x_dot = np.array([0.0, 0.0, SPEED if step < 20 else -SPEED])
        refs = np.zeros_like(points)
        refs[-1] = x_dot
        rates = limited_rates(
            jacs[-1], x_dot, jacs, refs, np.ones(len(points)), q, spatial.limits, spatial.speeds, DT
        )
        assert np.isfinite(rates).all()
        q = q + rates * DT
        assert (np.abs(q) <= spatial.limits + 1e-9).all()


def test_limits_hold_a_joint_at_its_range_and_re_solve_the_rest():
    spec = arm_spec(4, planar=True)
    kin = ArmKinematics(spec)
    q = np.array(spec.home)
    q[1] = spec.limits[1] - 1e-3  # joint 2 at its upper range
    points, jacs = kin.jacobians(q)
    x_dot = np.array([0.0, -SPEED])
    refs = np.zeros_like(points)
    refs[-1] = x_dot
    free = weighted_rates(jacs[-1], x_dot, jacs, refs, np.ones(len(points)))
    rates = limited_rates(
        jacs[-1], x_dot, jacs, refs, np.ones(len(points)), q, spec.limits, spec.speeds, DT
    )
    assert q[1] + rates[1] * DT <= spec.limits[1] + 1e-12
    assert (np.abs(rates) <= spec.speeds + 1e-12).all()
    if q[1] + free[1] * DT > spec.limits[1]:  # the limit was binding: the rest still tracks
        np.testing.assert_allclose(jacs[-1] @ rates, x_dot, atol=1e-6)


# ---------------------------------------------------------------- eq. 8-11
def _follow(kin, spec, v_of_t, sign, steps=60):
    """Drive the gripper along directions ``v_of_t`` with trajectory following only."""
    q = np.array(spec.home)
    trail, joints = [], []
    for t in range(steps):
        points, jacs = kin.jacobians(q)
        v = v_of_t(t)
        refs = combine(trajectory_following(points, v, sign), np.zeros_like(points), SPEED)
        refs[-1] = SPEED * v
        rates = limited_rates(
            jacs[-1], SPEED * v, jacs, refs, np.ones(len(points)), q, spec.limits, spec.speeds, DT
        )
        q = q + rates * DT
        trail.append(points[-1])
        joints.append(points[1:-1])
    return np.array(trail), np.array(joints)


def _trace_error(trail, joints, first):
    """Mean distance of each joint to the gripper's path travelled so far: (P-2,)."""
    errors = []
    for t in range(first, len(trail)):
        d, _ = closest_point_on_segment(joints[t][:, None], trail[None, :t], trail[None, 1 : t + 1])
        errors.append(d.min(axis=1))
    return np.mean(errors, axis=0)


def test_trajectory_following_makes_the_joints_trace_the_gripper_path():
    """Paper Fig. 3: without obstacles the joints trace the gripper's path."""
    spec = arm_spec(5, planar=True)
    kin = ArmKinematics(spec)

    def curve(t):
        return np.array([np.cos(-0.3 - 0.02 * t), np.sin(-0.3 - 0.02 * t)])

    printed = _trace_error(*_follow(kin, spec, curve, +1.0), first=30)
    flipped = _trace_error(*_follow(kin, spec, curve, -1.0), first=30)
    # the joint next to the gripper runs along the gripper's path ...
    assert printed[-1] < 0.09
    # ... and the printed sign traces better than the opposite one, joint by joint
    assert (printed[1:] < flipped[1:] - 0.01).all()


def test_trajectory_term_is_perpendicular_to_each_link():
    points = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.3], [0.3, 0.0, 0.3], [0.3, 0.2, 0.3]])
    v = np.array([0.6, 0.0, 0.8])
    w = trajectory_following(points, v)
    u = np.diff(points, axis=0) / np.linalg.norm(np.diff(points, axis=0), axis=1)[:, None]
    np.testing.assert_allclose(np.sum(w[:-1] * u, axis=1), 0.0, atol=1e-12)
    np.testing.assert_allclose(w[0], np.cross(np.cross(v, u[0]), u[0]))
    assert not w[-1].any()  # the gripper follows its own path


def _push(planar_dof, obstacle_terms, clearance, steps=10):
    """Hold the gripper still and let the avoidance terms move the arm."""
    spec = arm_spec(planar_dof, planar=True) if planar_dof else arm_spec(7, planar=False)
    kin = ArmKinematics(spec)
    q = np.array(spec.home)
    gripper0 = kin.forward(q)[-1]
    history = []
    for _ in range(steps):
        points, jacs = kin.jacobians(q)
        history.append(clearance(points))
        refs = combine(np.zeros_like(points), obstacle_terms(points), SPEED)
        refs[-1] = 0.0
        zero = np.zeros(points.shape[1])
        rates = limited_rates(
            jacs[-1], zero, jacs, refs, np.ones(len(points)), q, spec.limits, spec.speeds, DT
        )
        q = q + rates * DT
    history.append(clearance(kin.forward(q)))
    return np.array(history), np.linalg.norm(kin.forward(q)[-1] - gripper0)


@pytest.mark.parametrize("link", [1, 2, 3])
def test_a_point_obstacle_next_to_a_link_pushes_the_link_away(link):
    """Paper Fig. 5."""
    spec = arm_spec(5, planar=True)
    home = ArmKinematics(spec).forward(np.array(spec.home))
    u = home[link + 1] - home[link]
    normal = np.array([-u[1], u[0]]) / np.linalg.norm(u)
    centre = 0.5 * (home[link] + home[link + 1]) + 0.09 * normal
    r = np.array([0.015])

    def terms(points):
        return point_obstacle_terms(points, centre[None], r, LINK_R)

    def clearance(points):
        d, _ = closest_point_on_segment(centre, points[link], points[link + 1])
        return d - r[0] - LINK_R

    history, gripper_drift = _push(5, terms, clearance)
    assert terms(home)[link] @ normal < 0  # the term at X_i points away from the obstacle
    assert history[-1] > history[0] + 0.02
    assert gripper_drift < 0.01


def test_a_bar_obstacle_across_a_link_pushes_the_link_away():
    """Paper Fig. 6: a branch crossing the forearm of the 7-DOF arm."""
    spec = arm_spec(7, planar=False)
    home = ArmKinematics(spec).forward(np.array(spec.home))
    elbow, wrist = home[2], home[3]
    mid = 0.5 * (elbow + wrist)
    a, b = mid + [0.0, 0.08, -0.2], mid + [0.0, 0.08, 0.2]  # upright, 8 cm to the side

    def terms(points):
        return bar_obstacle_terms(points, a[None], b[None], np.array([0.008]), LINK_R)

    def clearance(points):
        d, _, _ = closest_points_between_segments(points[2], points[3], a, b)
        return d - 0.008 - LINK_R

    history, gripper_drift = _push(None, terms, clearance)
    assert terms(home)[2, 1] < 0  # the elbow X_i is pushed to -y, away from the bar
    assert history[-1] > history[0] + 0.02
    assert gripper_drift < 0.01
    # a bar whose common perpendicular misses the link does nothing (paper's test)
    far_a, far_b = wrist + [0.3, -0.2, 0.05], wrist + [0.3, 0.2, 0.05]
    off = bar_obstacle_terms(home, far_a[None], far_b[None], np.array([0.008]), LINK_R)
    assert not off[2].any()


def test_eq11_normalises_only_sums_longer_than_one():
    w_d = np.array([[0.6, 0.0], [0.1, 0.0]])
    w_ob = np.array([[0.0, 3.0], [0.0, 0.2]])
    out = combine(w_d, w_ob, SPEED)
    assert np.linalg.norm(out[0]) == pytest.approx(SPEED)
    np.testing.assert_allclose(out[1], SPEED * np.array([0.1, 0.2]))


# ---------------------------------------------------------------- policies
def test_policies_are_declared_for_both_ids():
    for env_id in ("motiongym/HarvestArm-v0", "motiongym/HarvestArmPlanar-v0"):
        assert {"potential-field", "potential-field-extended", "resolved-rate"} <= set(
            scripted_policies(env_id)
        )


def _rollouts(env_id, dof, name, seeds):
    env = gym.make(env_id, dof=dof, terminate_on_collision=False)
    kwargs = {**gym.spec(env_id).kwargs, "dof": dof, "terminate_on_collision": False}
    policy = make_policy(env_id, name, env.observation_space, env.action_space, kwargs)
    shortest, success = [], []
    for seed in seeds:
        observation, info = env.reset(seed=seed)
        start, d_min = True, info["min_distance"]
        while True:
            action, _ = policy.predict(observation, episode_start=start)
            start = False
            observation, _, terminated, truncated, info = env.step(action)
            d_min = min(d_min, info["min_distance"])
            if terminated or truncated:
                break
        shortest.append(d_min)
        success.append(info["is_success"])
    return np.array(shortest), np.array(success)


@pytest.mark.parametrize(
    ("env_id", "dof"), [("motiongym/HarvestArm-v0", 7), ("motiongym/HarvestArmPlanar-v0", 4)]
)
def test_potential_field_reaches_the_fruit_with_fewer_close_approaches(env_id, dof):
    seeds = range(100, 116)
    ours, ours_success = _rollouts(env_id, dof, "potential-field", seeds)
    plain, plain_success = _rollouts(env_id, dof, "resolved-rate", seeds)
    assert ours_success.mean() >= 0.8
    assert plain_success.mean() >= 0.8
    assert (ours < 0.03).mean() < (plain < 0.03).mean()
    assert ours.mean() > plain.mean() + 0.01


def test_policy_handles_batched_observations_and_rejects_a_wrong_arm():
    env_id = "motiongym/HarvestArm-v0"
    env = gym.make(env_id, dof=6)
    policy = make_policy(
        env_id, "potential-field", env.observation_space, env.action_space, {"dof": 6}
    )
    observations = np.stack([env.reset(seed=s)[0] for s in (0, 1)])
    actions, _ = policy.predict(observations, episode_start=np.array([True, True]))
    assert actions.shape == (2, 6)
    assert np.all(np.abs(actions) <= 1.0)
    with pytest.raises(ValueError, match="does not match"):
        make_policy(env_id, "potential-field", env.observation_space, env.action_space, {"dof": 5})
