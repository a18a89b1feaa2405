"""A table of field PSTs (CSV) as profiles and records, so that published tables run like CAAML pits.

One row is one PST. Columns (header names carry their units; blank = not given):

==================== ===================================================================================
``id``               a name for the test (required)
``outcome``          End, SF or Arr (required; any case)
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
``column_ends``      ``vertical`` or ``slope_normal`` / ``slope-normal`` (optional, any case; blank: slope_normal)
``notes``            free text (optional; not read)
==================== ===================================================================================

The file is read as :mod:`.table_read` says (encodings, separators, headers); every number is checked
against its range in :data:`~.table_read.RANGES`, the same wherever the quantity appears.

:func:`iter_table` turns each row, one at a time (a large table starts at once), into a
:class:`~mpm_warp.scenes.profile.SnowProfileData` (the slab's layers and the weak layer, nothing below: the
column's substratum is the scene's default old snow) and its :class:`~mpm_warp.scenes.profile.PSTRecord`, or a
refusal line naming the row and every column that cannot be used, with its value and its range.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from ..scenes.profile import ProfileLayer, PSTRecord, SnowProfileData
from ..scenes.profile.records import MEASURED
from .table_read import Problems, RowError, TableError, choice, number, read_csv

__all__ = ["table_profiles", "iter_table", "TableRow", "TableError", "COLUMNS", "REQUIRED", "LAYER_COLUMNS"]

COLUMNS = ("id", "outcome", "slope_deg", "column_cm", "cut_cm", "slab_cm", "slab_density", "layers",
           "weak_layer_cm", "weak_layer_density", "w_f", "column_ends", "notes")
REQUIRED = ("id", "outcome", "slope_deg", "column_cm", "cut_cm", "weak_layer_cm")
#: the columns of a ``layers`` file: a layer's thickness and density (required), free text (optional; not read)
LAYER_COLUMNS = ("thickness_cm", "density", "notes")
#: the outcomes a row may give (any case), as the observer's standard writes them
OUTCOME_NAMES = {"end": "End", "sf": "SF", "arr": "Arr"}
#: the column ends a row may give (any case; a hyphen, underscore or space between words)
ENDS_NAMES = {"vertical": "vertical", "slope normal": "slope_normal"}


def _layer(i: int, top: float, th: float, rho: float | None, src: str, name: str = "") -> ProfileLayer:
    return ProfileLayer(index=i, depth_top=top, thickness=th, density=rho, density_source=src, hardness=None,
                        grain_1=name or None, grain_2=None)


def _extra(row: dict, where: str, n: int) -> None:
    if row.get(None):
        raise RowError(f"{where}: {len(row[None])} value(s) beyond the {n} columns ({', '.join(row[None])}): a "
                       "decimal comma in a comma-separated table? quote it, write a point, or use semicolons")


def _layers_file(path: str, where: str, base: str) -> list[tuple[float, float]]:
    """``(thickness m, density)`` of a ``layers`` file's layers, top to bottom."""
    full = path if os.path.isabs(path) else os.path.join(base, path)
    try:
        table = read_csv(full, path, LAYER_COLUMNS, LAYER_COLUMNS[:2])
    except TableError as e:
        raise RowError(f"{where}: layers file {e}") from None
    out, bad = [], Problems(where)
    for line, r in table.rows():
        at = f"{where}: {path} row {line}"
        th = rho = None
        with bad:
            _extra(r, at, len(table.fields))
        with bad:
            th = number(r, "thickness_cm", at, decimal_comma=table.decimal_comma)
        with bad:
            rho = number(r, "density", at, decimal_comma=table.decimal_comma, measured=True)
        if th is not None and rho is not None:
            out.append((th / 100.0, rho))
    bad.check()
    if not out:
        raise RowError(f"{where}: layers = {path!r} has no layer (a row each: thickness_cm, density)")
    return out


def _slab(row: dict, where: str, base: str, comma: bool) -> list[tuple[float, float]]:
    """``(thickness m, density)`` of the slab's layers, top to bottom."""
    path = (row.get("layers") or "").strip()
    if path:
        return _layers_file(path, where, base)
    if not (row.get("slab_cm") or "").strip() and not (row.get("slab_density") or "").strip():
        raise RowError(f"{where}: no slab: give slab_cm and slab_density, or a layers file")
    return [(number(row, "slab_cm", where, decimal_comma=comma) / 100.0,
             number(row, "slab_density", where, decimal_comma=comma, measured=True))]


@dataclass(frozen=True)
class TableRow:
    """One row: its profile and record (None where the row is refused), its w_f; ``where`` names the row
    (``table.csv: row 4 (id)``), ``line`` is its line in the file, ``problem`` says why it is refused (None where it
    is not) and ``observed`` is the outcome as written."""

    id: str
    profile: SnowProfileData | None
    record: PSTRecord | None
    w_f: float | None
    where: str
    problem: str | None = None
    line: int = 0
    observed: str | None = None

    @property
    def refusal(self) -> str | None:
        """The refusal line, ``table.csv: row 4 (id): problem``; None where the row is read."""
        return None if self.problem is None else f"{self.where}: {self.problem}"


def _row(row: dict, rid: str, where: str, name: str, base: str, comma: bool, line: int, n: int) -> TableRow:
    bad, got = Problems(where), {}

    def num(key, required=True, measured=False, scale=1.0):
        with bad:
            v = number(row, key, where, required=required, decimal_comma=comma, measured=measured)
            got[key] = None if v is None else v * scale

    with bad:
        _extra(row, where, n)
    with bad:
        got["outcome"] = choice(row, "outcome", where, OUTCOME_NAMES)
    with bad:
        got["slab"] = _slab(row, where, base, comma)
    for key in ("weak_layer_cm", "column_cm", "cut_cm"):
        num(key, scale=0.01)
    num("weak_layer_density", required=False, measured=True)
    num("slope_deg")
    num("w_f", required=False)
    with bad:
        got["ends"] = choice(row, "column_ends", where, ENDS_NAMES, default="slope_normal")
    bad.check()
    slab, d_wl, rho_wl, slope = got["slab"], got["weak_layer_cm"], got["weak_layer_density"], got["slope_deg"]
    column, cut, w_f, outcome, ends = got["column_cm"], got["cut_cm"], got["w_f"], got["outcome"], got["ends"]
    layers, top = [], 0.0
    for i, (th, rho) in enumerate(slab):
        layers.append(_layer(i, top, th, rho, MEASURED))
        top += th
    layers.append(_layer(len(layers), top, d_wl, rho_wl, MEASURED if rho_wl else "not given", "weak layer"))
    rec = PSTRecord(cut_length=cut, column_length=column, propagation=outcome, depth=top, layer_thickness=d_wl,
                    grain_1=None)
    prof = SnowProfileData(layers=tuple(layers), slope_angle=slope, aspect=None, location=rid, date=None,
                           total_depth=top + d_wl, pst_tests=(rec,), source=f"{name}#{rid}", caaml_version="6",
                           country="US" if ends == "vertical" else None)
    return TableRow(rid, prof, rec, w_f, where, None, line, outcome)


def iter_table(path):
    """Every row of the CSV table ``path`` as a :class:`TableRow`, one at a time (a row is set up only when asked
    for).

    Raises
    ------
    TableError
        A table that cannot be read at all (:func:`~.table_read.read_csv`), before any row.
    """
    path = os.fspath(path)
    base, name = os.path.dirname(os.path.abspath(path)), os.path.basename(path)
    table = read_csv(path, name, COLUMNS, REQUIRED)

    def rows():
        for line, row in table.rows():
            rid = (row.get("id") or "").strip() or f"row {line}"
            where = f"{name}: row {line} ({rid})"
            try:
                yield _row(row, rid, where, name, base, table.decimal_comma, line, len(table.fields))
            except RowError as e:
                yield TableRow(rid, None, None, None, where, str(e).removeprefix(where + ": "), line,
                               (row.get("outcome") or "").strip() or None)

    return rows()


def table_profiles(path) -> list[TableRow]:
    """Every row of the CSV ``path`` as a :class:`TableRow` (:func:`iter_table`, all at once)."""
    return list(iter_table(path))
