"""Newton-Raphson IK of the excavator (eq. 9-13): Jacobians, the paper's case, failures."""

from __future__ import annotations

import math

import numpy as np
import pytest

from motiongym.baselines.excavator import newton_raphson as nr
from motiongym.envs.excavator.config import DEFAULT_MACHINE as M
from motiongym.envs.excavator.config import Machine
from motiongym.envs.excavator.kinematics import base_pose, bucket_angle, forward, swing_for_target


def test_analytic_jacobian_matches_central_differences():
    rng = np.random.default_rng(0)
    base = base_pose((1.0, 2.0, 0.3), (0.04, -0.06, 0.5))
    for machine, b in ((M, None), (Machine(L0=0.3, d2=0.2), base)):
        for q in rng.uniform(machine.q_min, machine.q_max, size=(20, 4)):
            h_d = forward(rng.uniform(machine.q_min, machine.q_max), machine, b)
            np.testing.assert_allclose(
                nr.jacobian(q, machine, b), nr.jacobian_numeric(q, h_d, machine, b), atol=1e-7
            )


def test_error_vector_picks_the_five_entries_of_eq_9():
    q = np.array(M.q_rest)
    h_d = np.eye(4)
    h = forward(q, M)
    assert nr.error_vector(q, h_d, M) == pytest.approx(
        [h[0, 0] - 1, h[2, 0], h[0, 3], h[1, 3], h[2, 3]]
    )


@pytest.mark.parametrize("jacobian_mode", ["analytic", "numeric"])
def test_paper_case_converges_within_20_iterations(jacobian_mode):
    tip, beta = nr.paper_target(M)
    assert tip == pytest.approx([0.8 * M.reach, 0, 0]) and beta == -math.pi / 8
    result = nr.solve(tip, beta, M, stop_early=False, jacobian_mode=jacobian_mode)
    assert result.converged and result.reason == "converged"
    assert result.iterations == 20 and result.errors.shape == (21, 5)
    assert result.position_error < 1e-3 and result.angle_error < 1e-3
    assert np.all(np.abs(result.errors[-1]) < 1e-9)  # every element of V -> 0 (Fig. 4)
    # Quadratic convergence once close: the error norm at least squares.
    norms = np.linalg.norm(result.errors, axis=1)
    k = int(np.argmax(norms < 0.1))
    assert norms[k + 1] < 10 * norms[k] ** 2
    # The pose is one of the closed-form solutions, inside the limits.
    assert nr.within_limits(result.q, M)
    assert any(np.allclose(result.q, s, atol=1e-6) for s in nr.analytic_solutions(tip, beta, M))


def test_other_bucket_sign_is_reported_as_joint_limits():
    tip, beta = nr.paper_target(M)
    result = nr.solve(tip, -beta, M)
    assert not result.converged and result.reason == "joint_limits"


def test_unreachable_targets_are_never_reported_as_success():
    far = nr.solve([M.reach + 2.0, 0.0, 0.0], -0.5, M, max_iterations=50)
    assert not far.converged and far.reason == "out_of_reach"
    near = nr.solve([0.5, 0.0, 4.0], -0.5, M, max_iterations=50)
    assert not near.converged and near.reason in ("out_of_reach", "joint_limits")
    rng = np.random.default_rng(1)
    for _ in range(100):
        tip = rng.uniform([-14, -14, -9], [14, 14, 12])
        beta = rng.uniform(-math.pi, math.pi)
        result = nr.solve(tip, beta, M, max_iterations=30)
        h = forward(result.q, M)
        if result.converged:
            assert np.linalg.norm(h[:3, 3] - tip) < 1e-3
            assert abs(math.remainder(bucket_angle(result.q) - beta, 2 * math.pi)) < 1e-3
            assert nr.within_limits(result.q, M)
        else:
            assert result.reason in nr.NO_SOLUTION + nr.FROM_START
            if not nr.analytic_solutions(tip, beta, M):
                assert result.reason == "out_of_reach"


def test_random_reachable_poses_mostly_converge():
    rng = np.random.default_rng(2)
    converged, iterations = 0, []
    for q in rng.uniform(M.q_min, M.q_max, size=(100, 4)):
        h = forward(q, M)
        q0 = np.array(M.q_rest)
        q0[0] = swing_for_target(h[0, 3], h[1, 3], M)
        result = nr.solve(h[:3, 3], bucket_angle(q), M, q0=q0)
        converged += result.converged
        iterations += [result.iterations] if result.converged else []
    assert converged >= 80  # pure eq. 13 from the rest pose (1,000 poses: reproduction)
    assert np.median(iterations) <= 6


def test_damped_variant_stays_bounded_beyond_reach():
    # Just beyond full stretch the 2R arm is singular; LM returns the closest pose.
    target = np.array([M.reach + 0.5, 0.0, 0.0])
    lm = nr.solve(target, 0.0, M, method="lm", max_iterations=100)
    newton = nr.solve(target, 0.0, M, method="newton", max_iterations=100)
    assert lm.reason == newton.reason == "out_of_reach"
    assert np.all(np.isfinite(lm.q))
    assert lm.position_error < 1.0
    assert np.linalg.norm(lm.errors[-1]) <= np.linalg.norm(lm.errors[0])


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="method"):
        nr.solve([5, 0, 0], 0.0, M, method="gauss")
    with pytest.raises(ValueError, match="Jacobian"):
        nr.solve([5, 0, 0], 0.0, M, jacobian_mode="forward")
    with pytest.raises(ValueError, match="finite"):
        nr.solve([5, np.nan, 0], 0.0, M)


def test_solves_with_a_tilted_moved_base():
    # H_M^O of eq. 1-2: the machine 100 m away on a slope; beta is in frame M.
    base = base_pose((100.0, 50.0, 3.0), (0.05, -0.08, 1.2))
    rng = np.random.default_rng(3)
    converged = 0
    for q in rng.uniform(M.q_min, M.q_max, size=(40, 4)):
        h = forward(q, M, base)
        q0 = np.array(M.q_rest)
        q0[0] = q[0]
        result = nr.solve(h[:3, 3], bucket_angle(q), M, q0=q0, base=base)
        if result.converged:
            converged += 1
            np.testing.assert_allclose(forward(result.q, M, base)[:3, 3], h[:3, 3], atol=1e-3)
    assert converged >= 30
