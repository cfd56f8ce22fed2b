"""The papers' algorithms as scripted reference policies, one subpackage per system."""

from __future__ import annotations

from motiongym.baselines.policy import ScriptedPolicy
from motiongym.baselines.registry import make_policy, scripted_policies

__all__ = ["ScriptedPolicy", "make_policy", "scripted_policies"]
