"""Results files hold no inf or NaN: a value that does not exist is JSON null, with the reason beside it.

:func:`finite_json` turns every non-finite number of a result into None and, in the dict holding it, puts the
reason under ``<key>_null`` (unless the producer gave one already: e.g. "the front did not reach 3.8 m: no
speed"). :func:`~mpm_warp.studies.environment.write_json` writes through it with ``allow_nan=False``.

:func:`load_json` reads such a file back with nan where the writer put null for a number (the nulls with a
``<key>_null`` reason beside them), so code that computes with the values reads what it wrote.

``python -m mpm_warp.finite_json FILE...`` rewrites results files of older releases this way (values
unchanged; ``NaN`` and ``Infinity`` tokens become null with a reason).
"""

from __future__ import annotations

import json
import math
import numbers
import os
import sys

import numpy as np

__all__ = ["finite_json", "non_finite_reason", "dump_finite", "load_json", "with_nan", "main"]


def non_finite_reason(v) -> str | None:
    """Why ``v`` (a number or a list of numbers) goes to JSON as null, None when nothing does."""
    if isinstance(v, np.ndarray):
        v = v.tolist()
    if _bad(v):
        return f"no value: the computation gave {v!r}"
    if isinstance(v, (list, tuple)):
        n = sum(1 for x in v if _bad(x))
        if n:
            return f"null entries ({n} of {len(v)}): no value there (the computation gave nan or inf)"
    return None


def _bad(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, (bool, numbers.Integral)) and not math.isfinite(v)


def finite_json(obj):
    """A copy of ``obj`` (dicts, lists, numbers, NumPy arrays and scalars) with no non-finite number.

    A non-finite number becomes None; in a dict, the entry ``k`` that is one, or a list holding some, gets
    ``k + "_null"`` with :func:`non_finite_reason` unless the dict has that key.
    """
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            out[k] = finite_json(v)
            why = non_finite_reason(v)
            if why is not None and f"{k}_null" not in obj:
                out[f"{k}_null"] = why
        return out
    if isinstance(obj, np.ndarray):
        return finite_json(obj.tolist())
    if isinstance(obj, (list, tuple)):
        return [finite_json(v) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if _bad(obj):
        return None
    return obj


def dump_finite(data, fh, **kwargs) -> None:
    """``json.dump`` of :func:`finite_json` of ``data`` (``allow_nan=False``: a non-finite number left raises)."""
    json.dump(finite_json(data), fh, allow_nan=False, **kwargs)


def with_nan(obj):
    """``obj`` read from a results file with nan for every null the writer put for a non-finite number: an entry
    ``k`` (or the entries of a list ``k``) of a dict that has ``k + "_null"``. Other nulls stay None."""
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            if f"{k}_null" in obj and isinstance(obj[f"{k}_null"], str):
                if v is None:
                    v = math.nan
                elif isinstance(v, list):
                    v = [math.nan if x is None else x for x in v]
            out[k] = with_nan(v)
        return out
    if isinstance(obj, list):
        return [with_nan(v) for v in obj]
    return obj


def load_json(source):
    """A results file (a path or an open file) through :func:`with_nan`."""
    if isinstance(source, (str, os.PathLike)):
        with open(source) as fh:
            return with_nan(json.load(fh))
    return with_nan(json.load(source))


def main(argv=None) -> int:
    """Rewrite the results files named in ``argv`` through :func:`finite_json` (see the module docstring)."""
    for path in (sys.argv[1:] if argv is None else argv):
        with open(path) as fh:
            data = json.load(fh)
        with open(path + ".tmp", "w") as fh:
            dump_finite(data, fh, indent=1)
            fh.write("\n")
        os.replace(path + ".tmp", path)
        print("wrote", path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
