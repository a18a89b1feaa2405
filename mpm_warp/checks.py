"""Argument checks that turn bad input into :class:`InvalidArgument` naming the field, the value and the range."""

from __future__ import annotations

import dataclasses
import math
import os
import typing
from collections.abc import Sequence

import numpy as np

from .errors import InvalidArgument


def finite_number(field: str, value, *, lo=None, hi=None, lo_open=False, hi_open=False) -> float:
    """Return ``value`` as a float, checking it is finite and within ``[lo, hi]``.

    ``lo_open``/``hi_open`` make the bound strict. The error names the field,
    the value and the allowed range.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidArgument(field, value, "a number")
    v = float(value)
    lo_s = "-inf" if lo is None else f"{lo:g}"
    hi_s = "inf" if hi is None else f"{hi:g}"
    rng = f"{'(' if lo_open or lo is None else '['}{lo_s}, {hi_s}{')' if hi_open or hi is None else ']'}"
    if not math.isfinite(v):
        raise InvalidArgument(field, value, f"a finite number in {rng}")
    if lo is not None and (v < lo or (lo_open and v == lo)):
        raise InvalidArgument(field, value, f"a number in {rng}")
    if hi is not None and (v > hi or (hi_open and v == hi)):
        raise InvalidArgument(field, value, f"a number in {rng}")
    return v


def vector(field: str, value, n: int = 3, *, nonzero: bool = False) -> tuple[float, ...]:
    """Return ``value`` as a tuple of ``n`` finite floats (``n`` = the scene's dimension, 2 or 3)."""
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)) or len(value) != n:
        raise InvalidArgument(field, value, f"a list of {n} numbers" + (" (x, y: the scene is 2D)" if n == 2 else ""))
    out = tuple(finite_number(f"{field}[{i}]", c) for i, c in enumerate(value))
    if nonzero and all(c == 0.0 for c in out):
        raise InvalidArgument(field, value, "a non-zero vector")
    return out


def choice(field: str, value, allowed: Sequence[str]) -> str:
    """Check that ``value`` is one of ``allowed`` (strings)."""
    if value not in allowed:
        raise InvalidArgument(field, value, "one of " + ", ".join(repr(a) for a in allowed))
    return value


def positive_int(field: str, value, *, lo: int = 1, hi: int | None = None) -> int:
    """Check an integer in ``[lo, hi]``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidArgument(field, value, "an integer")
    if value < lo or (hi is not None and value > hi):
        raise InvalidArgument(field, value, f"an integer in [{lo}, {hi if hi is not None else 'inf'}]")
    return int(value)


def check_choices(obj, where: str) -> None:
    """Check every ``Literal``-typed field of the dataclass ``obj`` and of its nested dataclasses (:func:`choice`)."""
    hints = typing.get_type_hints(type(obj))
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if typing.get_origin(hints[f.name]) is typing.Literal:
            choice(f"{where}.{f.name}", value, typing.get_args(hints[f.name]))
        elif dataclasses.is_dataclass(value) and not isinstance(value, type):
            check_choices(value, f"{where}.{f.name}")


def flag(field: str, value) -> bool:
    """Check a bool (``overwrite="no"`` is not a yes: any other type is refused)."""
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidArgument(field, value, "True or False")
    return bool(value)


def file_path(field: str, value, *, none: bool = False) -> str | None:
    """Check a file path (``str`` or ``os.PathLike``, not empty); None too when ``none``. Returns a ``str``."""
    if value is None and none:
        return None
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str) or not value:
        raise InvalidArgument(field, value, "a file path (str or os.PathLike)" + (" or None" if none else ""))
    return value


def optional_callable(field: str, value):
    """Check None or a callable."""
    if value is not None and not callable(value):
        raise InvalidArgument(field, value, "None or a callable")
    return value
