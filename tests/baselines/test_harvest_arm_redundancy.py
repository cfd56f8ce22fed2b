"""Joint rates of the redundant arm: eq. 1's weighted pseudo-inverse, its limits, and the
relaxed form of ``critical_clearance``."""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

from motiongym.baselines.harvest_arm.redundancy import (
    limited_rates,
    relaxed_rates,
    weighted_rates,
)
from motiongym.envs.harvest_arm.model import ArmKinematics, arm_spec

SPEED, DT = 0.2, 0.05


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


def test_relaxed_rates_are_the_weighted_least_squares_and_tend_to_the_constrained_rates():
    """:func:`relaxed_rates` (``critical_clearance``): checked against numpy's least squares
    on the square-root-weighted stack (an independent solver), and, as the gripper's
    weight grows, against eq. 1's constrained solution."""
    rng = np.random.default_rng(3)
    n, m = 7, 6
    jacs, refs = rng.normal(size=(m, 3, n)), rng.normal(size=(m, 3)) * 0.1
    weights = rng.uniform(0.5, 3.0, m)
    big = np.full(n, 1e3)  # limits and speeds that never bind
    rates = relaxed_rates(jacs, refs, weights, np.zeros(n), big, big, 0.01, reg=0.0)
    w = np.sqrt(weights)[:, None, None]
    lstsq = np.linalg.lstsq((w * jacs).reshape(-1, n), (w[:, :, 0] * refs).ravel(), rcond=None)
    np.testing.assert_allclose(rates, lstsq[0], atol=1e-7)
    heavy = weights.copy()
    heavy[-1] = 1e7  # the last point is the gripper
    constrained = weighted_rates(jacs[-1], refs[-1], jacs[:-1], refs[:-1], weights[:-1], reg=0.0)
    relaxed = relaxed_rates(jacs, refs, heavy, np.zeros(n), big, big, 0.01, reg=0.0)
    np.testing.assert_allclose(relaxed, constrained, atol=1e-5)
