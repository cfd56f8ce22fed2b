"""Scripted reference policies for the excavator world."""

from __future__ import annotations

POLICIES: dict[str, dict[str, str]] = {}
