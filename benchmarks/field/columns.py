"""How many field cases an hour, each alone or many columns stepped together, and do they keep their outcome?

Draws the first ``--limit`` cases of the development set's stratified draw (``--per-class``, ``--seed``: the draw
of ``field_batch.py``) and runs them by the field protocol twice on ``--device``, each time into a fresh folder:
each case alone (``columns`` 1, ``--workers`` Dask workers of one thread), then in groups of ``--columns``
stepped together (``mpm_warp.column_batch``; on the CPU ``--workers`` groups side by side). Per case: the class
and runaway cut of both runs, the steps, and what the shared step cost the column (its own elastic step over
its group's). Writes ``benchmarks/field/results/field_columns_<cpu|cuda>.json``: cases per hour both ways
(kernels compiled beforehand by a first case), their ratio, and the agreement.

Usage: ``python benchmarks/field/columns.py DIR [--limit 8] [--columns 4] [--workers 2] [--device cpu]``;
``--quick``: three made-up table columns, in groups of three, to a temporary folder. Minutes per case on the
CPU.
"""

from __future__ import annotations

import math
import os
import statistics
import sys
import tempfile
import time
import warnings

from mpm_warp.field.batch import gather, run_cases
from mpm_warp.field.draw import select
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser, result_name

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
#: the made-up columns of --quick (two grids; the crack runs away in none)
QUICK_TABLE = ("id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,"
               "column_ends\n") + """tiny-a,End,0,40,12,15,180,4,,0.3,
tiny-b,Arr,0,40,15,15,180,4,,0.5,vertical
tiny-c,End,0,40,12,15,180,5,,0.3,
"""


def _run(cases, folder, device, workers, columns) -> tuple[list, float]:
    proto = FieldProtocol(columns=columns).validate()
    t0 = time.perf_counter()
    batch = run_cases(cases, [], folder, workers=workers, device=device, protocol=proto, progress=True)
    return batch.records, time.perf_counter() - t0


def _same_cut(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return math.isclose(a, b, rel_tol=0.0, abs_tol=0.01)


def main(argv=None) -> int:
    p = parser(__doc__, "three made-up columns in one group of three")
    p.add_argument("data", nargs="?", help="folder of CAAML files (the unpacked development set)")
    p.add_argument("--limit", type=int, default=8, help="the first N cases of the draw (default 8)")
    p.add_argument("--columns", type=int, default=4, help="columns stepped together (default 4)")
    p.add_argument("--workers", type=int, default=2, help="Dask workers, each one thread (default 2)")
    p.add_argument("--per-class", type=int, default=50, help="the draw's cases per observed class (default 50)")
    p.add_argument("--seed", type=int, default=0, help="the draw's seed (default 0)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    scratch = tempfile.mkdtemp(prefix="mpm_warp_field_columns_")
    if args.quick:
        table = os.path.join(scratch, "columns.csv")
        with open(table, "w") as fh:
            fh.write(QUICK_TABLE)
        chosen, _ = gather([table])
        columns, workers = 3, 1
    else:
        if not args.data:
            p.error("DIR (the development set's pits) is required without --quick")
        cases, _ = gather([args.data], calibrate=False)
        chosen = select(cases, args.per_class, args.seed, measured=False)[0][:max(1, args.limit)]
        columns, workers = args.columns, args.workers
    workers = 1 if (args.device or "").startswith("cuda") else workers
    env = environment(args.device)
    # a first case compiles every kernel the others use (not timed)
    _run(chosen[:1], os.path.join(scratch, "compile"), args.device, 1, 1)
    alone, wall_alone = _run(chosen, os.path.join(scratch, "alone"), args.device, workers, 1)
    together, wall_together = _run(chosen, os.path.join(scratch, "together"), args.device, workers, columns)
    rows = []
    for a, t in zip(alone, together, strict=True):
        rows.append({"pit": a.get("pit"), "test": a.get("test"), "observed": a.get("observed"),
                     "status": [a.get("status"), t.get("status")], "particles": a.get("particles"),
                     "class": [a.get("predicted"), t.get("predicted")],
                     "runaway_cut": [a.get("runaway_cut"), t.get("runaway_cut")],
                     "sim_time": [a.get("sim_time"), t.get("sim_time")], "steps": [a.get("steps"), t.get("steps")],
                     "shared_step_cost": t.get("shared_step_cost")})
    ok = [r for r in rows if r["status"] == ["ok", "ok"]]
    n = len(rows)                    # the cases set up and run (a drawn record the protocol refuses runs in neither)
    data = {"name": "field_columns", "environment": env, "device": args.device, "quick": args.quick,
            "draw": None if args.quick else {"per_class": args.per_class, "seed": args.seed, "limit": args.limit},
            "drawn": len(chosen), "cases": n, "columns": columns, "workers": workers,
            "alone": {"wall_s": wall_alone, "cases_per_hour": 3600.0 * n / wall_alone},
            "together": {"wall_s": wall_together, "cases_per_hour": 3600.0 * n / wall_together},
            "speedup": wall_alone / wall_together,
            "agreement": {"both_ok": len(ok), "same_class": sum(r["class"][0] == r["class"][1] for r in ok),
                          "same_runaway_cut_1cm": sum(_same_cut(*r["runaway_cut"]) for r in ok),
                          "shared_step_cost_median": statistics.median(r["shared_step_cost"] for r in ok)
                          if ok else None,
                          "shared_step_cost_max": max((r["shared_step_cost"] for r in ok), default=None)},
            "rows": rows}
    path = write_json(result_name("field_columns", args), data, out_dir(args, RESULTS, "field_columns"))
    ag = data["agreement"]
    print(f"{path}: {n} cases on {args.device}: alone {data['alone']['cases_per_hour']:.0f}/h, {columns} together "
          f"{data['together']['cases_per_hour']:.0f}/h ({data['speedup']:.2f}x); same class {ag['same_class']} of "
          f"{ag['both_ok']}, same runaway cut (1 cm) {ag['same_runaway_cut_1cm']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
