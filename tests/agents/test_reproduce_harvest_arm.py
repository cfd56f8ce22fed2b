"""``motiongym reproduce harvest-arm`` in its quick form."""

from __future__ import annotations

import json

from motiongym.agents.reproduce.harvest_arm import PAPER, run


def test_quick_reproduction_prints_tables_and_writes_numbers_and_figures(tmp_path, capsys):
    numbers = run(tmp_path, quick=True)
    printed = capsys.readouterr().out
    for table in range(4, 10):
        assert f"Table {table}" in printed
    assert set(numbers["summary"]) == {f"{kind}-{dof}" for kind, dof in PAPER}
    saved = json.loads((tmp_path / "harvest_arm.json").read_text())
    assert saved["summary"] == numbers["summary"]
    for name in numbers["figures"]:
        assert (tmp_path / name).stat().st_size > 10_000
    for key, res in numbers["results"].items():
        kind, dof = key.split("-")
        assert res["paper"] == PAPER[(kind, int(dof))]
        for policy in ("potential-field", "potential-field-extended", "resolved-rate"):
            (only_run,) = res[policy]["runs"]
            assert 0.0 <= only_run["clearance"]["below_pct"] <= 100.0
            assert only_run["axis"]["mean"] >= only_run["clearance"]["mean"]
    # pooled over the six arms, the paper's method comes less close than the plain baseline
    summary = numbers["summary"].values()
    ours = sum(s["ours_clearance_below_pct"] for s in summary)
    plain = sum(s["baseline_clearance_below_pct"] for s in summary)
    assert ours < plain
