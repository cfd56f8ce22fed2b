"""The trained models shipped in ``agents/models/pretrained/``.

Layout: ``pretrained/<Name>-vN/<label>/`` (the algorithm, with ``-shared`` or
``-dagger`` for those kinds, :func:`motiongym.agents.models.ship.shipped_label`) holds a
run folder's ``model.zip``, ``config.yml``, ``command.txt``, ``metrics.json``
(with the agent's ``kind``: ``scratch``, ``demonstrations`` or ``residual``),
optionally ``vecnormalize.npz`` and ``dagger.json``, and ``manifest.json``: the
SHA-256 of every other file.
The manifest is checked before a model is used. :mod:`motiongym.agents.models.ship`
puts a run's model here.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

from motiongym.agents import limits
from motiongym.agents.environments import short_name
from motiongym.agents.errors import UsageError

MANIFEST = "manifest.json"
SHIPPED_FILES = ("model.zip", "vecnormalize.npz", "config.yml", "command.txt", "dagger.json")
METRICS = "metrics.json"
LEARNING_CURVES = "learning_curves.csv"


def pretrained_root() -> Path:
    return Path(str(resources.files("motiongym.agents.models") / "pretrained"))


MAX_MANIFEST_BYTES = 1 << 20


def sha256(path: Path) -> str:
    """The file's SHA-256, its size capped first (:func:`motiongym.agents.limits.sha256`)."""
    return limits.sha256(path)


def write_manifest(folder: Path) -> Path:
    """Record the SHA-256 of every file of ``folder`` (but the manifest)."""
    digests = {
        p.name: sha256(p) for p in sorted(folder.iterdir()) if p.is_file() and p.name != MANIFEST
    }
    path = folder / MANIFEST
    path.write_text(json.dumps(digests, indent=2) + "\n")
    return path


def verify_manifest(folder: Path, required: tuple[str, ...] = ()) -> None:
    """Raise :class:`UsageError` unless every file matches the manifest.

    The manifest must be a JSON object of plain file names (no folder parts)
    to SHA-256 hex digests, and must list every file of ``required`` that
    exists (the files about to be read): a manifest that leaves out the model
    verifies nothing.
    """
    manifest = folder / MANIFEST
    if not manifest.is_file():
        raise UsageError(f"{folder} has no {MANIFEST}")
    digests = limits.read_json_file(manifest, MAX_MANIFEST_BYTES)
    if not isinstance(digests, dict) or not all(
        isinstance(n, str)
        and Path(n).name == n
        and n not in ("", ".", "..")
        and isinstance(d, str)
        and len(d) == 64
        for n, d in digests.items()
    ):
        raise UsageError(f"{manifest} must map plain file names to SHA-256 hex digests")
    unlisted = [name for name in required if (folder / name).exists() and name not in digests]
    if unlisted:
        raise UsageError(f"{manifest} does not list {unlisted}; refused")
    for name, digest in digests.items():
        path = folder / name
        if not path.is_file():
            raise UsageError(f"{path} is listed in {manifest} but missing")
        if sha256(path) != digest:
            raise UsageError(f"{path} does not match its SHA-256 in {manifest}")


def pretrained_models(env_id: str) -> dict[str, Path]:
    """``{label: folder}`` of the models shipped for ``env_id`` (label ``<algo>``, with
    ``-shared`` or ``-residual`` appended: :func:`~motiongym.agents.models.ship.shipped_label`)."""
    root = pretrained_root() / short_name(env_id)
    if not root.is_dir():
        return {}
    return {
        folder.name: folder for folder in sorted(root.iterdir()) if (folder / "model.zip").is_file()
    }
