"""Scripted reference policies for the dual arm world."""

from __future__ import annotations

POLICIES: dict[str, dict[str, str]] = {}
