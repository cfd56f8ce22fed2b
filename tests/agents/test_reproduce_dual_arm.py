"""The dual-arm reproduction (quick): paper case and a small study."""

from __future__ import annotations

import json

import pytest

from motiongym.agents.reproduce import dual_arm

# The quick protocol runs once per module (its fixture): the slow tier.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def numbers(tmp_path_factory):
    out = tmp_path_factory.mktemp("dual_arm")
    result = dual_arm.run(out, quick=True)
    result["_out"] = out
    return result


def test_paper_case_shape_of_the_result(numbers):
    case = numbers["paper_case"]
    lo, hi = case["collision_interval_s"]
    assert 0.6 <= lo <= 0.8 and 1.0 <= hi <= 1.2  # paper: 0.76-1.16 s
    assert case["delay_samples"] == case["exhaustive_delay_samples"] > 0
    assert case["min_distance_after_delay_m"] > 0  # Fig. 10: positive throughout
    assert case["time_saved_s"] > 0.5  # paper: 1.22 s
    assert case["evaluated_ratio"] <= 0.2
    k2, k1 = case["departure_k2_k1"]
    assert (k2 - k1) * 0.02 == pytest.approx(case["delay_s"])
    assert case["env"]["is_success"]
    spans = case["makespan_s"]
    assert spans["min_makespan"] <= spans["delay"] < spans["sequential"]


def test_study(numbers):
    study = numbers["study"]
    assert study["pairs"] == 12 and study["solved"] == 12
    assert study["agree"] == study["solved"]
    assert study["bf_never_below_exhaustive"]
    assert study["median_evaluated_ratio"] < 0.2
    m = study["mean_makespan_s"]
    assert m["min_makespan"] <= m["exhaustive_delay"] <= m["boundary_following"] < m["sequential"]


def test_outputs_written(numbers):
    out = numbers["_out"]
    for name in ("dual_arm_distance.png", "dual_arm_collision_map.png", "dual_arm_study.png"):
        assert (out / name).stat().st_size > 10_000
    saved = json.loads((out / "dual_arm.json").read_text())
    assert saved["paper"]["delay_s"] == 0.7


def test_truth_study(numbers):
    truth = numbers["truth"]
    assert truth["pairs"] == 3
    assert truth["exact"]["equal"] == 3 and truth["exact_fine_collisions"] == 0
    assert truth["exact"]["early"] == truth["exact"]["failed"] == 0
    assert (
        truth["at_rest"]["start"]["delay"] is None
        and "at rest" in truth["at_rest"]["end"]["reason"]
    )
    for n_levels in (50, 100):
        assert numbers["resolution"][n_levels]["equal"] == 3
