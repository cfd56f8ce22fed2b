"""95 % intervals of evaluation measures: rates inside [0, 1] (Wilson), the rest Student's t."""

from __future__ import annotations

import io

import numpy as np
import pytest

from motiongym.agents.evaluation.episodes import Evaluation
from motiongym.agents.evaluation.report import comparison_rows, make_console, summary_table
from motiongym.agents.evaluation.statistics import interval, t_half_width, wilson_interval

UNITS = {"return": "reward", "length": "steps", "is_success": "rate", "coverage": "fraction"}


def _evaluation(successes: list[float], coverage: list[float]) -> Evaluation:
    episodes = [
        {"seed": i, "return": float(i), "length": 10 + i, "is_success": s, "coverage": c}
        for i, (s, c) in enumerate(zip(successes, coverage, strict=True))
    ]
    return Evaluation("motiongym/Sweeper-v0", "p", episodes, dict(UNITS))


def test_wilson_interval_matches_the_published_values():
    # 1 of 10: (0.0179, 0.4042); 0 of 10: (0, 0.2775); 10 of 10: (0.7225, 1), z = 1.95996
    np.testing.assert_allclose(wilson_interval(1, 10), (0.017876, 0.404150), atol=1e-6)
    np.testing.assert_allclose(wilson_interval(0, 10), (0.0, 0.277533), atol=1e-6)
    np.testing.assert_allclose(wilson_interval(10, 10), (0.722467, 1.0), atol=1e-6)
    with pytest.raises(ValueError, match="n must be at least 1"):
        wilson_interval(0, 0)


def test_a_success_rate_interval_lies_in_zero_one_where_t_left_it():
    evaluation = _evaluation([1.0] + [0.0] * 9, [0.5] * 10)
    stats = evaluation.summary()["is_success"]
    assert stats["mean"] == pytest.approx(0.1)
    assert stats["mean"] - stats["ci95"] < 0.0  # the t interval: 0.1 ± 0.226
    assert (stats["low"], stats["high"]) == pytest.approx((0.017876, 0.404150), abs=1e-6)


def test_a_continuous_fraction_keeps_the_t_interval_clipped_to_one():
    coverage = [1.0, 1.0, 0.99, 0.7, 1.0]
    stats = _evaluation([1.0] * 5, coverage).summary()["coverage"]
    half = t_half_width(coverage)
    assert stats["ci95"] == pytest.approx(half)
    assert stats["low"] == pytest.approx(np.mean(coverage) - half)
    assert stats["high"] == 1.0 < np.mean(coverage) + half


def test_other_measures_keep_the_symmetric_t_interval():
    stats = _evaluation([1.0, 0.0, 1.0], [0.5, 0.5, 0.5]).summary()["return"]
    assert stats["low"] == pytest.approx(1.0 - stats["ci95"])
    assert stats["high"] == pytest.approx(1.0 + stats["ci95"])
    assert interval([3.0], "reward") == (3.0, 3.0)


def test_tables_print_asymmetric_intervals_as_bounds():
    evaluation = _evaluation([1.0] + [0.0] * 9, [0.5] * 10)
    rows = {row[0]: row[1] for row in comparison_rows([evaluation])}
    assert rows["is_success (rate)"] == "0.1 [0.01788, 0.4042]"
    assert rows["return (reward)"].startswith("4.5 ± ")
    out = io.StringIO()
    make_console(out).print(summary_table(evaluation))
    assert "[0.01788, 0.4042]" in out.getvalue()


def test_the_normal_quantile_constant_is_scipys():
    """Z95 is written as a literal (scipy.stats is imported only for the t interval)."""
    from scipy import stats

    from motiongym.agents.evaluation.statistics import Z95

    assert float(stats.norm.ppf(0.975)) == Z95


# --- Agarwal et al. 2021: interquartile mean, probability of improvement, bootstrap ---


def test_iqm_is_the_mean_of_the_middle_half():
    from motiongym.agents.evaluation.statistics import iqm

    assert iqm([1, 2, 3, 4, 5, 6, 7, 100]) == 4.5  # 2 cut from each end: mean of 3..6
    assert iqm([4.0, 1.0, 3.0, 2.0]) == 2.5  # 1 cut from each end: mean of 2, 3
    assert iqm(np.arange(1.0, 11.0)) == pytest.approx(5.5)  # 2 cut each end: 3..8
    assert iqm([7.0]) == 7.0
    assert iqm([0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]) == 1.0  # a 0/1 rate of 0.75


def test_probability_of_improvement_of_identical_and_dominated_distributions():
    from motiongym.agents.evaluation.statistics import (
        improvement_interval,
        probability_of_improvement,
    )

    x = [0.1, 0.5, 0.9, 0.5]
    assert probability_of_improvement(x, x) == 0.5
    assert probability_of_improvement([1.0] * 5, [1.0] * 3) == 0.5  # every pair a tie
    assert probability_of_improvement([2.0, 3.0, 4.0], [0.0, 1.0]) == 1.0
    assert probability_of_improvement([0.0, 1.0], [2.0, 3.0, 4.0]) == 0.0
    assert probability_of_improvement([1.0, 0.0], [0.0, 0.0]) == 0.75  # 2 wins, 2 ties of 4
    assert improvement_interval([2.0, 3.0, 4.0], [0.0, 1.0]) == (1.0, 1.0, 1.0)
    assert improvement_interval([0.0, 1.0], [2.0, 3.0]) == (0.0, 0.0, 0.0)


def test_probability_of_improvement_is_the_mann_whitney_statistic():
    """Against scipy's Mann-Whitney U (ties counted half), on values with many ties."""
    from scipy import stats

    from motiongym.agents.evaluation.statistics import probability_of_improvement

    rng = np.random.default_rng(5)
    for _ in range(5):
        x, y = rng.integers(0, 6, 31).astype(float), rng.integers(1, 7, 17).astype(float)
        u = stats.mannwhitneyu(x, y, alternative="greater").statistic
        assert probability_of_improvement(x, y) == pytest.approx(u / (31 * 17), abs=1e-12)


def test_bootstrap_intervals_cover_the_true_values_about_95_percent():
    """100 synthetic experiments, 40 normal values each (IQM of N(1, 1): 1; P(X > Y) for
    X ~ N(0.5, 1), Y ~ N(0, 1): Phi(0.5 / sqrt 2) = 0.638); percentile intervals of
    500 resamples cover them 86-100 % of the time (95 % nominal; the percentile
    bootstrap is a little short at n = 40)."""
    from scipy import stats

    from motiongym.agents.evaluation.statistics import improvement_interval, iqm_interval

    rng = np.random.default_rng(11)
    truth = stats.norm.cdf(0.5 / np.sqrt(2.0))
    iqm_hits = improvement_hits = 0
    for trial in range(100):
        _, low, high = iqm_interval(rng.normal(1.0, 1.0, 40), resamples=500, seed=trial)
        iqm_hits += low <= 1.0 <= high
        x, y = rng.normal(0.5, 1.0, 40), rng.normal(0.0, 1.0, 40)
        _, low, high = improvement_interval(x, y, resamples=500, seed=trial)
        improvement_hits += low <= truth <= high
    assert 86 <= iqm_hits <= 100
    assert 86 <= improvement_hits <= 100


def test_bootstrap_is_deterministic_given_its_seed():
    from motiongym.agents.evaluation.statistics import improvement_interval, iqm_interval

    values = np.random.default_rng(2).normal(size=30)
    assert iqm_interval(values) == iqm_interval(values)
    assert iqm_interval(values, seed=1) != iqm_interval(values, seed=2)
    other = values[::-1] + 0.3
    assert improvement_interval(values, other) == improvement_interval(values, other)


def test_resampling_stays_inside_each_stratum():
    """Each resample keeps every stratum's count: two runs of constant values (0 and 1)
    give an IQM interval of zero width, where one stratum lets it move."""
    from motiongym.agents.evaluation.statistics import (
        iqm_interval,
        run_strata,
        stratified_resamples,
    )

    strata = np.array([0, 0, 0, 1, 1, 1, 1, 2])
    rows = stratified_resamples(strata, 200, np.random.default_rng(0))
    assert rows.shape == (200, 8)
    assert np.all(strata[rows] == strata)  # position i always draws from i's stratum
    assert len(np.unique(rows[:, :3])) == 3  # and draws every member of it
    values = np.array([0.0] * 6 + [1.0] * 6)
    runs = np.repeat([0, 1], 6)
    assert iqm_interval(values, runs)[1:] == (0.5, 0.5)
    low, high = iqm_interval(values)[1:]
    assert low < 0.5 < high
    np.testing.assert_array_equal(run_strata([7, 8, 9, 7, 8, 9]), [0, 0, 0, 1, 1, 1])


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda s: s.iqm([]), ValueError, r"values: a non-empty 1-D .* shape \(0,\)"),
        (lambda s: s.iqm_interval([[1.0, 2.0]]), ValueError, r"values: .* shape \(1, 2\)"),
        (lambda s: s.iqm([1.0, np.nan]), ValueError, "values: every value must be finite"),
        (lambda s: s.probability_of_improvement([1.0], []), ValueError, "y: a non-empty"),
        (
            lambda s: s.iqm_interval([1.0, 2.0, 3.0], strata=[0, 1]),
            ValueError,
            r"strata: one stratum label per value is needed \(3\), got shape \(2,\)",
        ),
        (
            lambda s: s.improvement_interval([1.0, 2.0], [1.0], y_strata=[0, 0]),
            ValueError,
            r"y_strata: one stratum label per value is needed \(1\)",
        ),
        (lambda s: s.iqm_interval([1.0], resamples=0), ValueError, "resamples: at least 1"),
        (lambda s: s.iqm_interval([1.0], resamples=2.5), TypeError, "resamples: an integer"),
        (lambda s: s.iqm_interval([1.0], confidence=1.0), ValueError, r"confidence: .* \(0, 1\)"),
    ],
)
def test_bad_input_is_refused_by_name(call, error, message):
    from motiongym.agents.evaluation import statistics

    with pytest.raises(error, match=message):
        call(statistics)


def _pooled(policy: str, returns: list[list[float]], successes: list[list[float]]) -> Evaluation:
    """An evaluation of ``len(returns)`` runs on the same episode seeds (a pooled agent)."""
    episodes = [
        {"seed": 100 + i, "return": r, "length": 10, "is_success": s, "coverage": 0.5}
        for run_returns, run_successes in zip(returns, successes, strict=True)
        for i, (r, s) in enumerate(zip(run_returns, run_successes, strict=True))
    ]
    return Evaluation("motiongym/Sweeper-v0", policy, episodes, dict(UNITS))


def test_robust_rows_give_iqm_and_improvement_over_the_paper():
    from motiongym.agents.evaluation.report import robust_rows
    from motiongym.agents.evaluation.statistics import robust_statistics

    paper = _pooled("paper", [[1.0, 2.0, 3.0, 4.0]], [[1.0, 1.0, 0.0, 0.0]])
    learned = _pooled("ppo", [[5.0, 6.0, 7.0, 8.0], [5.0, 6.0, 7.0, 9.0]], [[1.0] * 4] * 2)
    robust = robust_statistics([paper, learned], "paper")
    assert robust[1]["return"]["runs"] == 2 and robust[0]["return"]["runs"] == 1
    assert robust[1]["return"]["iqm"] == 6.5  # 2 of 8 cut from each end: 6, 6, 7, 7
    assert robust[1]["return"]["p_improvement"] == 1.0
    assert robust[1]["is_success"]["p_improvement"] == 0.75  # 2 wins, 2 ties of 4 pairs
    assert "p_improvement" not in robust[1]["length"]  # not a larger-is-better measure
    rows = {row[0]: row[1:] for row in robust_rows([paper, learned], "paper", robust)}
    (paper_iqm, learned_iqm) = rows["IQM return (reward)"]
    assert paper_iqm.startswith("2.5 [") and learned_iqm.startswith("6.5 [")
    low, high = robust[1]["return"]["iqm_low"], robust[1]["return"]["iqm_high"]
    assert 5.0 <= low < 6.5 < high <= 9.0
    assert "IQM is_success (rate)" not in rows  # a 0/1 rate's IQM is 0 or 1: read its mean
    assert rows["P(return > paper's)"] == ["(reference)", "1 [1, 1]"]
    assert rows["P(coverage > paper's)"] == ["(reference)", "0.5 [0.5, 0.5]"]
    unrelated = robust_rows([learned], "paper")  # the paper's algorithm not compared
    assert not any(row[0].startswith("P(") for row in unrelated)


def test_compare_files_carry_the_robust_statistics(tmp_path):
    import csv
    import json

    from motiongym.agents.evaluation.report import write_comparison

    paper = _pooled("paper", [[1.0, 2.0, 3.0, 4.0]], [[1.0, 1.0, 0.0, 0.0]])
    learned = _pooled("ppo", [[5.0, 6.0, 7.0, 8.0], [5.0, 6.0, 7.0, 9.0]], [[1.0] * 4] * 2)
    write_comparison([paper, learned], tmp_path, "S", reference="paper")
    with (tmp_path / "S_comparison.csv").open() as handle:
        rows = {(r["policy"], r["measure"]): r for r in csv.DictReader(handle)}
    row = rows[("ppo", "return")]
    assert (row["runs"], row["episodes"], row["reference"]) == ("2", "8", "paper")
    assert float(row["iqm"]) == 6.5 and float(row["p_improvement"]) == 1.0
    assert float(row["mean"]) == pytest.approx(6.625)
    assert rows[("ppo", "length")]["p_improvement"] == ""
    data = json.loads((tmp_path / "S_comparison.json").read_text())
    assert data[1]["reference"] == "paper"
    assert data[1]["robust"]["is_success"]["p_improvement"] == 0.75
    assert (
        "P(return > paper's) | (reference) | 1 [1, 1] |"
        in (tmp_path / "S_comparison.md").read_text()
    )
