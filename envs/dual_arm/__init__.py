"""The dual arm world (not yet built)."""

from __future__ import annotations

REGISTRATIONS: tuple[dict, ...] = ()
