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

import dataclasses
import json
import os
import random
import sys
import tempfile
import time
import warnings

import h5py
import numpy as np

from mpm_warp.config import TimeControl
from mpm_warp.field.batch import run_records
from mpm_warp.field.protocol import decided
from mpm_warp.io.checkpoint import read_checkpoint_meta
from mpm_warp.loader import resolved_scenario
from mpm_warp.runner import run
from mpm_warp.scenes.pst import PSTParams, build
from mpm_warp.scenes.pst.saw import Saw
from mpm_warp.scenes.pst.static import static_column
from mpm_warp.scenes.snowpack import SnowLayer
from mpm_warp.scenes.weac_reference import slab_stress
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")

#: the crack has started once the damage front leads the blade by this many grid cells
ONSET_CELLS = 2.0

#: the control: a homogeneous soft slab (20 cm of 120 kg/m^3, E and strength from density) on flat ground, sawn
#: at 1 m/s from the upslope end to 0.36 m (weac's critical cut 0.40 m): the run's slab stress against weac's
#: beam where the beam is exact, before the crack starts
CONTROL_CUTS = (0.1, 0.15, 0.2, 0.25, 0.3)


def principal_2d(stress: np.ndarray) -> np.ndarray:
    """Largest in-plane principal stress (Pa) of Cauchy stresses ``(n, 3, 3)`` (plane strain: the in-plane block)."""
    a, b, c = stress[:, 0, 0], stress[:, 1, 1], stress[:, 0, 1]
    return 0.5 * (a + b) + np.sqrt(0.25 * (a - b) ** 2 + c * c)


def run_series(scenario, path: str, threads: int) -> dict:
    """Run ``scenario`` with stress frames into ``path``; per frame the blade, the front, each slab layer's peak
    ratio (top to bottom) and where the slab's largest ratio sits: ``peak_at`` = [x0 (m along the column, at
    the start), depth below the slab's surface (m, at the start), sigma_xx (along the bed), sigma_yy (normal to
    it), sigma_xy (Pa)]."""
    sc = dataclasses.replace(scenario, output=dataclasses.replace(scenario.output, fields=("x", "stress")))
    t0 = time.perf_counter()
    res = run(sc, path, device="cpu", overwrite=True, n_threads=threads, callback=lambda sim, frame: not decided(sim))
    wall = time.perf_counter() - t0
    slabs = sorted((n for n in sc.materials if n.startswith("slab")),     # "slab", or "slab_1" (top) to "slab_N"
                   key=lambda n: int(n.rsplit("_", 1)[-1]) if "_" in n else 0)
    with h5py.File(path, "r") as f:
        groups = [g["name"] if isinstance(g, dict) else g for g in json.loads(f.attrs["groups"])]
        member, x0 = f["static/group"][:], f["static/x0"][:]
        slab = np.isin(member, [groups.index(n) for n in slabs])
        strength = np.zeros(member.size)
        for name in slabs:
            strength[member == groups.index(name)] = sc.materials[name].tensile_strength
        top = x0[slab, 1].max()
        ratio = np.empty((f["time"].shape[0], len(slabs)))
        peak_at = []
        for k in range(ratio.shape[0]):
            stress = f["particles/stress"][k]
            s1 = principal_2d(stress)
            for j, name in enumerate(slabs):
                ratio[k, j] = s1[member == groups.index(name)].max() / sc.materials[name].tensile_strength
            i = np.flatnonzero(slab)[np.argmax(s1[slab] / strength[slab])]
            sig = stress[i]
            peak_at.append([float(x0[i, 0]), float(top - x0[i, 1]), float(sig[0, 0]), float(sig[1, 1]),
                            float(sig[0, 1])])
        series = {"t": f["time"][:].tolist(), "saw": f["scalars/saw"][:].tolist(),
                  "front": f["scalars/front"][:].tolist(), "ratio": ratio.tolist(),
                  "peak_at": peak_at}
    o = res.scene_result.get("outcome", {})
    return {"series": series, "layers": slabs, "predicted": o.get("class"), "wall_s": wall}


def control(tmp: str, threads: int) -> dict:
    """The homogeneous control (:data:`CONTROL_CUTS`): per cut, the run's slab stress over strength while the blade
    had cut at most that much, and weac's over the cut there."""
    p = PSTParams(length=2.0, slab_layers=(SnowLayer(0.2, 120.0),), slab_fracture=True,
                  saw=Saw(cut_length=0.36, speed=1.0))
    p = dataclasses.replace(p, weak_layer=dataclasses.replace(p.weak_layer, tau_p=700.0, h_c=0.006))
    sc = build(p.validate("scene"), TimeControl(end=p.saw_start + 0.36, frame_interval=0.005), name="control")
    out = run_series(sc, os.path.join(tmp, "control.h5"), threads)
    rows = [{"cut": cut, "run": mpm_ratio_to(out["series"], cut), "weac": weac_ratios(sc.scene, cut)["over_cut"]}
            for cut in CONTROL_CUTS]
    return {"what": "20 cm of 120 kg/m^3 on flat ground, 2 m column, sawn to 0.36 m", "dx": p.dx,
            "slab_depth_m": p.slab_depth,
            "rows": rows, "wall_s": out["wall_s"]}


def onset_cut(series: dict, dx: float) -> float | None:
    """The blade's position (m) at the first frame the damage front leads it by :data:`ONSET_CELLS` cells."""
    for saw, front in zip(series["saw"], series["front"], strict=True):
        if front - saw >= ONSET_CELLS * dx:
            return float(saw)
    return None


def weac_ratios(params, cut: float) -> dict:
    """weac's static slab stress over strength at ``cut`` (m): over the cut, and at the crack tip."""
    strengths = [ly.strength for ly in params.slab_stack()]
    st = slab_stress(static_column(params), cut, strengths, dx=0.005, dz=0.002)
    over = st["ratio"][:, st["cracked"]]
    tip = st["ratio"][:, np.isclose(st["x"], cut, rtol=0.0, atol=1e-9)]
    return {"cut": cut, "over_cut": float(over.max()) if over.size else None, "tip": float(tip.max()),
            "peak_layer": int(st["peak_ratio_layer"])}


def mpm_ratio_to(series: dict, cut: float) -> float | None:
    """The run's largest slab stress over strength (any layer) while the blade had cut at most ``cut`` (m)."""
    r = [max(row) for saw, row in zip(series["saw"], series["ratio"], strict=True) if saw <= cut + 1e-9]
    return max(r) if r else None


def case_row(rec: dict, run_dir: str, tmp: str, threads: int, closure: bool | None = None) -> dict:
    ck = os.path.join(run_dir, rec["id"] + ".ckpt.h5")
    sc = resolved_scenario(read_checkpoint_meta(ck)["scenario"], source=ck)
    if closure is not None and closure != sc.scene.interface_closure:      # the same column, the closure switched
        sc = build(dataclasses.replace(sc.scene, interface_closure=closure),
                   TimeControl(end=sc.time.end, frame_interval=sc.time.frame_interval), name="field")
    p = sc.scene
    out = run_series(sc, os.path.join(tmp, rec["id"] + ".h5"), threads)
    s, onset = out["series"], onset_cut(out["series"], p.dx)
    layers = [{"thickness_m": ly.thickness, "density": ly.density, "cells": ly.thickness / p.dx,
               "tensile_strength": ly.strength, "peak_ratio": max(row[j] for row in s["ratio"])}
              for j, ly in enumerate(p.slab_stack())]
    peak_frame = int(np.argmax([max(row) for row in s["ratio"]]))
    return {"id": rec["id"], "test": rec["test"], "observed": rec["observed"], "predicted_batch": rec["predicted"],
            "peak_at": s["peak_at"][peak_frame],
            "predicted": out["predicted"], "interface_closure": p.interface_closure,
            "slope_deg": p.slope_angle, "dx": p.dx, "slab_depth_m": p.slab_depth,
            "recorded_cut": rec["recorded_cut"],
            "onset_cut": onset, "runaway_cut": rec.get("runaway_cut"), "layers": layers,
            "mpm_peak_ratio": max(max(row) for row in s["ratio"]),
            "mpm_ratio_to_recorded_cut": mpm_ratio_to(s, rec["recorded_cut"]),
            "mpm_ratio_to_onset": mpm_ratio_to(s, onset) if onset is not None else None,
            "weac_at_recorded_cut": weac_ratios(p, rec["recorded_cut"]),
            "weac_at_onset": weac_ratios(p, onset) if onset else None,
            "wall_s": out["wall_s"], "series": s}


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
            row = case_row(r, run_dir, tmp, args.threads, closure)
            data["cases"].append(row)
            path = write_json("field_slab_stress", data, dest)          # after every case
            print(f"{r['test']}: MPM peak {row['mpm_peak_ratio']:.2f} of strength; weac at the recorded cut "
                  f"{row['weac_at_recorded_cut']['over_cut']:.2f} over the cut, "
                  f"{row['weac_at_recorded_cut']['tip']:.2f} at the tip", flush=True)
    print(f"{path if recs else dest}: {len(data['cases'])} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
