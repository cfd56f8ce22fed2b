"""Each paper's evaluation on our scenes: ``motiongym reproduce NAME``.

Every experiment module exposes ``run(out_dir: Path, quick: bool = False) ->
dict``: it prints our figures beside the paper's, writes its figures and a
JSON of the numbers into ``out_dir`` and returns the numbers. ``quick`` runs
a reduced protocol (fewer trials) for tests.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path
from typing import Any

from motiongym.agents.errors import UsageError
from motiongym.systems import SYSTEMS


def experiments() -> dict[str, str]:
    """``{experiment name: module}`` of every system that declares a reproduction."""
    return {s.name: s.reproduction for s in SYSTEMS if s.reproduction is not None}


EXPERIMENTS = experiments()


def reproduce(
    name: str, out_dir: Path, quick: bool = False, seeds: int | None = None
) -> dict[str, Any]:
    """Run the experiment ``name`` (one of :func:`experiments`); ``seeds``, where an
    experiment takes it (its ``run`` has a ``seeds`` argument), sets its trial count."""
    found = experiments()
    if name not in found:
        raise UsageError(f"unknown experiment {name!r}; valid: {', '.join(found)}")
    run = importlib.import_module(found[name]).run
    if seeds is None:
        return run(out_dir, quick=quick)
    if "seeds" not in inspect.signature(run).parameters:
        raise UsageError(f"experiment {name!r} takes no --seeds")
    return run(out_dir, quick=quick, seeds=seeds)
