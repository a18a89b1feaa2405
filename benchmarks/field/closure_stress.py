"""Is the slab's stress at the weak layer the grid's? The closure study's columns against a static FE.

The slab-stress studies found a field run's slab layers next to the weak layer 0.7 to 51 times the stress of a
static FE that resolves every layer, where the layers clear of it agree (docs/results/field-slab.md, "A resolved slab").
This study takes the SF and END cases of ``closure.py``'s draw (its JSON names them, its ``--runs`` holds their
checkpoints) and runs each from its scenario with the laminate closure ``--closure on`` or ``off``, nothing
else changed, with the particles' stress at every frame (``slab_stress.py``): per slab layer the largest
principal stress over its tensile strength, up to the crack's onset and in the onset frame. The same column is
then solved statically at that onset by the FE (``slab_fe.py``). Run once with each ``--closure`` (two
processes side by side on two cores). Writes ``benchmarks/field/results/closure/field_closure_stress_<on|off>.json``.

Usage: ``python benchmarks/field/closure_stress.py RUNDIR --closure on|off [--threads T]``; ``--quick``: the
cheapest case, coarse FE, to a temporary folder. Minutes a case.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import warnings

from mpm_warp.field.batch import run_records
from mpm_warp.field.studies.slab_fe import MESHES, fe_row
from mpm_warp.field.studies.slab_stress import stress_row
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results", "closure")
DRAW = os.path.join(HERE, "results", "field_closure.json")


def main(argv=None) -> int:
    p = parser(__doc__, "the cheapest case, coarse FE")
    p.add_argument("runs", help="closure.py's --runs folder (the closure runs' checkpoints)")
    p.add_argument("--closure", choices=("on", "off"), required=True,
                   help="run the columns with the closure or without")
    p.add_argument("--draw", default=DRAW, help="closure.py's JSON (default: the committed one)")
    p.add_argument("--threads", type=int, default=1, help="CPU threads of each run (default 1)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    draw = json.load(open(args.draw))
    wanted = {c["after_id"]: c for c in draw["cases"] if c["observed"] in ("SF", "END")
              and c["after"].get("status") == "ok"}
    recs = sorted(((r, d) for r, d in run_records([args.runs]) if r["id"] in wanted), key=lambda rd: rd[0]["wall_s"])
    if len(recs) < len(wanted):
        print(f"error: runs: {len(wanted) - len(recs)} of the draw's cases have no finished run in {args.runs}",
              file=sys.stderr)
        return 2
    recs = recs[:1] if args.quick else recs
    meshes = MESHES[:1] if args.quick else MESHES
    name = f"field_closure_stress_{args.closure}"
    dest = out_dir(args, RESULTS, name)
    data = {"name": name, "draw": os.path.relpath(args.draw, HERE), "closure": args.closure, "threads": args.threads,
            "meshes_m": list(meshes), "environment": environment("cpu"), "cases": []}
    with tempfile.TemporaryDirectory(prefix="mpm_warp_closure_stress_") as tmp:
        for r, run_dir in recs:
            row = stress_row(r, run_dir, tmp, args.threads, args.closure == "on")
            fe = fe_row(row, run_dir, meshes)
            row.pop("series")
            data["cases"].append({**row, "batch_id": wanted[r["id"]]["id"], "fe": fe})
            path = write_json(name, data, dest)
            o = fe.get("at_onset")
            print(f"{r['test']} ({r['observed']}, closure {args.closure}): {row['predicted']}, onset "
                  f"{row['onset_cut']}, run per layer at the onset {fe['run_layers_at_onset']}, FE "
                  f"{o['fe'][-1]['layers'] if o else '-'}", flush=True)
    print(f"{path if recs else dest}: {len(data['cases'])} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
