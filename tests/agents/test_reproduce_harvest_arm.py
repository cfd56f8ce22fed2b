"""``motiongym reproduce harvest-arm`` in its quick form."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motiongym.agents.reproduce.harvest_arm import PAPER, VARIANTS, mcnemar, paired_scenes, run


@pytest.mark.slow
def test_quick_reproduction_prints_tables_and_writes_numbers_and_figures(tmp_path, capsys):
    numbers = run(tmp_path, quick=True)
    printed = capsys.readouterr().out
    for table in range(4, 10):
        assert f"Table {table}" in printed
    assert "DOF trend, spatial 5 vs 7 DOF" in printed and "Ablations" in printed
    assert set(numbers["results"]) == {f"{kind}-{dof}" for kind, dof in PAPER}
    saved = json.loads((tmp_path / "harvest_arm.json").read_text())
    assert saved["dof_trend"] == json.loads(json.dumps(numbers["dof_trend"]))
    for name in numbers["figures"]:
        assert (tmp_path / name).stat().st_size > 10_000
    for key, res in numbers["results"].items():
        kind, dof = key.split("-")
        assert res["paper"] == PAPER[(kind, int(dof))]
        assert set(res["rates"]) == set(VARIANTS)
        for rates in res["rates"].values():
            assert rates["n"] == 6
            # centre lines are farther apart than surfaces, by the radii
            assert rates["mean_axis"] >= rates["mean_clearance"] + 0.02
        assert set(res["ablation"]) == set(VARIANTS) - {"full"}


def test_scenes_are_paired_across_the_arms_of_a_kind():
    scenes, drawn = paired_scenes("spatial", 5)
    assert len(scenes) == 5 and drawn >= 5
    assert sum("a" in ob for ob in scenes[0]["obstacles"]) == 3  # the bars
    again, _ = paired_scenes("spatial", 5)
    assert again == scenes


def test_mcnemar_counts_discordant_pairs():
    first = np.array([True, True, True, False, False, True])
    second = np.array([False, False, False, False, True, True])
    result = mcnemar(first, second)
    assert (result["only_first"], result["only_second"]) == (3, 1)
    assert result["p"] == 0.625  # two-sided exact binomial, 1 of 4 at 1/2
