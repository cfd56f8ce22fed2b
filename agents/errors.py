"""The one exception the command line turns into a one-line error (exit code 2)."""

from __future__ import annotations


class UsageError(Exception):
    """Bad input from the user: names the problem and the valid choices."""
