"""One layout for every flat (Box) observation: named fields with a shape, a unit and a meaning.

:class:`ObservationLayout` packs an observation (every field written,
nothing else), parses it (Meta-World's check: the fields cover the whole
vector), sets its bounds and writes the docstring's table. Environments write
with it and scripted policies read with it, so both agree on every index.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np


@dataclasses.dataclass(frozen=True)
class Field:
    """One named part of a flat observation: its shape, unit and meaning."""

    name: str
    shape: tuple[int, ...]
    unit: str = "-"
    meaning: str = ""

    @property
    def size(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))


class ObservationLayout:
    """A flat float32 observation as named fields, in order.

    ``fields`` are :class:`Field` objects or ``(name, shape, unit, meaning)``
    tuples (shape an int or a tuple). The same object builds the observation
    (:meth:`pack`), reads it (:meth:`parse`), sets its bounds
    (:meth:`bounds`) and documents it (:meth:`table`).
    """

    def __init__(self, fields: Iterable[Field | tuple]) -> None:
        self.fields: tuple[Field, ...] = tuple(_as_field(f) for f in fields)
        names = [f.name for f in self.fields]
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate field names in {names}")
        self.slices: dict[str, slice] = {}
        start = 0
        for f in self.fields:
            self.slices[f.name] = slice(start, start + f.size)
            start += f.size
        self.size = start

    def __getitem__(self, name: str) -> slice:
        return self.slices[name]

    def __contains__(self, name: str) -> bool:
        return name in self.slices

    def pack(self, parts: Mapping[str, Any], out: np.ndarray | None = None) -> np.ndarray:
        """The observation from ``{name: value}``: every field, no other name."""
        missing = [f.name for f in self.fields if f.name not in parts]
        extra = sorted(set(parts) - set(self.slices))
        if missing or extra:
            raise ValueError(f"observation parts missing {missing}, unknown {extra}")
        buf = np.empty(self.size, np.float32) if out is None else out
        for f in self.fields:
            buf[self.slices[f.name]] = np.ravel(parts[f.name])
        return buf

    def parse(self, observation: Any) -> dict[str, np.ndarray]:
        """``{name: float64 array of the field's shape}``; the fields must cover the vector."""
        o = np.asarray(observation, dtype=np.float64)
        if o.shape != (self.size,):
            raise ValueError(f"observation must have shape ({self.size},) to parse, got {o.shape}")
        return {f.name: o[self.slices[f.name]].reshape(f.shape) for f in self.fields}

    def bounds(self, limits: Mapping[str, tuple[Any, Any]]) -> tuple[np.ndarray, np.ndarray]:
        """``(low, high)`` float32 arrays from ``{name: (low, high)}`` for every field."""
        missing = [f.name for f in self.fields if f.name not in limits]
        if missing:
            raise ValueError(f"bounds missing for {missing}")
        low = np.empty(self.size, np.float32)
        high = np.empty(self.size, np.float32)
        for f in self.fields:
            lo, hi = limits[f.name]
            low[self.slices[f.name]] = np.broadcast_to(np.ravel(lo), (f.size,))
            high[self.slices[f.name]] = np.broadcast_to(np.ravel(hi), (f.size,))
        return low, high

    def table(self) -> str:
        """A reStructuredText table (index, name, unit, meaning) for a docstring."""
        rows = [("index", "name", "unit", "meaning")]
        for f in self.fields:
            s = self.slices[f.name]
            index = str(s.start) if s.stop - s.start == 1 else f"{s.start}-{s.stop - 1}"
            rows.append((index, f.name, f.unit, f.meaning))
        widths = [max(len(r[i]) for r in rows) for i in range(4)]
        rule = "  ".join("=" * w for w in widths)
        lines = [
            rule,
            "  ".join(c.ljust(w) for c, w in zip(rows[0], widths, strict=True)).rstrip(),
            rule,
        ]
        lines += [
            "  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows[1:]
        ]
        lines.append(rule)
        return "\n".join(lines)


def _as_field(f: Field | tuple) -> Field:
    if isinstance(f, Field):
        return f
    name, shape, *rest = f
    shape = (shape,) if isinstance(shape, int) else tuple(shape)
    return Field(name, shape, *rest)
