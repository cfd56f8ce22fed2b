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
