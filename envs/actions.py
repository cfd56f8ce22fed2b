"""Checking continuous actions before a world acts on them.

Every Box-action world rejects a wrong shape and a non-finite entry with a
``ValueError`` that names the problem. Bounds are each world's business:
Gymnasium's convention for Box actions (and SB3's, which clips to the
space before stepping) is that a world clips to its action space, and each
world documents that it does.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def checked_box_action(action: Any, shape: tuple[int, ...], meaning: str) -> np.ndarray:
    """``action`` as a float64 array of ``shape``, all finite, else ``ValueError``.

    Args:
        action: what the caller passed to ``step``.
        shape: the action space's shape.
        meaning: what the entries are, for the message (e.g. "one rate per joint").
    """
    if np.iscomplexobj(action) or isinstance(action, (str, bytes)):
        raise ValueError(
            f"action must be real numbers of shape {shape} ({meaning}), got {action!r}"
        )
    try:
        a = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(
            f"action must be real numbers of shape {shape} ({meaning}), got {action!r}"
        ) from None
    if a.shape != shape:
        raise ValueError(f"action must have shape {shape} ({meaning}), got {a.shape}")
    if not math.isfinite(a.sum()):
        raise ValueError(f"action must be finite (no NaN or inf), got {a.tolist()}")
    return a
