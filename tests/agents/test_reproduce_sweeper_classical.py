"""The table of PSA + CWA beside the classical coverage references (Sweeper-v1.md)."""

from __future__ import annotations

import pytest

from motiongym.agents.reproduce import sweeper_classical


def test_classical_table_has_a_row_per_map_and_policy(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sweeper_classical, "SHIPPED_MAPS", ("room",))
    monkeypatch.setattr(sweeper_classical, "POLICIES", ("ba-star", "spiral-stc"))
    lines = sweeper_classical.table(1).splitlines()
    assert len(lines) == 4 and lines[0].startswith("| map | policy | coverage at done")
    assert lines[2].startswith("| room | ba-star | 100.0 % / 100.0 % |")
    assert lines[3].startswith("| room | spiral-stc |") and "100.0 %" not in lines[3]
