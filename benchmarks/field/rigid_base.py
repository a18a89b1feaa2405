"""What does a rigid base under the weak layer change in a field case? The same columns, without their old snow.

The field protocol ran each column on the profile's old snow (the substratum) until it moved to a rigid base, the
column weac reads the fracture energy back with (``scene.rigid_base``, docs/field.md). This study takes the
finished cases of earlier batches (their runs folders, run on the old snow), chooses the ``--cases`` cheapest
ones (their wall time, then their id: a choice that does not depend on the outcome, but favours small columns),
and runs each again from its checkpoint's scenario with the substratum replaced by the rigid base and nothing else
changed: the grid, the saw, the weak layer's calibration and fracture energy, the end of the run. Per case: the
predicted class, the runaway cut, where the slab broke, particles, steps and wall time on both bases, and the
substratum's compliance over the weak layer's (``sum d / M`` of its layers over ``D_wl / M_wl``, M the constrained
modulus), which is what a rigid base leaves out. Writes ``benchmarks/field/results/field_rigid_base.json``.

Usage: ``python benchmarks/field/rigid_base.py RUNDIR [RUNDIR ...] [--cases N]``; ``--quick``: the cheapest case,
to a temporary folder. A minute or two a case on one thread.
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
from mpm_warp.scenes.pst import PSTParams, build
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
#: what each run reports, on either base
KEYS = ("predicted", "runaway_cut", "slab_fracture_at", "particles", "steps", "wall_s", "sim_time")


def constrained_modulus(E: float, nu: float) -> float:
    """Constrained (oedometric) modulus (Pa) of Young's modulus ``E`` (Pa) and Poisson's ratio ``nu``."""
    return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))


def compliance_ratio(p: PSTParams) -> float:
    """The substratum's compliance under a normal load over the weak layer's (-): ``sum d / M`` over ``D_wl / M``."""
    sub = sum(ly.thickness / constrained_modulus(ly.modulus, ly.nu) for ly in p.substratum_stack())
    return sub / (p.weak_layer_thickness / constrained_modulus(p.weak_layer.E, p.weak_layer.nu))


def on_rigid_base(p: PSTParams) -> PSTParams:
    """``p`` with its substratum replaced by the rigid base, and nothing else changed."""
    bare = PSTParams()
    return dataclasses.replace(p, rigid_base=True, substratum_layers=(), substratum=bare.substratum,
                               substratum_thickness=bare.substratum_thickness)


def rerun(rec: dict, run_dir: str, folder: str) -> dict:
    """The case ``rec`` of ``run_dir`` again on a rigid base, its run file in ``folder``: the row of both runs."""
    ck = os.path.join(run_dir, rec["id"] + ".ckpt.h5")
    sc = resolved_scenario(read_checkpoint_meta(ck)["scenario"], source=ck)
    scenario = build(on_rigid_base(sc.scene), TimeControl(end=sc.time.end, frame_interval=sc.time.frame_interval),
                     name="field")
    t0 = time.perf_counter()
    rigid = run_until_decided(scenario, os.path.join(folder, rec["id"] + ".h5"), 1)
    return {"id": rec["id"], "test": rec["test"], "observed": rec["observed"], "setup": rec["setup"],
            "compliance_ratio": compliance_ratio(sc.scene), "substratum_m": sc.scene.substratum_depth,
            "substratum": {k: rec.get(k) for k in KEYS}, "rigid": rigid, "case_wall_s": time.perf_counter() - t0}


def main(argv=None) -> int:
    ap = parser(__doc__, "the cheapest case, to a temporary folder")
    ap.add_argument("runs", nargs="+", help="runs folders of earlier field batches (run on the old snow)")
    ap.add_argument("--cases", type=int, default=15, help="how many of the cheapest finished cases (default 15)")
    a = ap.parse_args(argv)
    warnings.filterwarnings("ignore")
    recs = [(r, d) for r, d in run_records(a.runs) if os.path.exists(os.path.join(d, r["id"] + ".ckpt.h5"))
            and "rigid base" not in r.get("setup", "")]
    recs.sort(key=lambda rd: (rd[0]["wall_s"], rd[0]["id"]))
    chosen = recs[:1 if a.quick else a.cases]
    folder = out_dir(a, RESULTS, "rigid_base")
    runs = tempfile.mkdtemp(prefix="mpm_warp_rigid_base_")
    cases = []
    for k, (rec, d) in enumerate(chosen):
        cases.append(rerun(rec, d, runs))
        c = cases[-1]
        print(f"[{k + 1}/{len(chosen)}] {c['test']}: {c['substratum']['predicted']} -> {c['rigid']['predicted']}, "
              f"{c['substratum']['wall_s']:.0f} s -> {c['rigid']['wall_s']:.0f} s", flush=True)
    data = {"name": "field_rigid_base", "runs": [os.path.basename(os.path.normpath(r)) for r in a.runs],
            "chosen": f"the {len(chosen)} cheapest of {len(recs)} finished cases (their wall time on the old snow)",
            "cases": cases, "environment": environment("cpu")}
    print("wrote", write_json("field_rigid_base", data, folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
