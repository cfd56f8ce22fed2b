"""Prints the fuzz suite's counts per outcome (:data:`fuzzing.OUTCOMES`) at the end."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session", autouse=True)
def _print_counts():
    yield
    from fuzzing import OUTCOMES

    if OUTCOMES:
        print("\nfuzz outcomes:")
        for key, count in sorted(OUTCOMES.items()):
            print(f"  {key}: {count}")


def pytest_collection_modifyitems(items):
    """A hang is a failure: no fuzz test (all its examples) runs past 15 minutes."""
    for item in items:
        if "fuzz" in item.nodeid.split("::")[0]:
            item.add_marker(pytest.mark.timeout(900))
