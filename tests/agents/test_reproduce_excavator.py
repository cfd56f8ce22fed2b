"""The excavator reproduction (quick protocol): numbers, files, the paper's claims."""

from __future__ import annotations

import json

import pytest

from motiongym.agents.reproduce import excavator


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    out = tmp_path_factory.mktemp("excavator")
    return out, excavator.run(out, quick=True)


def test_paper_case_every_element_of_v_converges(results):
    _, r = results
    case = r["paper_case"]["runs"]
    for name in ("newton_analytic", "newton_numeric", "lm"):
        assert case[name]["converged"], name
        assert len(case[name]["V"]) == 21  # 20 iterations, as in the paper
        assert max(abs(v) for v in case[name]["V"][-1]) < 1e-9
        assert case[name]["position_error_m"] < 1e-3 and case[name]["angle_error_rad"] < 1e-3
    assert case["newton_analytic"]["q"] == pytest.approx(case["newton_numeric"]["q"], abs=1e-9)


def test_ik_statistics_and_failures_are_honest(results):
    _, r = results
    for stats in r["random_poses"].values():
        assert stats["wrong_pose_reported_converged"] == 0
    assert r["random_poses"]["newton_rest_aligned"]["converged_rate"] >= 0.9
    assert r["unreachable"]["reported_converged"] == 0
    assert not r["issue_case"]["converged"] and r["issue_case"]["reason"] == "joint_limits"
    cart = r["cartesian_ik"]
    for name in ("newton_rest", "newton_rest_swing_aligned", "fallback_chain"):
        assert cart[name]["wrong_pose_reported_converged"] == 0
        assert cart[name]["no_solution_reason_with_in_limit_solution"] == 0
    assert cart["fallback_chain"]["converged_rate_of_solvable"] == 1.0


def test_dig_cycle_numbers(results):
    _, r = results
    d = r["dig_cycle"]
    assert d["success_rate"] == 1.0 and d["pipe_contacts"] == 0 and d["cost_steps_total"] == 0
    assert d["dig_fill_m3"]["mean"] >= 0.9 and d["truck_soil_m3"]["mean"] >= 0.9
    assert d["min_pipe_clearance_m"] >= 0.5


def test_files_written(results):
    out, r = results
    saved = json.loads((out / "excavator.json").read_text())
    assert saved["dig_cycle"]["n"] == r["dig_cycle"]["n"]
    assert (out / "fig4_convergence.png").stat().st_size > 10_000
    assert (out / "fig5_pose.png").stat().st_size > 10_000
    assert r["speed"]["ik_solves_per_s_paper_case"] > 0


@pytest.mark.slow
def test_full_protocol(tmp_path):
    r = excavator.run(tmp_path, quick=False)
    assert r["random_poses"]["newton_rest_aligned"]["n"] == 1000
    assert r["random_poses"]["newton_rest_aligned"]["converged_rate"] >= 0.95
    assert all(v["wrong_pose_reported_converged"] == 0 for v in r["random_poses"].values())
    assert r["unreachable"]["reported_converged"] == 0
    near = r["near_singular"]
    assert near["lm"]["converged_rate"] > near["newton"]["converged_rate"]
    d = r["dig_cycle"]
    assert d["n"] == 100 and d["success_rate"] >= 0.98 and d["pipe_contacts"] == 0


def test_probes_report_every_issue_probe(results):
    _, r = results
    probes = r["probes"]
    for name in ("heel_first_push", "sideways_swing", "curled_plunge", "boom_into_ground"):
        assert isinstance(probes[name]["physical"], bool), name
    assert probes["dragged_full_bucket"]["full_at_step"] is not None
    pipe = probes["pipe_beside_boom_plane"]
    assert pipe["seed"] is not None
    assert pipe["edge_corner_to_pipe_m"][0] < 0.0 < pipe["edge_corner_to_pipe_m"][1]
    assert 0.0 < probes["bucket_in_tracks"]["bucket_inside_undercarriage"] < 0.05
