"""Learner-side features: memories and features extractors that configs name.

A config names them, never code: ``memory: sweeper_map`` (with ``memory_kwargs``)
wraps every environment of the run in that memory, and ``policy_kwargs`` may say
``features_extractor_class: sweeper_egocentric`` (with
``features_extractor_kwargs``). A feature that knows one world is declared by that
system, in its learners module (``motiongym.agents.learners.<system>``, see
:class:`motiongym.systems.System`): ``MEMORIES`` (``{name: MemoryWrapper
subclass}``, :mod:`.memory`) and ``FEATURES_EXTRACTORS`` (``{name: SB3
BaseFeaturesExtractor subclass}``). Features that know no world (``goal_error``,
for the goal IDs of every world: :mod:`.goal`) are listed here. Training, config
validation and the model loaders read the merged dicts below.
"""

from __future__ import annotations

from typing import Any

from motiongym.systems import declared


def memories() -> dict[str, Any]:
    """``{name: memory wrapper class}`` of every system's learners module."""
    return declared("learners", "MEMORIES")


def features_extractors() -> dict[str, Any]:
    """``{name: features extractor class}``: every system's, and those of no one world."""
    from motiongym.agents.learners.goal import GoalError

    return {"goal_error": GoalError, **declared("learners", "FEATURES_EXTRACTORS")}


def entry_shape(space: Any, key: str) -> tuple[int, ...]:
    """The shape of entry ``key`` of a ``Dict`` observation space (a ``ValueError`` where
    the entry has none: learner-side features take array entries only)."""
    shape = space[key].shape
    if shape is None:
        raise ValueError(f"observation entry {key!r} has no shape ({space[key]})")
    return tuple(shape)
