"""95 % intervals of a measure's mean over episodes.

* A measure in [0, 1] whose every episode is 0 or 1 (a success, a collision: unit
  ``rate`` or ``fraction``, see :data:`RATE_UNITS`) is a binomial proportion: its
  interval is Wilson's score interval (Wilson 1927; Brown, Cai and DasGupta 2001
  recommend it over the normal "Wald" interval, which leaves [0, 1] and covers
  badly near 0 and 1). It lies inside [0, 1] and is not symmetric about the mean.
* Any other measure: Student's t interval of the mean, ``mean ± t s / sqrt(n)``
  (``s`` the sample standard deviation); for a rate or fraction that takes other
  values (a coverage), clipped to [0, 1].
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

Z95 = 1.959963984540054  # two-sided 95 % normal quantile (scipy.stats.norm.ppf(0.975))

# Units of measures bounded by [0, 1] (their intervals lie inside it).
RATE_UNITS = ("rate", "fraction")
# Units of measures that are never negative (figures clip their intervals at 0).
COUNT_UNITS = ("steps", "count", "cells", "s", "m3", "ratio")


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
