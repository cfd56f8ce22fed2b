"""Each paper's evaluation on our scenes: ``motiongym reproduce NAME``.

Every experiment module exposes ``run(out_dir: Path, quick: bool = False) ->
dict``: it prints our figures beside the paper's, writes its figures and a
JSON of the numbers into ``out_dir`` and returns the numbers. ``quick`` runs
a reduced protocol (fewer trials) for tests.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

from motiongym.agents.errors import UsageError

EXPERIMENTS = {
    "sweeper": "motiongym.agents.reproduce.sweeper",
    "harvest-arm": "motiongym.agents.reproduce.harvest_arm",
    "dual-arm": "motiongym.agents.reproduce.dual_arm",
    "excavator": "motiongym.agents.reproduce.excavator",
}


def reproduce(name: str, out_dir: Path, quick: bool = False) -> dict[str, Any]:
    """Run the experiment ``name`` (one of :data:`EXPERIMENTS`)."""
    if name not in EXPERIMENTS:
        raise UsageError(f"unknown experiment {name!r}; valid: {', '.join(EXPERIMENTS)}")
    try:
        module = importlib.import_module(EXPERIMENTS[name])
    except ModuleNotFoundError as error:
        raise UsageError(f"experiment {name!r} is not built yet ({error})") from error
    return module.run(out_dir, quick=quick)
