"""Does a field case's outcome hold on a finer grid? The same columns at 6 cells across the weak layer instead of 4.

The field protocol resolves each weak layer with 4 grid cells (``FieldProtocol.cells_across``), where the snow
ladder's PST is still far from converged (its error at 4 cells: ``error_vs_runtime_snow.py --field-level``). What
the batch scores is the class, so this study asks whether the class, and where the crack ran away, change when
the same columns run finer. It draws ``--per-class`` of a field batch's finished 4-cell cases of each observed
class at random (``--seed``; blind to the predicted outcome) among those whose batch run took at most
``--max-wall`` seconds (the finer run costs about (6/4)^3 = 3.4 times as much), and runs each again from its
checkpoint's scenario with the grid spacing times 4/6, nothing else changed (the slab's crack band follows the
grid: one particle spacing, docs/model.md §9). Per case: the predicted class, the runaway cut, where the slab
broke, particles, steps and wall time at both resolutions. Writes ``benchmarks/field/results/field_resolution.json``.

Usage: ``python benchmarks/field/resolution.py RUNDIR [RUNDIR ...] [--per-class N] [--seed S] [--max-wall W]
[--threads T]``; ``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case.
"""

from __future__ import annotations

import dataclasses
import os
import random
import sys
import tempfile
import time
import warnings

from mpm_warp.config import TimeControl
from mpm_warp.field.batch import run_records
from mpm_warp.field.protocol import FieldProtocol, run_until_decided
from mpm_warp.io.checkpoint import read_checkpoint_meta
from mpm_warp.loader import resolved_scenario
from mpm_warp.scenes.pst import build
from mpm_warp.scenes.pst.outcome import FIELD_CLASSES
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
#: what each run reports, at both resolutions
KEYS = ("predicted", "runaway_cut", "slab_fracture_at", "particles", "steps", "wall_s", "sim_time")
#: cells across the weak layer of the finer runs
FINER = 6


def rerun(rec: dict, run_dir: str, folder: str, cells: int, n_threads: int) -> dict:
    """The case ``rec`` of ``run_dir`` again at ``cells`` cells across its weak layer: the row of both runs."""
    ck = os.path.join(run_dir, rec["id"] + ".ckpt.h5")
    sc = resolved_scenario(read_checkpoint_meta(ck)["scenario"], source=ck)
    p = sc.scene
    coarse = FieldProtocol.cells_across
    fine = dataclasses.replace(p, dx=p.dx * coarse / cells)
    scenario = build(fine, TimeControl(end=sc.time.end, frame_interval=sc.time.frame_interval), name="field")
    t0 = time.perf_counter()
    fine_run = {**run_until_decided(scenario, os.path.join(folder, rec["id"] + ".h5"), n_threads), "threads": n_threads}
    return {"id": rec["id"], "test": rec["test"], "observed": rec["observed"], "setup": rec["setup"],
            "cells": [coarse, cells], "dx": [p.dx, fine.dx],
            "coarse": {**{k: rec.get(k) for k in KEYS}, "threads": rec.get("threads")}, "fine": fine_run,
            "case_wall_s": time.perf_counter() - t0}


def main(argv=None) -> int:
    ap = parser(__doc__, "one case of at most 20 s, to a temporary folder")
    ap.add_argument("runs", nargs="+", help="runs folders of a field batch")
    ap.add_argument("--per-class", type=int, default=4, help="cases to draw per observed class (default 4)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the draw (default 0)")
    ap.add_argument("--max-wall", type=float, default=60.0,
                    help="draw among the cases whose batch run took at most this long (s, default 60)")
    ap.add_argument("--threads", type=int, default=2, help="CPU threads of each finer run (default 2)")
    a = ap.parse_args(argv)
    warnings.filterwarnings("ignore")
    cap = 20.0 if a.quick else a.max_wall
    coarse = f"{FieldProtocol.cells_across} cells across"
    pool = sorted(((r, d) for r, d in run_records(a.runs)
                   if os.path.exists(os.path.join(d, r["id"] + ".ckpt.h5")) and r.get("setup", "").startswith(coarse)
                   and r["wall_s"] <= cap), key=lambda rd: rd[0]["id"])
    rng = random.Random(a.seed)
    chosen = []
    for cls in FIELD_CLASSES:
        of = [rd for rd in pool if rd[0]["observed"] == cls]
        chosen += rng.sample(of, min(a.per_class, len(of)))
    chosen = chosen[:1] if a.quick else chosen
    folder = out_dir(a, RESULTS, "resolution")
    runs = tempfile.mkdtemp(prefix="mpm_warp_resolution_")
    cases = []
    for k, (rec, d) in enumerate(chosen):
        c = rerun(rec, d, runs, FINER, a.threads)
        cases.append(c)
        print(f"[{k + 1}/{len(chosen)}] {c['test']}: {c['coarse']['predicted']} -> {c['fine']['predicted']}, runaway "
              f"{c['coarse']['runaway_cut']} -> {c['fine']['runaway_cut']}, {c['fine']['wall_s']:.0f} s", flush=True)
    data = {"name": "field_resolution", "runs": [os.path.basename(os.path.normpath(r)) for r in a.runs],
            "cells": [FieldProtocol.cells_across, FINER], "seed": a.seed, "max_wall_s": cap, "per_class": a.per_class,
            "chosen": f"{len(chosen)} drawn ({a.per_class} per observed class, seed {a.seed}) from the {len(pool)} "
                      f"finished cases at {coarse} the weak layer whose batch run took at most {cap:g} s",
            "cases": cases, "environment": environment("cpu")}
    print("wrote", write_json("field_resolution", data, folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
