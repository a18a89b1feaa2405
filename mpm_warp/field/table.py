"""A table of field PSTs (CSV) as profiles and records, so that published tables run like CAAML pits.

One row is one PST. Columns (header names carry their units; blank = not given):

==================== ===================================================================================
``id``               a name for the test (required)
``outcome``          End, SF or Arr (required; as the observer wrote it)
``slope_deg``        slope angle (deg, required)
``column_cm``        column length (cm, required)
``cut_cm``           the recorded cut (cm, required)
``slab_cm``          slab thickness (cm, vertical) and
``slab_density``     its mean density (kg/m^3), or instead
``layers``           a CSV of the slab's layers, top to bottom, with columns ``thickness_cm, density``
                     (a path relative to the table)
``weak_layer_cm``    weak-layer thickness (cm, vertical; required)
``weak_layer_density`` its density (kg/m^3; optional)
``w_f``              its fracture energy (J/m^2; optional: else read back from the cut)
``column_ends``      ``vertical`` or ``slope_normal`` (optional; default slope_normal)
==================== ===================================================================================

:func:`table_profiles` turns each row into a :class:`~mpm_warp.scenes.profile.SnowProfileData` (the slab's
layers and the weak layer, nothing below: the column's substratum is the scene's default old snow) and its
:class:`~mpm_warp.scenes.profile.PSTRecord`, or a refusal line naming the row, the column and the value.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass

from ..scenes.profile import ProfileLayer, PSTRecord, SnowProfileData

__all__ = ["table_profiles", "TableRow", "COLUMNS", "REQUIRED"]

COLUMNS = ("id", "outcome", "slope_deg", "column_cm", "cut_cm", "slab_cm", "slab_density", "layers",
           "weak_layer_cm", "weak_layer_density", "w_f", "column_ends")
REQUIRED = ("id", "outcome", "slope_deg", "column_cm", "cut_cm", "weak_layer_cm")


class RowError(ValueError):
    """A row that cannot be read: the message names the row, the column and the value."""


def _number(row: dict, key: str, where: str, required: bool = True) -> float | None:
    text = (row.get(key) or "").strip()
    if not text:
        if required:
            raise RowError(f"{where}: {key} is empty (a number is required)")
        return None
    try:
        v = float(text)
    except ValueError:
        raise RowError(f"{where}: {key} = {text!r} is not a number") from None
    if not math.isfinite(v):
        raise RowError(f"{where}: {key} = {text!r} is not a finite number")
    return v


def _layer(i: int, top: float, th: float, rho: float | None, src: str, name: str = "") -> ProfileLayer:
    return ProfileLayer(index=i, depth_top=top, thickness=th, density=rho, density_source=src, hardness=None,
                        grain_1=name or None, grain_2=None)


def _slab(row: dict, where: str, base: str) -> list[tuple[float, float]]:
    """``(thickness m, density)`` of the slab's layers, top to bottom."""
    path = (row.get("layers") or "").strip()
    if path:
        full = path if os.path.isabs(path) else os.path.join(base, path)
        try:
            with open(full, newline="") as fh:
                rows = list(csv.DictReader(fh))
        except OSError as e:
            raise RowError(f"{where}: layers = {path!r} cannot be read ({e.strerror})") from None
        out = [(_number(r, "thickness_cm", f"{where}: {path} row {k + 2}") / 100.0,
                _number(r, "density", f"{where}: {path} row {k + 2}")) for k, r in enumerate(rows)]
        if not out:
            raise RowError(f"{where}: layers = {path!r} has no layer (columns thickness_cm, density)")
        return out
    return [(_number(row, "slab_cm", where) / 100.0, _number(row, "slab_density", where))]


@dataclass(frozen=True)
class TableRow:
    """One row: its profile and record (None where the row is refused, with ``refusal`` the line), its w_f."""

    id: str
    profile: SnowProfileData | None
    record: PSTRecord | None
    w_f: float | None
    refusal: str | None


def table_profiles(path) -> list[TableRow]:
    """Every row of the CSV ``path`` as a :class:`TableRow`.

    A table without the required columns is refused whole (:class:`ValueError`, one line naming them).
    """
    path = str(path)
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        missing = [c for c in REQUIRED if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{path}: columns {', '.join(missing)} are missing (a field table has "
                             f"{', '.join(COLUMNS)})")
        rows = list(reader)
    base, name = os.path.dirname(os.path.abspath(path)), os.path.basename(path)
    out = []
    for k, row in enumerate(rows):
        rid = (row.get("id") or "").strip() or f"row {k + 2}"
        where = f"{name}: row {k + 2} ({rid})"
        try:
            slab = _slab(row, where, base)
            d_wl = _number(row, "weak_layer_cm", where) / 100.0
            rho_wl = _number(row, "weak_layer_density", where, required=False)
            slope = _number(row, "slope_deg", where)
            column, cut = _number(row, "column_cm", where) / 100.0, _number(row, "cut_cm", where) / 100.0
            w_f = _number(row, "w_f", where, required=False)
        except RowError as e:
            out.append(TableRow(rid, None, None, None, str(e)))
            continue
        layers, top = [], 0.0
        for i, (th, rho) in enumerate(slab):
            layers.append(_layer(i, top, th, rho, "given"))
            top += th
        layers.append(_layer(len(layers), top, d_wl, rho_wl, "given" if rho_wl else "not given", "weak layer"))
        ends = (row.get("column_ends") or "").strip()
        rec = PSTRecord(cut_length=cut, column_length=column, propagation=(row.get("outcome") or "").strip() or None,
                        depth=top, layer_thickness=d_wl, grain_1=None)
        prof = SnowProfileData(layers=tuple(layers), slope_angle=slope, aspect=None, location=rid, date=None,
                               total_depth=top + d_wl, pst_tests=(rec,), source=f"{name}#{rid}", caaml_version="6",
                               country="US" if ends == "vertical" else None)
        out.append(TableRow(rid, prof, rec, w_f, None))
    return out
