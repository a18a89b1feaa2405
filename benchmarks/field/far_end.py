"""Does the crack reach the column's end where the model says END? The field columns run on past that call.

The model says END once the damage front enters the far end zone, one slab thickness from the column's end
(docs/model.md; there the slab's free end lifts the layer). Where the crack runs away within a slab thickness of
the end, END is called as soon as it runs; an observer writes END only if the crack reaches the end and ARR if it
stops short of it. This study draws cases as
the what-if studies do (``--per-class`` of each observed class, ``--seed``, among the committed batches' cases of at
most ``--max-wall`` s), keeps those the batch predicted END, sets each up again from its pit (its id's digest must
match the batch's) and runs it by the field protocol, nothing changed, past the END call: until the damage front
reaches the last ``--end-bins`` bins of the column (the crack reached the end), or stands still for the
protocol's stall time (it stopped short), or the run's time ends. Per case: where the front was when END was
called and where it ended, and the cost. Runs ``--workers`` cases at a time, one thread each; a case whose record
is in ``--runs`` is not run again. Writes ``benchmarks/field/results/field_far_end.json``.

Usage: ``python benchmarks/field/far_end.py DIR --runs RUNDIR [--per-class 16] [--seed 0] [--workers 2]``;
``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import sys
import tempfile
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

from mpm_warp.field.batch import case_scenario
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.studies.drawn import add_draw_arguments, batch_cases, draw_rows
from mpm_warp.io.records import write_record
from mpm_warp.scenes.pst.analysis import end_zone
from mpm_warp.scenes.pst.outcome import STALL_TIME, front_stalled
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")


def run_past_end_call(scenario, path: str, end_bins: int) -> dict:
    """Run a field ``scenario`` into ``path`` past its END call, until the damage front is within ``end_bins`` bins
    of the column's end, or has stood still for the stall time after the saw stopped, or the time ends: the call
    (class, time, front) and where the front ended (m from the cut end)."""
    from mpm_warp.runner import run

    seen = {}

    def go_on(sim, frame):
        mon = sim.monitors["pst"]
        times, series = mon.series_arrays()
        front = series.get("front", [])
        if not len(times):
            return True
        seen.update(last_time=float(times[-1]), last_front=float(front[-1]))
        if "call" not in seen:
            o = mon.outcome()
            if o.get("class") is None:
                return True
            seen.update(call=o["class"], call_time=float(times[-1]), call_front=float(front[-1]))
            if o["class"] != "END":
                return False                      # decided otherwise: the batch's stop
        p = mon.sawn()
        seen["reached"] = bool(front[-1] >= p.length - end_bins * p.bin_width - 1e-9)
        seen["stalled"] = bool(front_stalled(times, front, p))   # the outcome's own test for an arrest
        return not (seen["reached"] or seen["stalled"])

    t0 = time.perf_counter()
    res = run(scenario, path, device="cpu", overwrite=True, n_threads=1, callback=go_on)
    p = scenario.scene
    return {**seen, "runaway_cut": res.scene_result.get("runaway_cut"), "length": float(p.length),
            "end_zone": float(end_zone(p)), "bin_width": float(p.bin_width), "sim_time": res.sim_time,
            "steps": res.steps, "particles": res.n_particles, "wall_s": time.perf_counter() - t0}


def _one(task: dict) -> dict:
    """One case in a worker process: its record, also written to its JSON under the runs folder."""
    warnings.filterwarnings("ignore")
    rec = {k: task[k] for k in ("id", "test", "observed", "batch")}
    try:
        rec.update(status="ok", **run_past_end_call(task["scenario"], task["path"] + ".h5", task["end_bins"]))
    except Exception as e:      # recorded, never stops the others
        rec.update(status="failed", error=f"{type(e).__name__}: {e}")
    write_record(task["path"] + ".json", rec, "a far-end case record", default=str)   # atomic: a kill leaves none
    return rec


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_draw_arguments(p, "past the END call", 16, RESULTS)
    p.add_argument("--end-bins", type=int, default=2, help="the crack reached the end within this many bins (2)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    env = environment("cpu")
    cap = 20.0 if args.quick else args.max_wall
    chosen, pool = draw_rows(args.batches, args.per_class, args.seed, cap)
    ends = [c for c in chosen if c["predicted"] == "END"][: 1 if args.quick else None]
    proto = FieldProtocol().validate()
    cases = batch_cases(args.data, ends, proto)
    if cases is None:
        return 2
    dest = out_dir(args, RESULTS, "field_far_end")
    with tempfile.TemporaryDirectory(prefix="mpm_warp_far_end_") as tmp:
        runs = args.runs or tmp
        os.makedirs(runs, exist_ok=True)
        records, todo = {}, []
        for b, case in zip(ends, cases, strict=True):
            path = os.path.join(runs, b["id"])
            if os.path.exists(path + ".json"):
                records[b["id"]] = json.load(open(path + ".json"))
                continue
            scenario, _ = case_scenario(case, proto)
            batch = {k: b.get(k) for k in ("predicted", "runaway_cut", "particles", "steps", "wall_s", "threads")}
            todo.append({"id": b["id"], "test": b["test"], "observed": b["observed"], "batch": batch,
                         "scenario": scenario, "path": path, "end_bins": args.end_bins})
        with ProcessPoolExecutor(max_workers=args.workers or 2, mp_context=multiprocessing.get_context("spawn")) as ex:
            for rec in ex.map(_one, todo):
                records[rec["id"]] = rec
                print(f"{rec['test']} ({rec['observed']}): call {rec.get('call')} at front {rec.get('call_front')}, "
                      f"reached {rec.get('reached')}, stalled {rec.get('stalled')}", flush=True)
    data = {"name": "field_far_end", "per_class": args.per_class, "seed": args.seed, "max_wall_s": cap,
            "end_bins": args.end_bins, "stall_time": STALL_TIME,
            "chosen": f"{len(ends)} the batch predicted END of {len(chosen)} drawn ({args.per_class} per observed "
                      f"class, seed {args.seed}) from the {pool} finished cases of the batches whose run took at most "
                      f"{cap:g} s",
            "batches": [os.path.relpath(b, HERE) for b in args.batches], "workers": args.workers or 2,
            "environment": env, "cases": [records[b["id"]] for b in ends]}
    path = write_json("field_far_end", data, dest)
    print(f"{path}: {len(ends)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
