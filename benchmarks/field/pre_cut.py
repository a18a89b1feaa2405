"""Does a pre-cut change a field case's outcome? The same columns, started sawn a share of weac's critical cut.

The saw's way to the runaway is most of a field case's simulated time. A column pre-cut short of its critical
cut (``scene.saw.pre_cut``) settles as a sawn one does (``tests/test_pst_pre_cut.py``), but a field case then
runs on through the dynamics of its crack. This study takes the finished cases of a field batch (its runs
folder), chooses the ``--cases`` cheapest (their wall time, then their id: a choice blind to the outcome, which
favours small columns), and runs each again from its checkpoint's scenario with the saw pre-cut ``--share``
times weac's critical cut of the column at its fracture energy (at most half the column), nothing else
changed. Per case: the predicted class, the runaway cut, where the slab broke, particles, steps and wall time,
with and without the pre-cut. Writes ``benchmarks/field/results/field_pre_cut.json``.

Usage: ``python benchmarks/field/pre_cut.py RUNDIR [RUNDIR ...] [--cases N] [--share S]``; ``--quick``: the
cheapest case, to a temporary folder. Seconds to a minute a case on one thread.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import tempfile
import time
import warnings

from mpm_warp.config import TimeControl
from mpm_warp.field.batch import run_records
from mpm_warp.field.protocol import run_until_decided
from mpm_warp.io.checkpoint import read_checkpoint_meta
from mpm_warp.loader import resolved_scenario
from mpm_warp.scenes.pst import build
from mpm_warp.scenes.pst.static import static_column
from mpm_warp.scenes.weac_reference import critical_cut
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
#: what each run reports, with and without the pre-cut
KEYS = ("predicted", "runaway_cut", "slab_fracture_at", "particles", "steps", "wall_s", "sim_time")


def rerun(rec: dict, run_dir: str, folder: str, share: float) -> dict:
    """The case ``rec`` of ``run_dir`` again, pre-cut ``share`` of weac's critical cut: the row of both runs."""
    ck = os.path.join(run_dir, rec["id"] + ".ckpt.h5")
    sc = resolved_scenario(read_checkpoint_meta(ck)["scenario"], source=ck)
    p = sc.scene
    static = critical_cut(static_column(p), p.weak_layer.w_f)
    pre = min(share * static, 0.5 * float(p.length)) if static else 0.0
    cut = dataclasses.replace(p, saw=dataclasses.replace(p.saw, pre_cut=pre))
    t_end = sc.time.end - pre / p.saw.speed               # the protocol's end, less the way the blade skips
    scenario = build(cut, TimeControl(end=t_end, frame_interval=sc.time.frame_interval), name="field")
    t0 = time.perf_counter()
    pre_run = run_until_decided(scenario, os.path.join(folder, rec["id"] + ".h5"), 1)
    return {"id": rec["id"], "test": rec["test"], "observed": rec["observed"], "setup": rec["setup"],
            "static_cut": static, "pre_cut": pre, "without": {k: rec.get(k) for k in KEYS}, "with": pre_run,
            "case_wall_s": time.perf_counter() - t0}


def main(argv=None) -> int:
    ap = parser(__doc__, "the cheapest case, to a temporary folder")
    ap.add_argument("runs", nargs="+", help="runs folders of a field batch")
    ap.add_argument("--cases", type=int, default=15, help="how many of the cheapest finished cases (default 15)")
    ap.add_argument("--share", type=float, default=0.5, help="the pre-cut over weac's critical cut (default 0.5)")
    a = ap.parse_args(argv)
    warnings.filterwarnings("ignore")
    recs = [(r, d) for r, d in run_records(a.runs) if os.path.exists(os.path.join(d, r["id"] + ".ckpt.h5"))
            and "pre-cut" not in r.get("setup", "")]
    recs.sort(key=lambda rd: (rd[0]["wall_s"], rd[0]["id"]))
    chosen = recs[:1 if a.quick else a.cases]
    folder = out_dir(a, RESULTS, "pre_cut")
    runs = tempfile.mkdtemp(prefix="mpm_warp_pre_cut_")
    cases = []
    for k, (rec, d) in enumerate(chosen):
        c = rerun(rec, d, runs, a.share)
        cases.append(c)
        print(f"[{k + 1}/{len(chosen)}] {c['test']}: pre-cut {c['pre_cut']:.3f} m, {c['without']['predicted']} -> "
              f"{c['with']['predicted']}, {c['without']['steps']} -> {c['with']['steps']} steps", flush=True)
    data = {"name": "field_pre_cut", "runs": [os.path.basename(os.path.normpath(r)) for r in a.runs],
            "share": a.share, "chosen": f"the {len(chosen)} cheapest of {len(recs)} finished cases (their wall time)",
            "cases": cases, "environment": environment("cpu")}
    print("wrote", write_json("field_pre_cut", data, folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
