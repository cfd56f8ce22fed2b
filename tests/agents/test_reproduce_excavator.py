"""The excavator reproduction (quick protocol): numbers, files, the paper's claims."""

from __future__ import annotations

import json

import pytest

from motiongym.agents.reproduce import excavator

# The quick protocol runs once per module (its fixture): the slow tier.
pytestmark = pytest.mark.slow


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
    for env_id, d in r["dig_cycle"].items():
        assert d["success_rate"] == 1.0 and d["clean_delivery_rate"] == 1.0, env_id
        assert all(v == 0 for v in d["episodes_with_contact"].values()), env_id
        assert d["dig_fill_m3"]["mean"] >= 0.9 and d["truck_soil_m3"]["mean"] >= 0.9
        assert d["min_pipe_clearance_m"] >= 0.5


def test_files_written(results):
    out, r = results
    saved = json.loads((out / "excavator.json").read_text())
    assert saved["dig_cycle"].keys() == r["dig_cycle"].keys()
    assert (out / "fig4_convergence.png").stat().st_size > 10_000
    assert (out / "fig5_pose.png").stat().st_size > 10_000
    assert r["speed"]["ik_solves_per_s_paper_case"] > 0


@pytest.mark.study
def test_full_protocol(tmp_path):
    r = excavator.run(tmp_path, quick=False)
    assert r["random_poses"]["newton_rest_aligned"]["n"] == 1000
    assert r["random_poses"]["newton_rest_aligned"]["converged_rate"] >= 0.95
    assert all(v["wrong_pose_reported_converged"] == 0 for v in r["random_poses"].values())
    assert r["unreachable"]["reported_converged"] == 0
    near = r["near_singular"]
    assert near["lm"]["converged_rate"] > near["newton"]["converged_rate"]
    v1 = r["dig_cycle"]["motiongym/Excavator-v1"]
    assert v1["n"] == 200 and v1["clean_delivery_rate"] >= 0.95  # the target
    assert r["cartesian_ik"]["n"] == 3000
    assert all(
        r["cartesian_ik"][k]["wrong_pose_reported_converged"] == 0
        for k in ("newton_rest", "newton_rest_swing_aligned", "fallback_chain")
    )


def test_probes_not_physical_on_v0_physical_on_v1(results):
    _, r = results
    v0, v1 = r["probes"]["motiongym/Excavator-v0"], r["probes"]["motiongym/Excavator-v1"]
    names = [k for k in v1 if k != "env_id"]
    assert len(names) == 7
    assert all(v0[name]["physical"] is False for name in names)
    assert all(v1[name]["physical"] is True for name in names)
    pipe = v1["pipe_beside_boom_plane"]
    assert pipe["edge_corner_to_pipe_m"][0] < 0.0 < pipe["edge_corner_to_pipe_m"][1]
    assert [row["contact"] for row in pipe["reported"]] == [True, False]
    assert 0.0 < v1["bucket_in_tracks"]["bucket_inside_undercarriage"] < 0.05
