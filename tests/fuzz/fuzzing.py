"""The fuzz suite's shared setup: Hypothesis profiles and the outcome counts.

``MOTIONGYM_FUZZ=fuzz`` (``make fuzz``) selects the full profile; the default
suite runs the fast one. Every test records its outcome in :data:`OUTCOMES`
(``"<area>: <outcome>"``); ``conftest.py`` prints the counts at the session's end.
"""

from __future__ import annotations

import os
from collections import Counter

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, settings  # noqa: E402

settings.register_profile(
    "fast", max_examples=4, deadline=None, suppress_health_check=list(HealthCheck)
)
settings.register_profile(
    "fuzz", max_examples=60, deadline=None, suppress_health_check=list(HealthCheck)
)
PROFILE = os.environ.get("MOTIONGYM_FUZZ", "fast")
settings.load_profile(PROFILE)

OUTCOMES: Counter = Counter()
