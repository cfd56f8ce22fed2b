"""BENCHMARKS.md generation: scripted and pooled learned columns, figures, kept prose."""

from __future__ import annotations

import pytest

from motiongym.agents.evaluation import benchmarks
from motiongym.agents.evaluation.statistics import robust_statistics

ENV_ID = "motiongym/ExcavatorReach-v0"


@pytest.fixture
def one_shipped_id(monkeypatch, shipped_folder):
    monkeypatch.setattr(benchmarks, "ENV_IDS", [ENV_ID])
    monkeypatch.setattr(benchmarks, "pretrained_models", lambda env_id: {"ppo": shipped_folder})


def test_pooled_evaluation_holds_every_seed_episode(shipped_folder):
    evaluation, metrics = benchmarks.pooled_evaluation(shipped_folder)
    assert evaluation.policy == "ppo (from scratch, 2 seeds)"
    assert len(evaluation.episodes) == 2 * len(metrics["held_out_seeds"])
    (robust,) = robust_statistics([evaluation])  # the training seeds are the strata
    assert robust["return"]["runs"] == 2


def test_benchmarks_rewrites_only_the_generated_part(one_shipped_id, tmp_path):
    path = tmp_path / "BENCHMARKS.md"
    path.write_text(
        f"# Benchmarks\n\nreading above\n\n{benchmarks.BEGIN}\nstale\n{benchmarks.END}\n"
        "\nreading below\n"
    )
    benchmarks.write_benchmarks(path, n_episodes=2)
    text = path.read_text()
    assert "stale" not in text
    assert text.index("reading above") < text.index(benchmarks.BEGIN)
    assert text.index(benchmarks.END) < text.index("reading below")
    generated = text.split(benchmarks.BEGIN)[1].split(benchmarks.END)[0]
    header = next(line for line in generated.splitlines() if line.startswith("| measure"))
    assert "newton-raphson-reach" in header and "ppo (from scratch, 2 seeds)" in header
    assert "over 2 or 4 episodes per policy" in generated
    robust = next(line for line in generated.splitlines() if line.startswith("| statistic"))
    assert "newton-raphson-reach" in robust and "ppo (from scratch, 2 seeds)" in robust
    assert "probability of improvement over newton-raphson-reach" in generated
    assert "| IQM return (reward) |" in generated
    assert "| P(return > newton-raphson-reach's) | (reference) |" in generated
    assert (tmp_path / "docs" / "benchmarks" / "ExcavatorReach-v0.png").is_file()
    assert "](docs/benchmarks/ExcavatorReach-v0.png)" in generated


def test_benchmarks_ids_rewrites_only_those_sections(one_shipped_id, tmp_path):
    """``ids``: the named ID's section is regenerated, a neighbour's and the preamble kept;
    an ID without a section, or not registered, is refused by name."""
    path = tmp_path / "BENCHMARKS.md"
    other = "### motiongym/Sweeper-v0\n\nkept table\n"
    path.write_text(
        f"{benchmarks.BEGIN}\npreamble\n\n### {ENV_ID}\n\nstale\n\n{other}{benchmarks.END}\n"
    )
    benchmarks.write_benchmarks(path, n_episodes=2, ids=[ENV_ID])
    generated = path.read_text().split(benchmarks.BEGIN)[1].split(benchmarks.END)[0]
    assert "stale" not in generated and "preamble" in generated and other in generated
    assert generated.index(f"### {ENV_ID}") < generated.index("newton-raphson-reach")
    assert generated.index("newton-raphson-reach") < generated.index(other)
    path.write_text(f"{benchmarks.BEGIN}\n{other}{benchmarks.END}\n")
    with pytest.raises(ValueError, match="ExcavatorReach-v0 has no section"):
        benchmarks.write_benchmarks(path, n_episodes=2, ids=[ENV_ID])
    with pytest.raises(ValueError, match=r"\['Nope-v0'\] are not registered"):
        benchmarks.write_benchmarks(path, n_episodes=2, ids=["Nope-v0"])


@pytest.mark.parametrize("ids", [None, [ENV_ID]])
def test_benchmarks_keeps_what_was_edited_while_it_evaluated(
    one_shipped_id, monkeypatch, tmp_path, ids
):
    """The file is read again just before it is written: a reading edited during the
    evaluations (they take minutes to hours) is not written over by the copy read at the
    start."""
    path = tmp_path / "BENCHMARKS.md"
    path.write_text(f"reading\n\n{benchmarks.BEGIN}\n### {ENV_ID}\n\nstale\n{benchmarks.END}\n")
    section = benchmarks.benchmark_section

    def edit_meanwhile(*args):
        path.write_text(path.read_text().replace("reading", "reading, edited meanwhile"))
        return section(*args)

    monkeypatch.setattr(benchmarks, "benchmark_section", edit_meanwhile)
    benchmarks.write_benchmarks(path, n_episodes=2, ids=ids)
    text = path.read_text()
    assert text.startswith("reading, edited meanwhile\n") and "stale" not in text
