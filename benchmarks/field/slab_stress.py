"""Why did the slab not break? A field run's slab stress against its strength and against weac's static beam.

For each selected finished case of a field batch (default: every observed SF the model called END; or any
observed and predicted class, a seeded sample of them, or given cases), the case runs again from its own
scenario (the one in its checkpoint: the field protocol, the same stop) with the particles' stress stored
at every frame. Per frame: the blade, the damage front, and each slab layer's largest in-plane principal
stress over its tensile strength (the run's own, Sigrist 2006 from density). The crack's onset is the
blade's position at the first frame the damage front leads it by two cells.

Beside it, weac's static solution of the same column at the recorded cut and at the onset: the slab's
largest stress over strength over the cut (the cantilever's bending) and at the crack tip (where weac's
beam puts the weak layer's reaction), as the static rule of the batch reads it (docs/field.md). Each slab
layer's thickness in grid cells says where a thin layer is resolved by one or two cells only. The control
is a homogeneous soft slab sawn to below its critical cut: there a beam's bending holds once the cut is as
long as the slab is deep. Nothing here changes the model. Writes
``benchmarks/field/results/field_slab_stress.json``.

Usage: ``python benchmarks/field/slab_stress.py RUNDIR [RUNDIR ...] [--observed SF --predicted END]
[--sample N --seed 0] [--cases ID ...] [--no-control] [--interface-closure on|off]``; ``--quick``: the first
selected case, to a temporary folder. Minutes of CPU a case.
"""

from __future__ import annotations

import os
import random
import sys
import tempfile
import warnings

from mpm_warp.config import TimeControl
from mpm_warp.field.batch import run_records
from mpm_warp.field.studies.slab_stress import (
    ONSET_CELLS,
    control_params,
    mpm_ratio_to,
    run_series,
    stress_row,
    weac_at,
)
from mpm_warp.scenes.pst import build
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")

#: the control's cuts (m): the run's slab stress against weac's beam where the beam is exact, before the crack
#: starts (:func:`~mpm_warp.field.studies.slab_stress.control_params`: weac's critical cut 0.40 m)
CONTROL_CUTS = (0.1, 0.15, 0.2, 0.25, 0.3)


def control(tmp: str, threads: int) -> dict:
    """The homogeneous control (:data:`CONTROL_CUTS`): per cut, the run's slab stress over strength while the blade
    had cut at most that much, and weac's over the cut there."""
    p = control_params()
    sc = build(p.validate("scene"), TimeControl(end=p.saw_start + 0.36, frame_interval=0.005), name="control")
    out = run_series(sc, os.path.join(tmp, "control.h5"), threads)
    rows = [{"cut": cut, "run": mpm_ratio_to(out["series"], cut), "weac": weac_at(sc.scene, cut)["over_cut"]}
            for cut in CONTROL_CUTS]
    return {"what": "20 cm of 120 kg/m^3 on flat ground, 2 m column, sawn to 0.36 m", "dx": p.dx,
            "slab_depth_m": p.slab_depth,
            "rows": rows, "wall_s": out["wall_s"]}


def main(argv=None) -> int:
    p = parser(__doc__, "the first selected case")
    p.add_argument("runs", nargs="+", help="field batches' runs folders (field_batch.py --runs)")
    p.add_argument("--cases", nargs="+", metavar="ID", help="case ids (instead of --observed and --predicted)")
    p.add_argument("--observed", default="SF", help="the observed class of the cases (default SF)")
    p.add_argument("--predicted", default="END", help="the predicted class of the cases (default END)")
    p.add_argument("--sample", type=int, help="a seeded sample of this many of the cases (default: all)")
    p.add_argument("--seed", type=int, default=0, help="seed of --sample (default 0)")
    p.add_argument("--no-control", action="store_true", help="leave out the homogeneous control")
    p.add_argument("--threads", type=int, default=1, help="CPU threads of each run (default 1)")
    p.add_argument("--interface-closure", choices=("as-run", "on", "off"), default="as-run",
                   help="run each column with the laminate closure on or off (default: as its batch ran it)")
    args = p.parse_args(argv)
    closure = None if args.interface_closure == "as-run" else args.interface_closure == "on"
    warnings.filterwarnings("ignore")
    recs = [(r, run_dir) for r, run_dir in run_records(args.runs)
            if ((r["id"] in args.cases) if args.cases else
                (r.get("observed") == args.observed and r["predicted"] == args.predicted))]
    if args.sample is not None and args.sample < len(recs):
        recs = random.Random(args.seed).sample(sorted(recs, key=lambda rd: rd[0]["id"]), args.sample)
    recs = recs[:1] if args.quick else recs
    dest = out_dir(args, RESULTS, "field_slab_stress")
    recs.sort(key=lambda rd: rd[0].get("wall_s") or 0.0)        # the cheapest first: a run stopped early keeps them
    data = {"name": "field_slab_stress", "runs": [os.path.basename(os.path.normpath(d)) for d in args.runs],
            "onset_cells": ONSET_CELLS, "selection": {"cases": args.cases} if args.cases else {
                "observed": args.observed, "predicted": args.predicted, "sample": args.sample, "seed": args.seed},
            "interface_closure": args.interface_closure, "selected": len(recs), "environment": environment("cpu"),
            "cases": []}
    with tempfile.TemporaryDirectory(prefix="mpm_warp_slab_stress_") as tmp:
        if not args.no_control:
            data["control"] = control(tmp, args.threads)
            print("control: " + ", ".join(f"{r['cut']:g} m: run {r['run']:.3f}, weac {r['weac']:.3f}"
                                          for r in data["control"]["rows"]), flush=True)
            path = write_json("field_slab_stress", data, dest)
        for r, run_dir in recs:
            row = stress_row(r, run_dir, tmp, args.threads, closure)
            data["cases"].append(row)
            path = write_json("field_slab_stress", data, dest)          # after every case
            print(f"{r['test']}: MPM peak {row['mpm_peak_ratio']:.2f} of strength; weac at the recorded cut "
                  f"{row['weac_at_recorded_cut']['over_cut']:.2f} over the cut, "
                  f"{row['weac_at_recorded_cut']['tip']:.2f} at the tip", flush=True)
    print(f"{path if recs else dest}: {len(data['cases'])} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
