"""Does the model predict a real PST's outcome (END, SF, ARR) better than the majority class and weac's static rule?

Sets up every PST record of a folder of pits (the development set, docs/profiles.md), selects the runnable
columns whose slab densities were all measured and a sample stratified by the observed class (``--per-class``
of each of END, SF and ARR, drawn with ``--seed``, from the rest; the classes interleaved, so that the first
N cases of a run stopped early are stratified too), and runs them by the field protocol on Dask
(``mpm_warp.field.batch``, resumable: the runs stay in ``--runs``). Writes ``benchmarks/field/results/
field_batch.json``: the selection, the scores of the model and of both baselines (confusion matrix, recall
per class, balanced accuracy), the cost per case (median wall time, particles, steps) and the batch's rate.

Usage: ``python benchmarks/field/field_batch.py DIR --runs RUNDIR [--per-class 50] [--workers 2] [--threads 1]``;
``--quick``: two cases per class on a small budget, to a temporary folder. Hours of CPU for the full
selection on 2 cores.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import warnings

from mpm_warp.field.batch import FieldBatch, finished_records, gather, run_cases, score_records
from mpm_warp.field.calibrated import MODEL_READINGS
from mpm_warp.field.draw import select
from mpm_warp.field.information_bar import CASE_FEATURES
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.studies.at_call import body_at_call
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


#: each case's keys in the JSON
CASE_KEYS = ("id", "pit", "test", "observed", "predicted", "p_end", "p_sf", "p_arr", "static_class",
             "static_peak_ratio", "recorded_cut", "runaway_cut", "slab_fracture_at", "slab_peak_stress_ratio",
             "slab_peak_body_stress_ratio", "slab_body_stress_ratio_at_call", *CASE_FEATURES,
             *(k for k in MODEL_READINGS if k != "static_peak_ratio"), "w_f", "w_f_source",
             "setup", "particles", "steps", "threads", "workers", "wall_s", "status", "error")


def main(argv=None) -> int:
    p = parser(__doc__, "two cases per class, no measured-density set, 30,000 particles")
    p.add_argument("data", help="folder of CAAML files (the unpacked development set)")
    p.add_argument("--runs", help="folder of the runs (kept: a rerun resumes); default a temporary folder")
    p.add_argument("--per-class", type=int, default=50, help="sampled cases per observed class (default 50)")
    p.add_argument("--seed", type=int, default=0, help="seed of the sample (default 0)")
    p.add_argument("--workers", type=int, default=None, help="Dask workers (default one per core)")
    p.add_argument("--threads", type=int, default=FieldProtocol.threads, help="CPU threads of each case (default 1)")
    p.add_argument("--max-particles", type=int, default=FieldProtocol.max_particles, help="per-case budget")
    p.add_argument("--limit", type=int, default=None, help="run only the first N selected cases (a rate measurement)")
    p.add_argument("--finished-only", action="store_true",
                   help="score the selected cases whose runs in --runs have finished, and run none (a batch stopped "
                        "early)")
    p.add_argument("--elastic-substratum", action="store_true",
                   help="run the weak layer on the profile's old snow instead of a rigid base (weac's column)")
    p.add_argument("--pre-cut-share", type=float, default=FieldProtocol.pre_cut_share,
                   help="start each column sawn this share of weac's critical cut (default 0.5; 0: none)")
    p.add_argument("--interface-closure", action="store_true",
                   help="run each column with the laminate closure at its layer interfaces (docs/model.md §5b)")
    p.add_argument("--no-measured", action="store_true",
                   help="leave out the measured-density columns (a first, small sample: the stratified part only)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    t0 = time.perf_counter()
    cases, refused = gather([args.data], calibrate=False)      # the selection's columns calibrate when built
    per, budget = (2, 30_000) if args.quick else (args.per_class, args.max_particles)
    chosen, counts = select(cases, per, args.seed, measured=not (args.quick or args.no_measured))
    if args.limit is not None:
        chosen = chosen[:max(1, args.limit)]
    runs = args.runs or tempfile.mkdtemp(prefix="mpm_warp_field_batch_")
    env = environment(args.device)
    t1 = time.perf_counter()
    proto = FieldProtocol(max_particles=budget, threads=args.threads, rigid_base=not args.elastic_substratum,
                          pre_cut_share=args.pre_cut_share, interface_closure=args.interface_closure).validate()
    if args.finished_only:
        recs = finished_records(chosen, runs, proto)
        body_at_call(recs, runs)                 # runs from before the body's series: its stress at the call
        batch = FieldBatch(recs, [], score_records(recs), len(recs), runs)
    else:
        batch = run_cases(chosen, [], runs, workers=args.workers, device=args.device,
                          protocol=proto, progress=True)
        body_at_call(batch.records, runs)        # reused runs from before the body's series: the same reading
        batch = FieldBatch(batch.records, batch.refused, score_records(batch.records), batch.skipped, batch.out_dir)
    wall = time.perf_counter() - t1
    ok = [r for r in batch.records if r.get("status") == "ok"]
    data = {"name": "field_batch", "data": os.path.basename(os.path.normpath(args.data)), "environment": env,
            "selection": {"runnable": len(cases), "refused": len(refused), **counts, "seed": args.seed,
                          "per_class": per, "max_particles": budget, "limit": args.limit,
                          "protocol": proto.run_key(),
                          "finished_only": args.finished_only},
            "workers": args.workers, "threads_per_case": args.threads,
            "scores": batch.scores, "batch_wall_s": wall, "setup_wall_s": t1 - t0,
            "cases_per_hour": 3600.0 * len(ok) / wall if wall > 0 and batch.skipped == 0 else None,
            "refused_at_build": None if args.finished_only else [r.line() for r in batch.refused],
            "resumed_cases": batch.skipped, "runs": runs,
            "cases": [{k: r.get(k) for k in CASE_KEYS} for r in batch.records]}
    path = write_json("field_batch", data, out_dir(args, RESULTS, "field_batch"))
    sc = batch.scores
    print(f"{path}: {sc['cases']} cases, balanced accuracy model {sc['model']['balanced_accuracy']}, majority "
          f"{sc['majority']['balanced_accuracy']}, weac static {sc['weac_static']['balanced_accuracy']}; median "
          f"case {sc['wall_s']['median']} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
