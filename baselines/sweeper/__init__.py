"""Scripted reference policies for the sweeper world."""

from __future__ import annotations

POLICIES: dict[str, dict[str, str]] = {}
