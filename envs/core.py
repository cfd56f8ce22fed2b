"""What every motiongym world does the same way: one place, one message style.

* **Arguments.** :func:`check_choice`, :func:`check_int`, :func:`check_float`,
  :func:`check_bool`, :func:`check_shape` validate one keyword argument or
  reset option and raise :class:`ArgumentError` (a ``ValueError``) whose
  message names the argument, what was given and what is allowed::

      dof must be an integer in [3, 5], got 5.5

  A system's frozen parameters dataclass calls them in ``__post_init__``; the
  environment and its scripted policies build that one dataclass from the
  same keyword arguments (:func:`params_from_kwargs`), so a default is written
  once and a bad value is refused at construction, never per step.
* **Render mode and reset options.** :func:`check_render_mode` and
  :func:`check_options` (``options`` must be ``None`` or a dict whose keys are
  declared).
* **Reward terms.** :func:`reward_and_info`: named terms whose sum, in their
  declared order, is the reward; ``info`` gets ``reward_<term>`` for each, the
  safety ``cost`` and ``is_success`` beside the world's measures.
* **Observation layout.** :class:`ObservationLayout`: named fields with a
  shape, a unit and a meaning; it packs (every field written, nothing else),
  parses (Meta-World's check: the fields cover the whole vector), sets bounds
  and writes the docstring's table.
* **Reset before step.** :class:`NeedsReset` raises a clear error from an
  unwrapped ``step()`` / ``render()`` before the first ``reset()``.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np


class ArgumentError(ValueError):
    """A keyword argument, reset option or action outside what is allowed."""


def _fail(name: str, allowed: str, value: Any) -> ArgumentError:
    return ArgumentError(f"{name} must be {allowed}, got {value!r}")


# ---------------------------------------------------------------- arguments


def check_choice(name: str, value: Any, choices: Iterable[Any]) -> Any:
    """``value`` if it is one of ``choices`` (compared with ``==`` and same type)."""
    choices = tuple(choices)
    for choice in choices:
        if type(value) is type(choice) and value == choice:
            return value
    listed = ", ".join(repr(c) for c in choices)
    raise _fail(name, f"one of {listed}", value)


def check_bool(name: str, value: Any) -> bool:
    """``value`` if it is a ``bool`` (or NumPy bool): no truthy strings or numbers."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise _fail(name, "True or False", value)


def check_int(name: str, value: Any, low: int | None = None, high: int | None = None) -> int:
    """``value`` as an ``int`` in ``[low, high]`` (either bound may be open: None).

    Floats are refused even when whole (``5.0``): an integer argument is a
    count or an index, and a float there is a mistake worth naming.
    """
    allowed = _interval("an integer", low, high, closed=(True, True))
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise _fail(name, allowed, value)
    v = int(value)
    if (low is not None and v < low) or (high is not None and v > high):
        raise _fail(name, allowed, value)
    return v


def check_float(
    name: str,
    value: Any,
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    high_open: bool = False,
) -> float:
    """``value`` as a finite ``float`` in the interval (bounds open where said)."""
    allowed = _interval("a finite number", low, high, closed=(not low_open, not high_open))
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise _fail(name, allowed, value)
    v = float(value)
    if not math.isfinite(v):
        raise _fail(name, allowed, value)
    if low is not None and (v < low or (low_open and v == low)):
        raise _fail(name, allowed, value)
    if high is not None and (v > high or (high_open and v == high)):
        raise _fail(name, allowed, value)
    return v


def check_shape(
    name: str, value: Any, shape: tuple[int | None, ...], *, finite: bool = True
) -> np.ndarray:
    """``value`` as a float64 array of ``shape`` (None: any length), finite if asked."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise _fail(name, f"an array of shape {_shape_text(shape)}", value) from None
    if a.ndim != len(shape) or any(
        s is not None and s != n for s, n in zip(shape, a.shape, strict=True)
    ):
        raise _fail(name, f"an array of shape {_shape_text(shape)}", value)
    if finite and not np.isfinite(a).all():
        raise _fail(name, "finite (no NaN or inf)", value)
    return a


def _shape_text(shape: tuple[int | None, ...]) -> str:
    return (
        "("
        + ", ".join("n" if s is None else str(s) for s in shape)
        + ("," if len(shape) == 1 else "")
        + ")"
    )


def _interval(kind: str, low: Any, high: Any, closed: tuple[bool, bool]) -> str:
    if low is None and high is None:
        return kind
    if high is None:
        return f"{kind} {'>=' if closed[0] else '>'} {low}"
    if low is None:
        return f"{kind} {'<=' if closed[1] else '<'} {high}"
    return f"{kind} in {'[' if closed[0] else '('}{low}, {high}{']' if closed[1] else ')'}"


P = TypeVar("P")


def params_from_kwargs(cls: type[P], kwargs: Mapping[str, Any], ignore: Iterable[str] = ()) -> P:
    """Build the frozen parameters dataclass ``cls`` from an environment's keywords.

    Keys in ``ignore`` (``render_mode``, say) are dropped; an unknown key is an
    :class:`ArgumentError` listing the valid ones. Validation is the
    dataclass's own ``__post_init__``.
    """
    fields = {f.name for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    ignored = set(ignore)
    unknown = sorted(set(kwargs) - fields - ignored)
    if unknown:
        raise ArgumentError(
            f"unknown keyword argument(s) {', '.join(unknown)}; valid: {', '.join(sorted(fields))}"
        )
    return cls(**{k: v for k, v in kwargs.items() if k in fields})


# ---------------------------------------------------------------- render mode, options


def check_render_mode(render_mode: Any, allowed: Sequence[str]) -> str | None:
    """``render_mode`` if it is None or one of ``allowed``; ``"human"`` only where a
    window can open (:func:`~motiongym.envs.rendering.missing_display`)."""
    if render_mode is None:
        return None
    mode = check_choice("render_mode", render_mode, (None, *allowed))
    if mode == "human":
        from motiongym.envs.rendering import missing_display

        problem = missing_display()
        if problem is not None:
            raise ArgumentError(
                f"render_mode='human' needs a display to open a window ({problem}); "
                "use render_mode='rgb_array' or `motiongym record`, or run under a "
                "virtual display (xvfb-run)"
            )
    return mode


def check_keys(name: str, value: Any, valid: Iterable[str]) -> dict[str, Any]:
    """``value`` as a dict whose keys are all in ``valid`` (a settings mapping such as a
    config's ``memory_kwargs``); anything but a mapping, or another key, is an
    :class:`ArgumentError` naming ``name``."""
    valid = list(valid)
    if not isinstance(value, Mapping):
        raise ArgumentError(f"{name} must be a mapping, got {value!r}")
    unknown = sorted(set(value) - set(valid), key=str)
    if unknown:
        raise ArgumentError(f"unknown {name} key {unknown[0]!r}; valid: {', '.join(valid)}")
    return dict(value)


def check_options(
    options: Any, validators: Mapping[str, Callable[[str, Any], Any]]
) -> dict[str, Any]:
    """Reset ``options`` as a dict of validated values.

    ``validators`` maps each accepted key to ``check(name, value) -> value``
    (one of this module's checks, partially applied); the name passed is
    ``options['key']``. ``None`` is an empty dict; anything but a dict, or an
    undeclared key, is an :class:`ArgumentError`.
    """
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise _fail("options", "None or a dict", options)
    unknown = sorted(set(options) - set(validators), key=str)
    if unknown:
        valid = ", ".join(validators) or "none"
        raise ArgumentError(f"unknown reset option(s) {unknown}; valid: {valid}")
    return {key: validators[key](f"options[{key!r}]", value) for key, value in options.items()}


# ---------------------------------------------------------------- reward terms


def reward_and_info(
    terms: Mapping[str, float], *, cost: float, is_success: bool, **measures: Any
) -> tuple[float, dict[str, Any]]:
    """The reward (the terms' sum, in their order) and the step's ``info``.

    ``info`` holds ``is_success``, ``cost``, the ``measures`` and
    ``reward_<term>`` for every term.
    """
    info: dict[str, Any] = {"is_success": bool(is_success), "cost": float(cost), **measures}
    return add_reward_terms(info, terms), info


def add_reward_terms(info: dict[str, Any], terms: Mapping[str, float]) -> float:
    """Write ``reward_<term>`` for every term into ``info``; return the reward (their
    sum, in their order). For a step that builds its ``info`` itself, in the layout of
    :func:`reward_and_info`."""
    for key, value in terms.items():
        info[f"reward_{key}"] = float(value)
    return float(sum(terms.values()))


def zero_terms(names: Iterable[str]) -> dict[str, float]:
    """Every term 0.0 (the reset's ``info``)."""
    return {name: 0.0 for name in names}


# ---------------------------------------------------------------- observation layout


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


# ---------------------------------------------------------------- reset before step


class NeedsReset:
    """Mixin: ``self._require_reset("step")`` raises until ``self._was_reset`` is set.

    An environment sets ``self._was_reset = True`` at the end of ``reset``
    and calls ``self._require_reset(...)`` first in ``step`` and ``render``.
    Gymnasium's ``OrderEnforcing`` wrapper does the same for ``gym.make``; this
    guards the unwrapped class.
    """

    _was_reset: bool = False

    def _require_reset(self, what: str) -> None:
        if not self._was_reset:
            raise RuntimeError(f"call reset() before {what}()")
