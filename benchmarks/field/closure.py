"""Do the field columns keep their outcome with the laminate closure at their layer interfaces?

At the field protocol's 4 cells across the weak layer the grid's bimaterial artefact is at its worst (the rows
next to the weak layer carry up to 85 % more or less than the overburden, docs/results/snow.md, "Stress at the weak
layer's interfaces"), and the slab-stress studies found the run's slab layers at the base 0.7 to 51 times the
static FE's stress (docs/results/field-slab.md, "A resolved slab"). The laminate closure (``scene.interface_closure``,
docs/model.md §5b) removes that artefact in the settled column. This study draws ``--per-class`` cases of each
observed class at random (``--seed``; blind to the predicted class) from the committed development-set batches
(``--batches``) among those whose batch run took at most ``--max-wall`` seconds, sets each up again from its
pit as the batch did (its id's digest of the parameters and the protocol must match), and runs it by the field
protocol with the closure on, nothing else changed, into ``--runs`` (a Dask batch: resumable). Per case: the
class and the runaway cut without the closure (the batch's run) and with it, and the cost of both. Writes
``benchmarks/field/results/field_closure.json``.

Usage: ``python benchmarks/field/closure.py DIR --runs RUNDIR [--per-class 6] [--seed 0] [--max-wall 120]
[--workers N] [--threads T]``; ``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case.
"""

from __future__ import annotations

import json
import os
import random
import sys
import tempfile
import time
import warnings

from mpm_warp.field.batch import case_digest, gather, run_cases
from mpm_warp.field.cases import FieldCase
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.scenes.pst.outcome import FIELD_CLASSES
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
BATCHES = (os.path.join(RESULTS, "field_batch.json"), os.path.join(RESULTS, "measured", "field_batch.json"))
#: what each run reports, without and with the closure
KEYS = ("status", "predicted", "runaway_cut", "slab_fracture_at", "particles", "steps", "wall_s", "threads", "workers")


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
    rows = {}
    for b in batches:
        for c in json.load(open(b))["cases"]:
            if c.get("status") == "ok":
                rows[c["id"]] = c
    chosen = sorted(rows.values(), key=lambda c: c["id"])[:limit]
    cases = batch_cases(data, chosen, FieldProtocol().validate())
    return None if cases is None else (chosen, cases)


def draw(batches: list[str], per_class: int, seed: int, max_wall: float) -> tuple[list[dict], int]:
    """``per_class`` finished cases of each observed class, at random (``seed``), among the batches' cases whose
    run took at most ``max_wall`` s; and the size of that pool."""
    pool = {}
    for b in batches:
        for c in json.load(open(b))["cases"]:
            if c.get("status") == "ok" and c.get("wall_s") is not None and c["wall_s"] <= max_wall:
                pool[c["id"]] = c
    ordered = sorted(pool.values(), key=lambda c: c["id"])
    rng = random.Random(seed)
    chosen = []
    for cls in FIELD_CLASSES:
        of = [c for c in ordered if c["observed"] == cls]
        chosen += rng.sample(of, min(per_class, len(of)))
    return chosen, len(ordered)


def add_draw_arguments(p, runs: str, per_class: int) -> None:
    """The arguments of a study that draws cases per observed class from the committed batches and runs them:
    the data, the runs folder (``runs`` says which runs), the draw and the Dask batch."""
    p.add_argument("data", help="folder of CAAML files (the unpacked development set)")
    p.add_argument("--runs", help=f"folder of the runs {runs} (kept: a rerun resumes); default temporary")
    p.add_argument("--batches", nargs="+", default=list(BATCHES), help="field_batch.py JSONs (default: both committed)")
    p.add_argument("--per-class", type=int, default=per_class,
                   help=f"cases to draw per observed class (default {per_class})")
    p.add_argument("--seed", type=int, default=0, help="seed of the draw (default 0)")
    p.add_argument("--max-wall", type=float, default=120.0,
                   help="draw among the cases whose batch run took at most this long (s, default 120)")
    p.add_argument("--workers", type=int, default=None, help="Dask workers (default one per core)")
    p.add_argument("--threads", type=int, default=FieldProtocol.threads, help="CPU threads of each case (default 1)")


def draw_and_run(args, name: str, env: dict, proto: FieldProtocol, run_proto: FieldProtocol, adjust=None):
    """The drawn cases (``add_draw_arguments``) set up again from their pits under ``proto`` (each must match its
    batch's digest), changed by ``adjust(case)`` when given (it may return a refusal: a column the change leaves
    the model unable to take), and run under ``run_proto`` into ``args.runs`` (or a temporary folder). Returns
    ``(chosen, records, meta)``: the batch rows drawn, the new runs' records in the same order
    (:func:`aligned_records`), and the fields every such study's JSON carries (``env``, the script's environment,
    recorded before the runs) with ``dest`` (the JSON's folder) and ``cases`` (the cases run, or their
    refusals), which the caller pops; None when a case does not match (said on stderr)."""
    cap = 20.0 if args.quick else args.max_wall
    chosen, pool = draw(args.batches, args.per_class, args.seed, cap)
    chosen = chosen[:1] if args.quick else chosen
    t0 = time.perf_counter()
    cases = batch_cases(args.data, chosen, proto)
    if cases is None:
        return None
    cases = [adjust(c) for c in cases] if adjust is not None else cases
    setup_s = time.perf_counter() - t0
    dest = out_dir(args, RESULTS, name)
    runnable = [c for c in cases if isinstance(c, FieldCase)]
    with tempfile.TemporaryDirectory(prefix=f"mpm_warp_{name}_") as tmp:
        batch = run_cases(runnable, [], args.runs or tmp, workers=args.workers, protocol=run_proto)
    records = aligned_records(cases, batch, run_proto)
    meta = {"batches": [os.path.relpath(b, HERE) for b in args.batches],
            "per_class": args.per_class, "seed": args.seed, "max_wall_s": cap,
            "chosen": f"{len(chosen)} drawn ({args.per_class} per observed class, seed {args.seed}) from the {pool} "
                      f"finished cases of the batches whose run took at most {cap:g} s",
            "runs": os.path.basename(os.path.normpath(args.runs)) if args.runs else None,
            "protocol": run_proto.run_key(), "threads": args.threads, "workers": args.workers, "setup_s": setup_s,
            "environment": env, "dest": dest, "cases": cases}
    return chosen, records, meta


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


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_draw_arguments(p, "with the closure", per_class=6)
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    off = FieldProtocol(threads=args.threads).validate()
    on = FieldProtocol(threads=args.threads, interface_closure=True).validate()
    drawn = draw_and_run(args, "field_closure", environment("cpu"), off, on)
    if drawn is None:
        return 2
    chosen, records, meta = drawn
    rows = []
    for b, rec in zip(chosen, records, strict=True):
        rows.append({"id": b["id"], "closure_id": rec["id"], "test": b["test"], "observed": b["observed"],
                     "w_f": b["w_f"], "w_f_source": b["w_f_source"], "setup": b["setup"],
                     "off": {k: b.get(k) for k in KEYS}, "on": {k: rec.get(k) for k in KEYS + ("error",)}})
        print(f"{b['test']} ({b['observed']}): {b['predicted']} -> {rec.get('predicted')}, runaway "
              f"{b['runaway_cut']} -> {rec.get('runaway_cut')}", flush=True)
    dest = meta.pop("dest")
    meta.pop("cases")
    data = {"name": "field_closure", **meta, "cases": rows}
    path = write_json("field_closure", data, dest)
    print(f"{path}: {len(rows)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
