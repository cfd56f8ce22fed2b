"""95 % intervals of a measure's mean over episodes.

* A measure in [0, 1] whose every episode is 0 or 1 (a success, a collision: unit
  ``rate`` or ``fraction``, see :data:`RATE_UNITS`) is a binomial proportion: its
  interval is Wilson's score interval (Wilson 1927; Brown, Cai and DasGupta 2001
  recommend it over the normal "Wald" interval, which leaves [0, 1] and covers
  badly near 0 and 1). It lies inside [0, 1] and is not symmetric about the mean.
* Any other measure: Student's t interval of the mean, ``mean ± t s / sqrt(n)``
  (``s`` the sample standard deviation); for a rate or fraction that takes other
  values (a coverage), clipped to [0, 1].

Beside them, the two aggregates that Agarwal, Schwarzer, Castro, Courville and
Bellemare recommend in "Deep Reinforcement Learning at the Edge of the Statistical
Precipice" (NeurIPS 2021; the ``rliable`` library), each with a stratified bootstrap
95 % interval (their section 4 and appendix A.2):

* the **interquartile mean** (IQM, their section 4.3): the mean of the middle 50 % of
  the values pooled over runs x episodes, ``scipy.stats.trim_mean(values, 0.25)``
  (``int(0.25 n)`` values cut from each end, as ``rliable.metrics.aggregate_iqm``).
  Robust to a few outlying episodes, unlike the mean, and less noisy than the median;
* the **probability of improvement** of X over Y (their section 4.4), ``P(X > Y) +
  P(X = Y) / 2`` for an episode X of one policy and an episode Y of the other drawn
  independently: the Mann-Whitney U statistic over ``n_x n_y``
  (``rliable.metrics.probability_of_improvement``). 0.5 for identical distributions,
  1 when every X beats every Y, 0 when every Y beats every X. Reported only for
  :data:`IMPROVEMENT_MEASURES`, where a larger value is better.

The **stratified bootstrap**: a run (a training seed, or the one run of a scripted
policy) is a stratum; each of :data:`BOOTSTRAP_RESAMPLES` resamples draws, within
every stratum, as many episodes as it has, with replacement, so every resample keeps
each run's weight; X and Y are resampled independently. The interval is the 2.5 and
97.5 percentiles of the statistic over the resamples (the percentile bootstrap,
``rliable``'s default). The resampling generator is seeded (:data:`BOOTSTRAP_SEED`),
so the same values give the same interval. ``rliable`` itself would install beside
the pins without touching them, but brings ten packages (pandas, statsmodels, arch,
seaborn among them) for these few lines of NumPy; motiongym has its own.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from motiongym.agents.evaluation.episodes import Evaluation

Z95 = 1.959963984540054  # two-sided 95 % normal quantile (scipy.stats.norm.ppf(0.975))

# Units of measures bounded by [0, 1] (their intervals lie inside it).
RATE_UNITS = ("rate", "fraction")
# Units of measures that are never negative (figures clip their intervals at 0).
COUNT_UNITS = ("steps", "count", "cells", "s", "m3", "ratio")
# Measures where a larger value is better: the probability of improvement is theirs.
IMPROVEMENT_MEASURES = ("return", "is_success", "coverage")
BOOTSTRAP_RESAMPLES = 2000  # resamples of a stratified bootstrap interval
BOOTSTRAP_SEED = 0  # seed of the bootstrap's generator


def t_half_width(values: Sequence[float] | np.ndarray) -> float:
    """Half-width of Student's 95 % t interval of the mean (0 for fewer than two values)."""
    values = np.asarray(values, dtype=float)
    n = len(values)
    if n < 2:
        return 0.0
    from scipy import stats  # imported here: scipy.stats costs seconds at start-up

    return float(stats.t.ppf(0.975, n - 1) * values.std(ddof=1) / np.sqrt(n))


def wilson_interval(successes: float, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson's score interval ``(low, high)`` of a proportion ``successes / n``."""
    if n < 1:
        raise ValueError(f"n must be at least 1, got {n}")
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return float(max(centre - half, 0.0)), float(min(centre + half, 1.0))


def interval(values: Sequence[float] | np.ndarray, unit: str = "") -> tuple[float, float]:
    """The 95 % interval ``(low, high)`` of the mean of ``values`` (see the module)."""
    values = np.asarray(values, dtype=float)
    mean = float(values.mean())
    if unit in RATE_UNITS:
        if np.all((values == 0.0) | (values == 1.0)):
            return wilson_interval(float(values.sum()), len(values))
        half = t_half_width(values)
        return max(mean - half, 0.0), min(mean + half, 1.0)
    half = t_half_width(values)
    return mean - half, mean + half


def _scores(values: Sequence[float] | np.ndarray, name: str) -> np.ndarray:
    """``values`` as a 1-D float array: at least one value, every one finite."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 1 or array.size == 0:
        raise ValueError(
            f"{name}: a non-empty 1-D sequence of numbers is needed, got shape {array.shape}"
        )
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name}: every value must be finite, got {array[~np.isfinite(array)]}")
    return array


def _labels(strata: Sequence[Any] | np.ndarray | None, n: int, name: str) -> np.ndarray:
    """A stratum label per value (one stratum when ``strata`` is None)."""
    if strata is None:
        return np.zeros(n, dtype=int)
    labels = np.asarray(strata)
    if labels.shape != (n,):
        raise ValueError(
            f"{name}: one stratum label per value is needed ({n}), got shape {labels.shape}"
        )
    return labels


def _check_bootstrap(resamples: int, confidence: float) -> None:
    if isinstance(resamples, bool) or not isinstance(resamples, (int, np.integer)):
        raise TypeError(f"resamples: an integer is needed, got {resamples!r}")
    if resamples < 1:
        raise ValueError(f"resamples: at least 1 is needed, got {resamples}")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence: a level in (0, 1) is needed, got {confidence}")


def iqm(values: Sequence[float] | np.ndarray) -> float:
    """The interquartile mean of ``values``: the mean of their middle 50 %."""
    from scipy import stats

    return float(stats.trim_mean(_scores(values, "values"), 0.25))


def probability_of_improvement(
    x: Sequence[float] | np.ndarray, y: Sequence[float] | np.ndarray
) -> float:
    """``P(X > Y) + P(X = Y) / 2`` over every pair of a value of ``x`` and one of ``y``."""
    return float(_improvement(_scores(x, "x")[None], _scores(y, "y")[None])[0])


def _improvement(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Row-wise probability of improvement of ``x`` (k, n_x) over ``y`` (k, n_y), from
    the Mann-Whitney U statistic: the sum of ``x``'s mid-ranks among both, less
    ``n_x (n_x + 1) / 2``, over ``n_x n_y``."""
    from scipy import stats

    n_x, n_y = x.shape[1], y.shape[1]
    ranks = stats.rankdata(np.concatenate([x, y], axis=1), axis=1)  # ties: mid-ranks
    u = ranks[:, :n_x].sum(axis=1) - n_x * (n_x + 1) / 2
    return np.asarray(u / (n_x * n_y))


def run_strata(seeds: Sequence[int]) -> np.ndarray:
    """A run label per episode: the k-th episode of a seed belongs to run k (a pooled
    learned agent runs every training seed on the same episode seeds; a scripted policy
    has one run)."""
    seen: dict[int, int] = {}
    labels = []
    for seed in seeds:
        labels.append(seen.get(seed, 0))
        seen[seed] = labels[-1] + 1
    return np.asarray(labels, dtype=int)


def stratified_resamples(
    strata: Sequence[Any] | np.ndarray, resamples: int, rng: np.random.Generator
) -> np.ndarray:
    """``(resamples, n)`` indices of ``n`` values labelled ``strata``: each row draws,
    at a stratum's positions, indices of that stratum only, with replacement."""
    labels = np.asarray(strata)
    rows = np.empty((resamples, len(labels)), dtype=int)
    for label in np.unique(labels):
        members = np.flatnonzero(labels == label)
        rows[:, members] = members[rng.integers(0, len(members), (resamples, len(members)))]
    return rows


def _percentiles(samples: np.ndarray, confidence: float) -> tuple[float, float]:
    tail = 100.0 * (1.0 - confidence) / 2.0
    low, high = np.percentile(samples, [tail, 100.0 - tail])
    return float(low), float(high)


def iqm_interval(
    values: Sequence[float] | np.ndarray,
    strata: Sequence[Any] | np.ndarray | None = None,
    resamples: int = BOOTSTRAP_RESAMPLES,
    seed: int = BOOTSTRAP_SEED,
    confidence: float = 0.95,
) -> tuple[float, float, float]:
    """``(IQM, low, high)``: the interquartile mean of ``values`` and its stratified
    bootstrap interval (``strata``: a label per value; None, one stratum)."""
    from scipy import stats

    array = _scores(values, "values")
    labels = _labels(strata, len(array), "strata")
    _check_bootstrap(resamples, confidence)
    rows = stratified_resamples(labels, resamples, np.random.default_rng(seed))
    samples = stats.trim_mean(array[rows], 0.25, axis=1)
    return (iqm(array), *_percentiles(samples, confidence))


def improvement_interval(
    x: Sequence[float] | np.ndarray,
    y: Sequence[float] | np.ndarray,
    x_strata: Sequence[Any] | np.ndarray | None = None,
    y_strata: Sequence[Any] | np.ndarray | None = None,
    resamples: int = BOOTSTRAP_RESAMPLES,
    seed: int = BOOTSTRAP_SEED,
    confidence: float = 0.95,
) -> tuple[float, float, float]:
    """``(P, low, high)``: the probability of improvement of ``x`` over ``y`` and its
    stratified bootstrap interval, ``x`` and ``y`` resampled independently, each
    within its own strata."""
    x_array, y_array = _scores(x, "x"), _scores(y, "y")
    x_labels = _labels(x_strata, len(x_array), "x_strata")
    y_labels = _labels(y_strata, len(y_array), "y_strata")
    _check_bootstrap(resamples, confidence)
    rng = np.random.default_rng(seed)
    x_rows = stratified_resamples(x_labels, resamples, rng)
    y_rows = stratified_resamples(y_labels, resamples, rng)
    samples = _improvement(x_array[x_rows], y_array[y_rows])
    return (probability_of_improvement(x_array, y_array), *_percentiles(samples, confidence))


def robust_statistics(
    evaluations: list[Evaluation], reference: str | None = None
) -> list[dict[str, dict[str, float]]]:
    """Per evaluation (in order), per measure: ``iqm``, ``iqm_low``, ``iqm_high`` and
    ``runs`` (its strata, :func:`run_strata`); for :data:`IMPROVEMENT_MEASURES`, when an
    evaluation's policy is ``reference`` (the paper's algorithm),
    ``p_improvement``, ``p_improvement_low``, ``p_improvement_high`` over it."""
    base = next((e for e in evaluations if reference is not None and e.policy == reference), None)
    results = []
    for evaluation in evaluations:
        strata = run_strata([int(episode["seed"]) for episode in evaluation.episodes])
        table: dict[str, dict[str, float]] = {}
        for key in evaluation.measures:
            values = [episode[key] for episode in evaluation.episodes]
            value, low, high = iqm_interval(values, strata)
            table[key] = {"iqm": value, "iqm_low": low, "iqm_high": high}
            table[key]["runs"] = len(np.unique(strata))
            if base is None or key not in IMPROVEMENT_MEASURES or key not in base.measures:
                continue
            other = [episode[key] for episode in base.episodes]
            other_strata = run_strata([int(episode["seed"]) for episode in base.episodes])
            p, p_low, p_high = improvement_interval(values, other, strata, other_strata)
            table[key].update(p_improvement=p, p_improvement_low=p_low, p_improvement_high=p_high)
        results.append(table)
    return results
