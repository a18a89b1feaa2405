"""Cases drawn from committed field batches and set up again from their pits, as their batch set them up.

A study draws finished batch rows per observed class (:func:`draw_rows`) or takes every scored row
(:func:`scored_cases`), and sets each up again from its pit (:func:`batch_cases`): a case matches when its id's
digest is that of the parameters and protocol it gets now, so a study reruns the batch's own column.
:func:`add_draw_arguments` gives a script those choices; :func:`aligned_records` reads a rerun's records back in
the drawn order.
"""

from __future__ import annotations

import json
import os
import sys

from ..batch import case_digest, gather
from ..cases import FieldCase
from ..draw import sample_per_class
from ..protocol import FieldProtocol

__all__ = ["BATCH_FILES", "committed_batches", "pit_file", "matched_cases", "batch_cases", "scored_cases",
           "draw_rows", "add_data_arguments", "add_draw_arguments", "aligned_records"]

#: the committed development-set batches, under ``benchmarks/field/results/``
BATCH_FILES = ("field_batch.json", os.path.join("measured", "field_batch.json"))


def committed_batches(results: str) -> list[str]:
    """The committed batches' JSONs in the results folder ``results``."""
    return [os.path.join(results, f) for f in BATCH_FILES]


def _ok_rows(batches: list[str], keep=lambda row: True) -> list[dict]:
    """The finished rows (``status`` ok) of the batches' JSONs that ``keep`` keeps, one a case id, by id."""
    rows = {}
    for b in batches:
        with open(b) as fh:
            for c in json.load(fh)["cases"]:
                if c.get("status") == "ok" and keep(c):
                    rows[c["id"]] = c
    return sorted(rows.values(), key=lambda c: c["id"])


def pit_file(case_id: str) -> str:
    """The pit's file name of a batch case id (``<pit stem>-<k>-<digest>``)."""
    return case_id.rsplit("-", 2)[0] + ".xml"


def matched_cases(data: str, ids: list[str], proto: FieldProtocol) -> tuple[list, list[str]]:
    """The cases of ``ids`` set up again from their pits in ``data``, in the order of ``ids``: a case matches
    when its key's digest under ``proto`` is the id's (same parameters, same protocol). Returns the cases and
    the ids that found none."""
    files = sorted({os.path.join(data, pit_file(i)) for i in ids})
    cases, _ = gather(files)
    by_digest = {case_digest(c, proto): c for c in cases}
    found = [by_digest.get(i.rsplit("-", 1)[1]) for i in ids]
    return [c for c in found if c is not None], [i for i, c in zip(ids, found, strict=True) if c is None]


def batch_cases(data: str, rows: list[dict], proto: FieldProtocol) -> list | None:
    """:func:`matched_cases` of the batch ``rows``; None, said in one line on stderr, when one is not set up as its
    batch set it up."""
    cases, missing = matched_cases(data, [c["id"] for c in rows], proto)
    if missing:
        print(f"error: data: {len(missing)} cases are not set up as their batch set them up (e.g. {missing[0]})",
              file=sys.stderr)
        return None
    return cases


def scored_cases(batches: list[str], data: str, limit: int | None = None) -> tuple[list[dict], list] | None:
    """Every case the batches scored (their rows, by id; the first ``limit``), and each set up again from its pit in
    ``data`` as its batch set it up (same order); None, said on stderr, when one is not set up as its batch set it
    up."""
    chosen = _ok_rows(batches)[:limit]
    cases = batch_cases(data, chosen, FieldProtocol().validate())
    return None if cases is None else (chosen, cases)


def draw_rows(batches: list[str], per_class: int, seed: int, max_wall: float) -> tuple[list[dict], int]:
    """``per_class`` finished rows of each observed class (END, SF, ARR in turn), at random (``seed``), among the
    batches' cases whose run took at most ``max_wall`` s; and the size of that pool."""
    pool = _ok_rows(batches, lambda c: c.get("wall_s") is not None and c["wall_s"] <= max_wall)
    return [c for of in sample_per_class(pool, per_class, seed, lambda c: c["observed"]) for c in of], len(pool)


def add_data_arguments(p, results: str) -> None:
    """The arguments of a study of the committed batches' cases set up again: the pits' folder and the batches
    (default those in ``results``)."""
    p.add_argument("data", help="folder of CAAML files (the unpacked development set)")
    p.add_argument("--batches", nargs="+", default=committed_batches(results),
                   help="field_batch.py JSONs (default: both committed)")


def add_draw_arguments(p, runs: str, per_class: int, results: str) -> None:
    """The arguments of a study that draws cases per observed class from the committed batches in ``results`` and
    runs them: the data (:func:`add_data_arguments`), the runs folder (``runs`` says which runs), the draw and the
    Dask batch."""
    add_data_arguments(p, results)
    p.add_argument("--runs", help=f"folder of the runs {runs} (kept: a rerun resumes); default temporary")
    p.add_argument("--per-class", type=int, default=per_class,
                   help=f"cases to draw per observed class (default {per_class})")
    p.add_argument("--seed", type=int, default=0, help="seed of the draw (default 0)")
    p.add_argument("--max-wall", type=float, default=120.0,
                   help="draw among the cases whose batch run took at most this long (s, default 120)")
    p.add_argument("--workers", type=int, default=None, help="Dask workers (default one per core)")
    p.add_argument("--threads", type=int, default=FieldProtocol.threads, help="CPU threads of each case (default 1)")


def aligned_records(cases: list, batch, proto: FieldProtocol) -> list[dict]:
    """The run's record of each of ``cases`` (field cases, or refusals where a change left a column the model
    cannot take), in their order: a refusal, or a case the batch refused when built (the particle budget, the
    calibration), gets ``{"status": "refused", "error": <its line in field terms>}``."""
    by_digest = {r["id"].rsplit("-", 1)[1]: r for r in batch.records}
    why = {(r.pit, r.test): r.message for r in batch.refused}
    out = []
    for c in cases:
        if not isinstance(c, FieldCase):
            out.append({"id": None, "status": "refused", "error": c.message})
        else:
            out.append(by_digest.get(case_digest(c, proto)) or
                       {"id": None, "status": "refused", "error": why.get((c.pit, c.test), "not run")})
    return out
