"""Is a field run's slab stress, or weac's, nearer a resolved continuum? A static plane-strain FE of the same columns.

For every case of the slab-stress studies (``slab_stress.py``'s JSONs: the SF records the model called END, a
sample of END records), the column the run used (its checkpoint's scenario, as weac sees it: each layer's E, the
weak layer's E, the slope, the ends) is solved statically at the crack's onset cut by a 9-node plane-strain FE
(``mpm_warp.validation.column_fe``) that resolves every slab layer, at two meshes (1 cm and 5 mm elements, two
at least through every layer). Per case: the slab's largest principal stress over its layer's strength, away
from the corner where the sawn weak layer ends and from the end faces (within ``CORNER_M`` of them linear
elasticity is singular; that zone's value is given apart), where it sits, and beside it weac's
(over the cut and at the tip) and the run's up to the onset (its whole slab, edges included). The homogeneous
control (20 cm of 120 kg/m^3, flat) is solved at the same cuts as ``slab_stress.py``'s. Static: no saw, no
dynamics, no damage. Writes ``benchmarks/field/results/field_slab_fe.json``.

Usage: ``python benchmarks/field/slab_fe.py RUNDIR [RUNDIR ...] [--studies JSON ...]``; ``--quick``: the control
at one cut and the first case, coarse, to a temporary folder. Seconds to a minute a case.
"""

from __future__ import annotations

import json
import os
import sys
import warnings

from mpm_warp.field.batch import run_records
from mpm_warp.field.studies.slab_fe import CORNER_M, MESHES, compare, fe_row
from mpm_warp.field.studies.slab_stress import control_params
from mpm_warp.scenes.pst.static import static_column
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
STUDIES = (os.path.join(RESULTS, "field_slab_stress.json"), os.path.join(RESULTS, "end", "field_slab_stress.json"))


def control(study: dict, meshes) -> dict:
    """The homogeneous control of ``slab_stress.py`` (its cuts and its run's values) solved by the FE."""
    p = control_params()
    col, strengths = static_column(p), [ly.strength for ly in p.slab_stack()]
    rows = [{**compare(col, strengths, row["cut"], meshes), "run": row["run"]} for row in study["control"]["rows"]]
    return {"what": study["control"]["what"], "slab_depth_m": study["control"]["slab_depth_m"], "rows": rows}


def main(argv=None) -> int:
    p = parser(__doc__, "the control at one cut and the first case, coarse")
    p.add_argument("runs", nargs="+", help="field batches' runs folders (field_batch.py --runs)")
    p.add_argument("--studies", nargs="+", default=list(STUDIES), help="slab_stress.py JSONs (default: both committed)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    meshes = MESHES[:1] if args.quick else MESHES
    dest = out_dir(args, RESULTS, "field_slab_fe")
    where = {r["id"]: d for r, d in run_records(args.runs)}
    studies = [json.load(open(s)) for s in args.studies]
    data = {"name": "field_slab_fe", "studies": [os.path.relpath(s, HERE) for s in args.studies],
            "corner_m": CORNER_M, "meshes_m": list(meshes), "environment": environment("cpu")}
    ctl = next((s for s in studies if "control" in s), None)
    if ctl is not None:
        if args.quick:
            ctl = {**ctl, "control": {**ctl["control"], "rows": ctl["control"]["rows"][-1:]}}
        data["control"] = control(ctl, meshes)
        print("control: " + ", ".join(f"{r['cut']:g} m: FE {r['fe'][-1]['peak']:.3f}, weac {r['weac']['peak']:.3f}, "
                                      f"run {r['run']:.3f}" for r in data["control"]["rows"]), flush=True)
    cases = [(c, s.get("selection", {"observed": "SF", "predicted": "END"})) for s in studies for c in s["cases"]]
    missing = [c["id"] for c, _ in cases if c["id"] not in where]
    if missing:
        print(f"error: runs: the runs of {len(missing)} cases are not in {args.runs} (e.g. {missing[0]})",
              file=sys.stderr)
        return 2
    data["cases"] = []
    for c, sel in cases[:1] if args.quick else cases:
        row = {**fe_row(c, where[c["id"]], meshes), "selection": sel}
        data["cases"].append(row)
        path = write_json("field_slab_fe", data, dest)
        o = row.get("at_onset")
        print(f"{row['test']} ({row['observed']}): at the onset {row['onset_cut']} m FE "
              f"{o['fe'][-1]['peak']:.2f}, weac {o['weac']['peak']:.2f}, run {row['run_to_onset']:.2f}"
              if o else f"{row['test']}: no onset", flush=True)
    path = write_json("field_slab_fe", data, dest)
    print(f"{path}: {len(data['cases'])} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
