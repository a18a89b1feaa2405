"""Field tables as users write them (issue 56): each hostile input ends in one line naming the row, the column, the
value and the allowed range, or is read correctly; never a traceback, never a silent default. Nothing here runs
the MPM: the rows are refused, or read and refused by the field rules (a cut as long as the column), or only set up.
"""

from __future__ import annotations

import os
import shutil
import time

import pytest

from mpm_warp.cli import main
from mpm_warp.field import batch_setup
from mpm_warp.field.batch import _case_id, _finished, finished_records, gather, run_field, run_records
from mpm_warp.field.batch_setup import DASK_LOG, dask_log
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.table import table_profiles
from mpm_warp.field.table_read import RANGES, TableError

HEADER = ("id", "outcome", "slope_deg", "column_cm", "cut_cm", "slab_cm", "slab_density", "weak_layer_cm",
          "weak_layer_density", "w_f", "column_ends")
#: a row every field rule reads and then refuses without building anything: its cut is the whole column
READ = {"id": "p1", "outcome": "End", "slope_deg": "30", "column_cm": "150", "cut_cm": "150", "slab_cm": "40",
        "slab_density": "200", "weak_layer_cm": "3", "weak_layer_density": "", "w_f": "", "column_ends": ""}
#: what the line of a row read whole says (its record's field line, then the field rule that refuses it)
READ_LINE = "PST 150/150 (End) down 40 cm: the cut is 100% of the column"
#: a row that runs (the smallest column of tests/test_field_batch.py)
RUNS = "tiny-a,End,0,40,12,15,180,4,,0.3,"
PITS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "snowpilot")


def table(sep: str = ",", header=HEADER, **change) -> str:
    """One header and one row: :data:`READ` with ``change``; a value None drops the column."""
    row = {**READ, **change}
    cols = [h for h in header if row.get(h) is not None]
    return sep.join(cols) + "\n" + sep.join(row[h] for h in cols) + "\n"


LAYERS = {**READ, "slab_cm": None, "slab_density": None, "layers": "slab.csv"}
HEADER_LAYERS = (*HEADER[:5], "layers", *HEADER[7:])
DENSITY_RANGE = f"expected {RANGES['density'].text()}"


def layered(slab) -> dict:
    """A table whose row's slab is the layers file ``slab.csv`` holding ``slab``."""
    return {"t.csv": table(header=HEADER_LAYERS, **LAYERS), "slab.csv": slab}


#: (case, files {name: text or bytes}, extra arguments, exit status, words of its line, words it must not hold)
CASES = [
    ("missing-column", {"t.csv": table(cut_cm=None)}, [], 2, ["t.csv: column cut_cm is missing"], []),
    ("empty-file", {"t.csv": ""}, [], 2, ["t.csv: the file is empty"], []),
    ("byte-order-mark", {"t.csv": b"\xef\xbb\xbf" + table(id="bom").encode()}, [], 0,
     [f"refused t.csv#bom: {READ_LINE}"], ["missing"]),
    ("semicolons-decimal-comma", {"t.csv": table(";", id="semi", slab_cm="40,0")}, [], 0,
     [f"refused t.csv#semi: {READ_LINE}"], []),
    ("tabs", {"t.csv": table("\t")}, [], 2, ["t.csv: the columns are separated by tabs", "commas or semicolons"],
     []),
    ("utf-16", {"t.csv": table().encode("utf-16")}, [], 2, ["t.csv: is UTF-16 or binary", "'CSV UTF-8'"], []),
    ("latin-1-table", {"t.csv": table(id="Bérard").encode("latin-1")}, [], 0, [f"refused t.csv#Bérard: {READ_LINE}"],
     []),
    ("latin-1-layers", {"t.csv": table(header=HEADER_LAYERS, **LAYERS),
                        "slab.csv": "thickness_cm,density,notes\n40,200,gros grains à facettes\n".encode("latin-1")},
     [], 0, [f"refused t.csv#p1: {READ_LINE}"], []),
    ("utf-16-layers-refuses-its-row-only",
     {"t.csv": table(header=HEADER_LAYERS, **LAYERS) + "p2,End,30,150,150,,3,,,\n",
      "slab.csv": "thickness_cm,density\n40,200\n".encode("utf-16")}, [], 0,
     ["refused t.csv#p1: row 2: layers file slab.csv: is UTF-16 or binary"], []),
    ("scheduler-not-an-address", {"t.csv": table()}, ["--scheduler", "notanaddress"], 2,
     ["scheduler = 'notanaddress' is invalid", "tcp://host:8786", "missing port number"], []),
    ("device-not-here", {"t.csv": table()}, ["--device", "cuda:7"], 2, ["device = 'cuda:7' is invalid"], []),
    ("negative-layer", layered("thickness_cm,density\n-5,200\n"), [], 0,
     ["refused t.csv#p1: row 2: slab.csv row 2: thickness_cm = -5 cm is outside the range",
      "expected a thickness in (0, 500] cm"], []),
    ("weak-layer-density-5000", {"t.csv": table(weak_layer_density="5000")}, [], 0,
     ["refused t.csv#p1: row 2: weak_layer_density = 5000 kg/m^3", DENSITY_RANGE], ["150"]),
    ("slab-density-5000", {"t.csv": table(slab_density="5000")}, [], 0,
     ["refused t.csv#p1: row 2: slab_density = 5000 kg/m^3", DENSITY_RANGE], []),
    ("layers-density-5000", layered("thickness_cm,density\n40,5000\n"), [], 0,
     ["slab.csv row 2: density = 5000 kg/m^3", DENSITY_RANGE], []),
    ("misspelt-header", {"t.csv": table(header=(*HEADER[:-1], "colum_ends"), colum_ends="vertical")}, [], 2,
     ["t.csv: unknown column 'colum_ends': did you mean 'column_ends'?"], []),
    ("column-ends-unknown", {"t.csv": table(column_ends="sideways")}, [], 0,
     ["refused t.csv#p1: row 2: column_ends = 'sideways' is not one of vertical, slope_normal"], []),
    ("outcome-unknown", {"t.csv": table(outcome="maybe")}, [], 0,
     ["refused t.csv#p1: row 2: outcome = 'maybe' is not one of End, SF, Arr"], []),
    ("id-with-a-slash", {"t.csv": table(id="a/b")}, [], 0, [f"refused t.csv#a/b: {READ_LINE}"], []),
    ("column-length-negative", {"t.csv": table(column_cm="-60", cut_cm="12")}, [], 0,
     ["refused t.csv#p1: row 2: column_cm = -60 cm is outside the range", "expected a column length in (0, 1000] cm"],
     ["no column length recorded"]),
    ("cut-negative", {"t.csv": table(cut_cm="-5")}, [], 0,
     ["refused t.csv#p1: row 2: cut_cm = -5 cm is outside the range", "expected a cut in (0, 1000] cm"],
     ["a cut of 0 cm"]),
    ("weak-layer-0", {"t.csv": table(weak_layer_cm="0")}, [], 0,
     ["refused t.csv#p1: row 2: weak_layer_cm = 0 cm is outside the range",
      "expected a weak-layer thickness in (0, 30] cm"], ["not described"]),
    ("weak-layer-negative", {"t.csv": table(weak_layer_cm="-3")}, [], 0,
     ["refused t.csv#p1: row 2: weak_layer_cm = -3 cm is outside the range"], ["not described"]),
    ("weak-layer-200-cm", {"t.csv": table(weak_layer_cm="200")}, [], 0,
     ["refused t.csv#p1: row 2: weak_layer_cm = 200 cm is outside the range", "(0, 30] cm"],
     ["substratum", "0.15"]),
    ("w_f-0", {"t.csv": table(w_f="0")}, [], 0,
     ["refused t.csv#p1: row 2: w_f = 0 J/m^2 is outside the range", "expected a fracture energy in [0.01, 10] J/m^2",
      "leave it blank to read it back from the cut"], ["exactly one of"]),
    ("measured-39", layered("thickness_cm,density\n30,39\n10,200\n"), [], 0,
     ["slab.csv row 2: density = 39 kg/m^3 (measured) is outside the range", DENSITY_RANGE,
             "seasonal dry snow"], ["estimated"]),
    ("every-bad-column-of-a-row", {"t.csv": table(column_cm="-60", cut_cm="-5", weak_layer_cm="-3")}, [], 0,
     ["weak_layer_cm = -3 cm", "column_cm = -60 cm", "cut_cm = -5 cm"], []),
    ("a-decimal-comma-in-a-comma-table", {"t.csv": table(header=HEADER[:-1], w_f="0,3")}, [], 0,
     ["refused t.csv#p1: row 2: 1 value(s) beyond the 10 columns (3): a decimal comma", "w_f = 0 J/m^2"], []),
    ("quoted-decimal-comma-in-a-comma-table", {"t.csv": table(w_f='"0,3"')}, [], 0,
     ["refused t.csv#p1: row 2: w_f = '0,3' is not a number (a decimal comma? use a point"], []),
    ("not-a-number", {"t.csv": table(slope_deg="nan", slab_cm="40 cm")}, [], 0,
     ["refused t.csv#p1: row 2: slab_cm = '40 cm' is not a number: expected a thickness in (0, 500] cm",
      "slope_deg = 'nan' is not a number"], []),
    ("out-unwritable", {"t.csv": table()}, ["--out", "t.csv/out"], 2,
     ["out = ", "is invalid: expected a folder this user can create and write in"], []),
]


def _write(tmp_path, files):
    for name, text in files.items():
        (tmp_path / name).write_bytes(text if isinstance(text, bytes) else text.encode())


@pytest.mark.parametrize("files, args, status, words, absent",
                         [pytest.param(*c[1:], id=c[0]) for c in CASES])
def test_a_hostile_table_is_one_line_or_read(tmp_path, capsys, files, args, status, words, absent):
    _write(tmp_path, files)
    out = ["--out", str(tmp_path / "run")] if "--out" not in args else []
    args = [str(tmp_path / a) if a.startswith("t.csv") else a for a in args]
    assert main(["field", str(tmp_path / "t.csv"), *out, *args, "--quiet"]) == status
    so, err = capsys.readouterr()
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if words[0] in ln]
    assert len(lines) == 1, err
    for w in words:
        assert w in lines[0], f"{w!r} not in {lines[0]!r}"
    for w in absent:
        assert w not in lines[0], f"{w!r} in {lines[0]!r}"
    if status == 2:
        assert err.count("\n") == 1 and so == "" and lines[0].startswith("mpm-warp: error: ")
    else:
        with open(tmp_path / "run" / "refused.csv", encoding="utf-8") as fh:
            assert words[0].removeprefix("refused ").split(": ", 1)[0] in fh.read()


def test_what_a_table_means_is_read_without_regard_to_case_and_spreadsheet_habits(tmp_path):
    """Enumerated values in any case, a decimal comma in a semicolon table, a trailing separator: read, not
    defaulted; a blank column_ends is the documented default."""
    path = tmp_path / "t.csv"
    path.write_text("id;outcome;slope_deg;column_cm;cut_cm;slab_cm;slab_density;weak_layer_cm;column_ends;\n"
                    "a;END;30;150;12;40,5;200;3;Vertical;\n"
                    "\n"
                    "b;sf;30;150;12;40;200;3;SLOPE-NORMAL;\n"
                    "c;arr;30;150;12;40;200;3;slope_normal;\n"
                    "d;End;30;150;12;40;200;3;;\n")
    a, b, c, d = table_profiles(path)
    assert [r.problem for r in (a, b, c, d)] == [None] * 4
    assert [r.record.propagation for r in (a, b, c, d)] == ["End", "SF", "Arr", "End"]
    assert [r.profile.country for r in (a, b, c, d)] == ["US", None, None, None]    # vertical ends; slope-normal
    assert a.profile.layers[0].thickness == pytest.approx(0.405) and a.profile.layers[0].measured
    assert (a.line, b.line, b.where) == (2, 4, "t.csv: row 4 (b)")                 # the file's own line numbers


def test_a_folder_of_upper_case_xml_pits_is_read(tmp_path, capsys):
    pits = tmp_path / "pits"
    pits.mkdir()
    shutil.copy(os.path.join(PITS, "snowpits-18264-caaml.xml"), pits / "snowpits-18264-caaml.XML")
    # its other PST (a 0.7 cm weak layer) now runs with an equivalent layer: a budget too small even for that
    # keeps the test to the reading (both records refused, nothing run)
    assert main(["field", str(pits), "--out", str(tmp_path / "run"), "--quiet", "--max-particles", "1000"]) == 0
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "2 records refused" in out           # its two PSTs
    assert "no equivalent weak layer fits either" in err
    assert "refused snowpits-18264-caaml.XML: PST 100/100 (End) down 51 cm: the cut is 100% of the column" in err


def test_an_id_with_a_slash_keeps_it_and_its_file_stays_in_the_folder(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text(",".join(HEADER) + "\n" + RUNS.replace("tiny-a", "a/b") + "\n")
    (case,), refused = gather([str(path)], calibrate=False)
    assert refused == [] and case.pit == "t.csv#a/b"                  # the pit cases.csv says
    cid = _case_id(case, 0, FieldProtocol())
    assert cid.startswith("t.csv-a_b-0-") and os.sep not in cid


def test_a_case_file_replaced_by_an_empty_list_is_run_again(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text(",".join(HEADER) + "\n" + RUNS + "\n")
    cases, _ = gather([str(path)], calibrate=False)
    task = {"out_dir": str(tmp_path), "id": _case_id(cases[0], 0, FieldProtocol())}
    (tmp_path / (task["id"] + ".json")).write_text("[]")
    assert _finished(task) is None and finished_records(cases, str(tmp_path)) == []
    assert run_records([str(tmp_path)]) == []


def _counted(monkeypatch):
    calls = []
    real = batch_setup.field_case

    def field_case(*a, **kw):
        calls.append(a[0].source)
        return real(*a, **kw)

    monkeypatch.setattr(batch_setup, "field_case", field_case)
    return calls


def test_limit_counts_runnable_rows_and_sets_up_no_more(tmp_path, monkeypatch):
    """A refused first row does not use up --limit 1: the runnable row after it is the one set up."""
    path = tmp_path / "t.csv"
    path.write_text(",".join(HEADER) + "\n" + RUNS.replace("tiny-a,End,0", "steep,End,70") + "\n" +
                    RUNS.replace("tiny-a,End,0,40,12", "sawn,End,0,40,40") + "\n" +
                    RUNS + "\n" + RUNS.replace("tiny-a", "tiny-b") + "\n")
    calls = _counted(monkeypatch)
    cases, refused = gather([str(path)], calibrate=False, limit=1)
    assert [c.pit for c in cases] == ["t.csv#tiny-a"] and calls == ["t.csv#sawn", "t.csv#tiny-a"]
    assert [(r.pit, r.test) for r in refused] == [("t.csv#steep", "row 2"),
                                                  ("t.csv#sawn", "PST 40/40 (End) down 15 cm")]
    assert refused[0].message.startswith("slope_deg = 70 deg is outside the range: expected a slope in [0, 60] deg")


@pytest.mark.parametrize("limit", [1, None])
def test_a_100000_row_table_starts_its_first_case_at_once(tmp_path, monkeypatch, limit):
    """On 100,000 rows, with --limit 1 or without, the first case goes to Dask once its own row is set up: one
    setup, well within 10 s (the rows after it are set up while it runs)."""
    from mpm_warp.field import batch

    path = tmp_path / "big.csv"
    path.write_text(",".join(HEADER) + "\n" + "\n".join([RUNS] * 100_000) + "\n")
    calls, handed = _counted(monkeypatch), []

    def first_only(todo, records, *a):      # as _execute takes its first task, without a cluster
        t = next(todo)
        handed.append((time.perf_counter() - t0, len(calls), t))
        records[t["id"]] = {"id": t["id"], "status": "failed", "error": "not run here"}

    monkeypatch.setattr(batch, "_execute", first_only)
    t0 = time.perf_counter()
    res = run_field([str(path)], str(tmp_path / "run"), limit=limit, progress=False)
    ((elapsed, setups, task),) = handed
    assert elapsed < 10.0 and setups == 1 and task["pit"] == "big.csv#tiny-a" and task["id"].startswith("big-0-")
    assert [r["id"] for r in res.records] == [task["id"]] and res.refused == []


def test_dask_logs_go_to_a_file_unless_verbose(tmp_path, capfd):
    with dask_log(str(tmp_path), verbose=False) as terminal:
        os.write(2, b"distributed.worker - WARNING - a worker's noise\n")     # as a worker process writes it
        terminal.write("field: 1/1 cases\n")
    _, err = capfd.readouterr()
    assert "noise" not in err and "field: 1/1 cases" in err
    assert "a worker's noise" in (tmp_path / DASK_LOG).read_text()
    with dask_log(str(tmp_path), verbose=True):
        os.write(2, b"loud\n")
    assert "loud" in capfd.readouterr().err


def test_a_table_that_cannot_be_read_is_a_table_error(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text(table(header=(*HEADER, "id")))
    with pytest.raises(TableError, match="t.csv: the column 'id' appears 2 times"):
        table_profiles(path)
    path.write_text(table(header=(*HEADER, "whatever"), whatever="x"))
    with pytest.raises(TableError, match="unknown column 'whatever': the columns are id, outcome"):
        table_profiles(path)


def test_the_documented_ranges_are_the_readers():
    """docs/field.md's table of columns gives every range the reader checks, as the reader writes it."""
    with open(os.path.join(os.path.dirname(PITS), "..", "..", "docs", "field.md"), encoding="utf-8") as fh:
        rows = [ln for ln in fh.read().splitlines() if ln.startswith("| `")]
    for key, rng in RANGES.items():
        col = "layers" if key in ("thickness_cm", "density") else key
        (line,) = [ln for ln in rows if f"`{col}`" in ln.split("|")[1]]
        assert f"{'(' if rng.open_lo else '['}{rng.lo:g}, {rng.hi:g}] {rng.unit}" in line, (key, line)
