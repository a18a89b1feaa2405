"""The reader contract of field tables: what a spreadsheet writes, read, or refused in one line.

:func:`read_csv` reads a field table or its ``layers`` files as a spreadsheet exports them: UTF-8 with or
without a byte-order mark, else Latin-1; comma or semicolon separators (a decimal comma in a semicolon table);
headers matched without regard to case, an unknown one refused naming the nearest known one. A file that cannot
be read at all is a :class:`TableError` (one line). :func:`number` and :func:`choice` read one value against
:data:`RANGES` and the enumerations: the same physical range wherever a quantity appears (slab, layers file,
weak layer), every refusal a line naming the column, the value and what is allowed.
"""

from __future__ import annotations

import csv
import difflib
import io
import re
from dataclasses import dataclass

from ..errors import MPMError
from ..scenes.profile.column import DENSITY_RANGE
from .cases import MAX_COLUMN
from .fracture_energy import PLAUSIBLE

__all__ = ["TableError", "RowError", "Range", "RANGES", "Problems", "read_csv", "number", "choice", "CsvTable"]


class TableError(MPMError, ValueError):
    """A table (or a layers file) that cannot be read at all: the message is one line naming the file and the fix."""


class RowError(ValueError):
    """A row, column or value that cannot be used: the message names the column, the value and what is allowed."""


@dataclass(frozen=True)
class Range:
    """A quantity's physical range: ``lo`` (exclusive when ``open_lo``) to ``hi`` (inclusive), in ``unit``, and why."""

    what: str
    lo: float
    hi: float
    unit: str
    why: str
    open_lo: bool = False

    def holds(self, v: float) -> bool:
        """Whether ``v`` lies in the range."""
        return (v > self.lo if self.open_lo else v >= self.lo) and v <= self.hi

    def text(self) -> str:
        """``a slope in [0, 60] deg (why)``."""
        return f"{self.what} in {'(' if self.open_lo else '['}{self.lo:g}, {self.hi:g}] {self.unit} ({self.why})"


class Problems:
    """The problems of one row, collected so that its one line names every column that cannot be used.

    ``with problems: ...`` records a :class:`RowError` raised inside (without its ``where`` prefix) and goes on;
    :meth:`check` raises them all as one :class:`RowError`.
    """

    def __init__(self, where: str):
        self.where = where
        self.found: list[str] = []

    def __enter__(self):
        return self

    def __exit__(self, kind, err, tb) -> bool:
        if isinstance(err, RowError):
            self.found.append(str(err).removeprefix(self.where + ": "))
            return True
        return False

    def check(self) -> None:
        """Raise the problems found, if any, as one line: ``where: problem; problem``."""
        if self.found:
            raise RowError(f"{self.where}: {'; '.join(self.found)}")


_RHO = Range("a density", *DENSITY_RANGE, "kg/m^3",
             "seasonal dry snow: the model derives the snow's stiffness and strength from its density by laws of "
             "settled snow, which lighter new snow and denser firn lie outside")
_THICK = Range("a thickness", 0.0, 500.0, "cm", "a layer of a snowpack, up to 5 m", open_lo=True)
#: every number a field table or its layers files may hold, by column: the same quantity, the same range
RANGES = {
    "slope_deg": Range("a slope", 0.0, 60.0, "deg", "the model takes slopes of 0-60 deg"),
    "column_cm": Range("a column length", 0.0, MAX_COLUMN * 100.0, "cm",
                       f"a PST column is 1-2 m, an extended column up to {MAX_COLUMN:g} m", open_lo=True),
    "cut_cm": Range("a cut", 0.0, MAX_COLUMN * 100.0, "cm",
                    "the recorded critical cut: a PST without a cut has nothing to compare with", open_lo=True),
    "slab_cm": _THICK,
    "thickness_cm": _THICK,
    "slab_density": _RHO,
    "density": _RHO,
    "weak_layer_density": _RHO,
    "weak_layer_cm": Range("a weak-layer thickness", 0.0, 30.0, "cm",
                           "the model's weak layer may be at most twice as thick as the 15 cm of old snow it rests "
                           "on, and a thicker profile layer says where the failure lies, not how thick it is: weac "
                           "takes 3 cm",
                           open_lo=True),
    "w_f": Range("a fracture energy", *PLAUSIBLE, "J/m^2",
                 "the range measured on weak layers, widened tenfold each way: leave it blank to read it back "
                 "from the cut"),
}

_NUMBER = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")


def number(row: dict, key: str, where: str, *, required: bool = True, decimal_comma: bool = False,
           measured: bool = False) -> float | None:
    """The value of ``row[key]`` checked against ``RANGES[key]``; None when blank and not ``required``.

    Raises
    ------
    RowError
        Blank where required, not a number, or outside its range: one line naming ``where``, the column, the value
        and the range (a density out of range is said to be ``measured`` where it was).
    """
    text = (row.get(key) or "").strip()
    rng = RANGES[key]
    if not text:
        if required:
            raise RowError(f"{where}: {key} is empty (required: {rng.text()})")
        return None
    shown = text.replace(",", ".") if decimal_comma else text
    if not _NUMBER.match(shown):
        hint = " (a decimal comma? use a point, or semicolons between columns)" if "," in text else ""
        raise RowError(f"{where}: {key} = {text!r} is not a number{hint}: expected {rng.text()}")
    v = float(shown)
    if not rng.holds(v):                # a finite number: the pattern has no nan, no inf
        how = " (measured)" if measured else ""
        raise RowError(f"{where}: {key} = {text} {rng.unit}{how} is outside the range: expected {rng.text()}")
    return v


def choice(row: dict, key: str, where: str, allowed: dict[str, str], default: str | None = None) -> str:
    """The value of ``row[key]`` as one of ``allowed`` (``{spelling, lower case: canonical}``), matched without
    regard to case; ``default`` when blank (a :class:`RowError` when blank without one, or not one of them)."""
    text = (row.get(key) or "").strip()
    names = ", ".join(dict.fromkeys(allowed.values()))
    if not text:
        if default is None:
            raise RowError(f"{where}: {key} is empty (required: one of {names})")
        return default
    got = allowed.get(re.sub(r"[\s_-]+", " ", text.lower()))
    if got is None:
        raise RowError(f"{where}: {key} = {text!r} is not one of {names} (read without regard to case)")
    return got


@dataclass
class CsvTable:
    """A CSV file read by :func:`read_csv`: its header (known names, lower case) and its rows, read lazily."""

    path: str
    name: str
    fields: list[str]
    separator: str
    encoding: str
    text: str
    first_line: int = 1

    @property
    def decimal_comma(self) -> bool:
        """A semicolon table may write its numbers with a decimal comma."""
        return self.separator == ";"

    def rows(self):
        """``(line, {column: text})`` of every row after the header, in order (``line``: the file's line, from 1;
        a row with more values than columns gets the extra values under ``None``)."""
        reader = csv.reader(io.StringIO(self.text), delimiter=self.separator)
        next(reader, None)
        n = len(self.fields)
        while True:
            line = reader.line_num + self.first_line
            values = next(reader, None)
            if values is None:
                return
            if not any(v.strip() for v in values):
                continue
            row = dict(zip(self.fields, values, strict=False))
            extra = [v for h, v in zip(self.fields, values, strict=False) if not h and v.strip()] + values[n:]
            row.pop("", None)
            if any(v.strip() for v in extra):       # values under no column: a decimal comma, an unquoted comma
                row[None] = extra
            yield line, row


def _decode(path: str, name: str) -> tuple[str, str]:
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as e:
        raise TableError(f"{name}: cannot be read ({e.strerror})") from None
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")) or b"\x00" in raw[:4096]:
        raise TableError(f"{name}: is UTF-16 or binary, not a CSV table: save it as 'CSV UTF-8' or 'CSV' (comma or "
                         "semicolon separated)")
    try:
        return raw.decode("utf-8-sig"), "utf-8"
    except UnicodeDecodeError:
        return raw.decode("latin-1"), "latin-1"


def read_csv(path: str, name: str, known: tuple[str, ...], required: tuple[str, ...]) -> CsvTable:
    """The CSV file ``path`` (called ``name`` in messages) with the columns ``known``, of which ``required`` must be
    there (module docstring).

    Raises
    ------
    TableError
        The file cannot be read, is empty, is not comma or semicolon separated, or has an unknown, repeated or
        missing column: one line naming the file and the fix.
    """
    text, enc = _decode(path, name)
    first = next((ln for ln in text.splitlines() if ln.strip()), "")
    if not first:
        raise TableError(f"{name}: the file is empty (a header line is required: {', '.join(known)})")
    counts = {sep: len(next(csv.reader([first], delimiter=sep))) for sep in (",", ";")}
    if max(counts.values()) == 1 and "\t" in first:
        raise TableError(f"{name}: the columns are separated by tabs: save the table as CSV, with commas or "
                         "semicolons between columns")
    sep = ";" if counts[";"] > counts[","] else ","
    header = [h.strip().lower() for h in next(csv.reader([first], delimiter=sep))]
    for h in header:
        if h and h not in known:          # an unnamed column (a spreadsheet's trailing separator) holds nothing
            near = difflib.get_close_matches(h, known, n=1, cutoff=0.6)
            hint = f"did you mean {near[0]!r}?" if near else f"the columns are {', '.join(known)}"
            raise TableError(f"{name}: unknown column {h!r}: {hint}")
    repeated = sorted({h for h in header if h and header.count(h) > 1})
    if repeated:
        raise TableError(f"{name}: the column {repeated[0]!r} appears {header.count(repeated[0])} times")
    missing = [c for c in required if c not in header]
    if missing:
        raise TableError(f"{name}: {'column' if len(missing) == 1 else 'columns'} {', '.join(missing)} "
                         f"{'is' if len(missing) == 1 else 'are'} missing (required: {', '.join(required)})")
    start = text.index(first)
    return CsvTable(path, name, header, sep, enc, text[start:], text[:start].count("\n") + 1)
