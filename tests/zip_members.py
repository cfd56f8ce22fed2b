"""Test support: rewriting a zip archive's members (a model.zip tampered with)."""

from __future__ import annotations

import zipfile
from collections.abc import Callable
from pathlib import Path


def rewrite_zip(path: Path, change: Callable[[dict[str, bytes]], None]) -> None:
    """Apply ``change`` to ``{member name: bytes}`` of the zip at ``path``, in place."""
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    change(members)
    with zipfile.ZipFile(path, "w") as archive:
        for name, content in members.items():
            archive.writestr(name, content)
