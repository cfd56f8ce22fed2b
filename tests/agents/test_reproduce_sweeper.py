"""``motiongym reproduce sweeper`` in its quick form: numbers, files and the paper's shape."""

from __future__ import annotations

import json

import pytest

from motiongym.agents.errors import UsageError
from motiongym.agents.reproduce import experiments, reproduce
from motiongym.agents.reproduce.sweeper import run


@pytest.mark.slow
def test_reproduce_sweeper_quick(tmp_path, capsys) -> None:
    results = run(tmp_path, quick=True)
    printed = capsys.readouterr().out
    assert "SmartDFS" in printed and "about 90 %" in printed and "3 %" in printed
    saved = json.loads((tmp_path / "sweeper.json").read_text())
    assert saved["coverage"]["maze"]["coverage_min"] == results["coverage"]["maze"]["coverage_min"]
    for name in ("room", "apartment", "maze"):
        assert results["coverage"][name]["coverage_min"] == 1.0  # the paper: full coverage
    assert (
        results["coverage"]["procedural"]["all_swept"]
        == results["coverage"]["procedural"]["episodes"]
    )
    sp = results["start_position"]
    assert sp["starts"] > 30 and 0.0 <= sp["spread_of_max"] < sp["spread"] < 1.0
    assert sp["travel_max"] - sp["travel_min"] == pytest.approx(sp["spread"] * sp["travel_min"])
    assert 0.0 < sp["alignment_variance_share"] < 1.0 and "3.2 / 3.1 %" in printed
    scale = results["start_scale"]  # the maze enlarged: travel between runs grows as its side
    assert [(r["reading"], r["k"]) for r in scale] == [
        (reading, k) for reading in ("ours", "paper's stack") for k in (1, 2)
    ]
    for small, large in (scale[0:2], scale[2:4]):
        assert large["travel_mean"] > 3.0 * small["travel_mean"]  # the area: about k^2
        share = [r["between_runs_mean"] / r["travel_mean"] for r in (small, large)]
        assert share[1] < share[0]
    assert "maze x2" in printed
    for name in ("room", "apartment", "maze", "procedural"):  # PSA leaves CWA nothing there
        row = results["coverage"][name]
        assert row["travel_shares"]["cwa"] < 0.01 and row["transfer_bfs_mean"] > 0.0
    cw = results["corner_work"]  # the paper's Fig. 9 -> 10 and the ablation without CWA
    assert cw["coverage_min"] == 1.0 and cw["no_cwa_coverage_max"] < 1.0
    assert cw["travel_shares"]["cwa"] > 0.05
    ori = results["orientation"]
    assert [row["heading"] for row in ori["rows"]] == ["east", "north", "west", "south"]
    assert all(row["coverage"] == 1.0 for row in ori["rows"])
    travel = [row["travel"] for row in ori["rows"]]
    assert ori["spread"] == (max(travel) - min(travel)) / min(travel)
    assert ori["starts"] == 5 and ori["spread_starts_max"] >= ori["spread_starts_mean"]
    assert all(row["coverage"] == 1.0 for row in ori["walls_turned"]["rows"])
    rows = results["odometry"]["rows"]
    assert {(r["map"], r["localise"]) for r in rows} == {
        (m, loc) for m in ("room", "maze") for loc in (True, False)
    }
    assert all(r["heading_noise"] == 0.01 and r["slip_noise"] == 0.05 for r in rows)
    for name in ("room", "maze"):  # measured: 99.1 / 99.7 % localised, 80.6 / 90.1 % not
        loc, dead = (
            next(r for r in rows if r["map"] == name and r["localise"] is k) for k in (True, False)
        )
        assert loc["coverage"] > dead["coverage"] and loc["coverage"] > 0.95
    summary = results["odometry"]["summary"]
    assert summary["localised"]["episodes"] == summary["dead reckoning"]["episodes"] == 2
    assert "stopped early" in printed
    wk = results["weak_baseline"]
    assert wk["psa_coverage"] == 1.0 and wk["weak_coverage_same_steps"] < 1.0
    for name in results["figures"]:
        assert (tmp_path / name).stat().st_size > 1000


def test_seeds_only_for_an_experiment_that_takes_them(tmp_path) -> None:
    others = [name for name in experiments() if name != "sweeper"]
    with pytest.raises(UsageError, match="takes no --seeds"):
        reproduce(others[0], tmp_path, quick=True, seeds=3)


def test_enlarged_maze_keeps_the_layout() -> None:
    from motiongym.agents.reproduce.sweeper_scale import enlarged_maze
    from motiongym.envs.sweeper import maps

    maze = maps.shipped_map("maze")
    big = enlarged_maze(3)
    assert big.shape == (3 * maze.shape[0], 3 * maze.shape[1]) and big.dtype == bool
    assert (big[::3, ::3] == maze).all() and (big[2::3, 1::3] == maze).all()
