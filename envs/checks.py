"""Checking what a user hands a world: keywords, reset options, render settings.

Every check raises :class:`ArgumentError` (a ``ValueError``) whose message
names the argument, what was given and what is allowed::

    dof must be an integer in [3, 5], got 5.5

A system's frozen parameters dataclass calls them in ``__post_init__``; the
environment and its scripted policies build that one dataclass from the same
keyword arguments (:func:`params_from_kwargs`), so a default is written once
and a bad value is refused at construction, never per step.

Conventions decided here once for every world (``docs/adding_a_world.md``):

* **Reward weights** are magnitudes: :func:`check_weight` takes a finite
  number in ``[0, MAX_WEIGHT]``; each term's sign is fixed by its meaning
  (a cost is subtracted), so a negative weight is refused, never flipped.
* **Render size**: one keyword, ``render_size`` = ``(rows, columns)`` of a
  frame, the shape of the array ``render()`` returns
  (:func:`check_render_size`).
* **Deprecated names** (a keyword or reset option renamed): the old name is
  accepted for one release, converted to the new one, and warns once per
  process with a :class:`MotiongymDeprecationWarning`
  (:class:`Deprecated`, :func:`params_from_kwargs`, :func:`check_options`).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import warnings
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

MAX_WEIGHT = 1e6  # largest reward weight: every reward term stays finite
RENDER_SIDE = (16, 2048)  # pixels: the least and largest side of a rendered frame


# ---------------------------------------------------------------- deprecated names


class MotiongymDeprecationWarning(FutureWarning):
    """A keyword or reset option used under a name that the next release drops.

    A ``FutureWarning``, so that it shows by default in a user's script (a
    ``DeprecationWarning`` raised inside ``gym.make`` would be hidden).
    """


@dataclasses.dataclass(frozen=True)
class Deprecated:
    """An old name of a keyword or reset option, accepted for one release.

    ``new``: the name it became (None: the keyword itself is going away and
    is still read as before). ``convert(value, current)``: the new name's
    value from the old one's and the new name's current value (given by the
    caller, else its default); None: the value carries over as it is.
    ``note``: what to write instead, for the warning.
    """

    new: str | None
    convert: Callable[[Any, Any], Any] | None = None
    note: str = ""


_warned: set[tuple[str, str]] = set()


def warn_deprecated(where: str, old: str, rule: Deprecated) -> None:
    """Warn once per process that ``old`` (of ``where``, a class or "reset option") is
    deprecated."""
    if (where, old) in _warned:
        return
    _warned.add((where, old))
    instead = rule.note or (f"use {rule.new!r}" if rule.new else "it will be removed")
    warnings.warn(
        f"{where}: {old!r} is deprecated and will be removed in the next release; {instead}",
        MotiongymDeprecationWarning,
        stacklevel=3,
    )


def _renamed(
    values: Mapping[str, Any],
    deprecated: Mapping[str, Deprecated],
    where: str,
    defaults: Mapping[str, Any],
) -> dict[str, Any]:
    """``values`` with every deprecated name replaced by its new one (warned once)."""
    out = dict(values)
    for old, rule in deprecated.items():
        if old not in out or rule.new is None:
            if old in out:
                warn_deprecated(where, old, rule)
            continue
        if rule.new in values:
            raise ArgumentError(f"give {rule.new!r} or its deprecated name {old!r}, not both")
        value = out.pop(old)
        warn_deprecated(where, old, rule)
        current = out.get(rule.new, defaults.get(rule.new))
        out[rule.new] = value if rule.convert is None else rule.convert(value, current)
    return out


def params_from_kwargs(cls: type[P], kwargs: Mapping[str, Any], ignore: Iterable[str] = ()) -> P:
    """Build the frozen parameters dataclass ``cls`` from an environment's keywords.

    Keys in ``ignore`` (``render_mode``, say) are dropped; a deprecated name
    listed in ``cls.DEPRECATED`` (``{old: Deprecated}``, optional) becomes its
    new one with a warning; an unknown key is an :class:`ArgumentError`
    listing the valid ones. Validation is the dataclass's own ``__post_init__``.
    """
    fields = {f.name: f for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    deprecated: Mapping[str, Deprecated] = getattr(cls, "DEPRECATED", {})
    ignored = set(ignore)
    if deprecated:
        defaults = {n: f.default for n, f in fields.items() if f.default is not dataclasses.MISSING}
        kwargs = _renamed(
            {k: v for k, v in kwargs.items() if k not in ignored}, deprecated, cls.__name__,
            defaults,
        )  # fmt: skip
    unknown = sorted(set(kwargs) - set(fields) - ignored)
    if unknown:
        raise ArgumentError(
            f"unknown keyword argument(s) {', '.join(unknown)}; valid: {', '.join(sorted(fields))}"
        )
    return cls(**{k: v for k, v in kwargs.items() if k in fields})


# ---------------------------------------------------------------- conventions


def check_weight(name: str, value: Any, cost: bool = True) -> float:
    """A reward weight: a finite number in ``[0, MAX_WEIGHT]``.

    Weights are magnitudes; the term's sign is its meaning's (a cost is
    subtracted), so a negative weight is refused with that reason: for a
    ``cost`` term the message gives the positive weight of the same reward;
    for a term that is paid (``cost=False``) no weight gives it.
    """
    try:
        return check_float(name, value, 0.0, MAX_WEIGHT)
    except ArgumentError:
        if isinstance(value, numbers.Real) and math.isfinite(float(value)) and value < 0:
            why = (
                f"a cost term is subtracted (give {name}={-float(value)!r} for the same reward)"
                if cost
                else f"{name} is paid (added), so no weight makes it a cost"
            )
            raise ArgumentError(
                f"{name} must be a reward weight in [0, {MAX_WEIGHT:g}], got {value!r}: "
                f"weights are magnitudes, {why}"
            ) from None
        raise


def check_render_size(name: str, value: Any) -> tuple[int, int]:
    """``(rows, columns)`` of a rendered frame, each an integer in :data:`RENDER_SIDE`."""
    lo, hi = RENDER_SIDE
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) != 2:
        raise _fail(name, f"(rows, columns), two integers in [{lo}, {hi}]", value)
    return (check_int(f"{name}[0]", value[0], lo, hi), check_int(f"{name}[1]", value[1], lo, hi))


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
    options: Any,
    validators: Mapping[str, Callable[[str, Any], Any]],
    deprecated: Mapping[str, Deprecated] | None = None,
) -> dict[str, Any]:
    """Reset ``options`` as a dict of validated values.

    ``validators`` maps each accepted key to ``check(name, value) -> value``
    (one of this module's checks, partially applied); the name passed is
    ``options['key']``. ``deprecated`` maps an old option name to its new
    one (converted, warned once). ``None`` is an empty dict; anything but a
    dict, or an undeclared key, is an :class:`ArgumentError`.
    """
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise _fail("options", "None or a dict", options)
    if deprecated:
        options = _renamed(options, deprecated, "reset option", {})
    unknown = sorted(set(options) - set(validators), key=str)
    if unknown:
        valid = ", ".join(validators) or "none"
        raise ArgumentError(f"unknown reset option(s) {unknown}; valid: {valid}")
    return {key: validators[key](f"options[{key!r}]", value) for key, value in options.items()}


# ---------------------------------------------------------------- vector environments

VECTOR_MEMORY_BOUND = 4 << 30  # bytes a natively vectorised world may hold for its sub-envs


def check_num_envs(value: Any, bytes_per_env: int, memory_bound: int = VECTOR_MEMORY_BOUND) -> int:
    """``num_envs`` of a natively vectorised world: an integer in ``[1, memory_bound //
    bytes_per_env]``, ``bytes_per_env`` being the world's upper estimate of one
    sub-environment's state and observations (its vector env's docstring derives it)."""
    high = max(1, memory_bound // bytes_per_env)
    try:
        return check_int("num_envs", value, 1, high)
    except ArgumentError as error:
        raise ArgumentError(
            f"{error} (the memory bound: {memory_bound / 2**30:g} GiB at up to "
            f"{bytes_per_env / 1024:.1f} KiB per sub-environment with these parameters)"
        ) from None


def per_env(
    name: str,
    value: Any,
    num_envs: int,
    is_one: Callable[[Any], bool],
    check: Callable[[str, Any], Any],
) -> list[Any]:
    """A reset option of a vector env, given either once for every sub-environment
    (``is_one(value)`` true) or as a sequence of one value per sub-environment: the list
    of ``num_envs`` values, each passed through ``check(name, value)`` (named
    ``name[i]`` when per sub-environment). A sequence of another length is an
    :class:`ArgumentError`."""
    if is_one(value):
        return [check(name, value)] * num_envs
    allowed = f"one value for every sub-environment or a sequence of num_envs={num_envs} values"
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, (Sequence, np.ndarray)):
        raise _fail(name, allowed, value)
    if len(value) != num_envs:
        raise ArgumentError(f"{name} must be {allowed}, got {len(value)} values: {value!r}")
    return [check(f"{name}[{i}]", item) for i, item in enumerate(value)]
