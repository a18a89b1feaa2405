"""Where do the model and the observers disagree, and what do those columns have in common?

Reads a field batch's runs (``field_batch.py --runs RUNDIR``) and the pits they came from, and describes each
scored case by what the observer recorded and what the run did: the slab's bed-normal depth and mean density,
the slope, the cut as a share of the column, where the weak layer's fracture energy came from (read back from
the recorded cut, or the default), the run's runaway cut against the recorded one, and whether the slab
cracked anywhere (its largest effective tensile stress over its strength, from the final checkpoint: ``kappa``,
docs/model.md §9), and whether a static energy balance could stop the crack before the far end: the least of
weac's energy release rate (with touchdown) beyond the recorded cut over the fracture energy the run took, and
what the slab had done at the run's call (``mpm_warp.field.studies.at_call``: its collapse, the share of the crack
it had come down over, the most it carried and how far a crack went through it).
Groups them by observed and predicted class. Nothing here changes the model: it is the
evidence for which physics is missing. Writes ``benchmarks/field/results/field_disagreements.json``.

Usage: ``python benchmarks/field/disagreements.py RUNDIR [RUNDIR ...] --data DIR``  (DIR: the unpacked pits).
``--quick``: the first six cases only.
"""

from __future__ import annotations

import os
import statistics
import sys
import warnings

from mpm_warp.field.batch import gather, run_records
from mpm_warp.field.run_on import scenario_of
from mpm_warp.field.studies.at_call import case_readings, slab_crack_ratio
from mpm_warp.scenes.pst.outcome import FIELD_CLASSES
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def from_checkpoint(run_dir: str, case_id: str, sc) -> tuple[float | None, float | None, str | None]:
    """From the run's final checkpoint: the slab's largest ``kappa / tensile strength`` (>= 1: it cracked
    somewhere), the fastest material's P-wave speed over the slab's fastest (> 1: another material, not the
    slab, sets the time step) and that material's name; Nones without a checkpoint (``sc``: its scenario,
    :func:`scenario_of`)."""
    if sc is None:
        return None, None, None
    c_p = {name: m.p_wave_speed for name, m in sc.materials.items()}
    slab = max((v for k, v in c_p.items() if k.startswith("slab")), default=None)
    dt_ratio = max(c_p.values()) / slab if slab else None
    fastest = max(c_p, key=c_p.get)
    return slab_crack_ratio(run_dir, case_id, sc), dt_ratio, fastest


#: m: the energy balance is read up to this far from the far end (where the cut column's last strip lets go)
FAR_END_M = 0.05
#: cuts at which weac's G is read between the recorded cut and the far end
ENERGY_POINTS = 12


def energy_beyond_cut(sc, rec: dict) -> float | None:
    """The least of weac's G (touchdown on) between the recorded cut and :data:`FAR_END_M` before the far end,
    over the run's fracture energy ``w_f``: below 1, a static energy balance stops the crack there (an ARR that
    needs no dynamics). ``sc``: the case's scenario (:func:`scenario_of`). None without weac or a checkpoint, or
    when the cut is within that distance of the end."""
    import numpy as np

    from mpm_warp.scenes.pst.static import static_column
    from mpm_warp.scenes.weac_reference import energy_release_rate, weac_unavailable

    if weac_unavailable() is not None or sc is None:
        return None
    col = static_column(sc.scene)
    if rec["recorded_cut"] >= col.length - FAR_END_M:
        return None
    cuts = np.linspace(rec["recorded_cut"], col.length - FAR_END_M, ENERGY_POINTS)
    return min(energy_release_rate(col, float(a), touchdown=True)[0] for a in cuts) / rec["w_f"]


def describe(rec: dict, case, run_dir: str) -> dict:
    """One scored case: the observer's column and the run's outcome."""
    p, slab = case.params, case.column.slab
    depth = sum(ly.thickness for ly in slab)
    sc = scenario_of(run_dir, rec["id"])
    crack, dt_ratio, fastest = from_checkpoint(run_dir, rec["id"], sc)
    return {"id": rec["id"], "test": rec["test"], "observed": rec["observed"], "predicted": rec["predicted"],
            "static_class": rec.get("static_class"), "slab_depth_m": p.slab_depth,
            "slab_density": sum(ly.thickness * ly.density for ly in slab) / depth, "slope_deg": p.slope_angle,
            "column_m": p.length, "cut_share": rec["recorded_cut"] / p.length, "column_ends": p.column_ends,
            "w_f": rec["w_f"], "w_f_read_back": rec.get("w_f_source") == "read back",
            "recorded_cut": rec["recorded_cut"], "runaway_cut": rec.get("runaway_cut"),
            "slab_fracture_at": rec.get("slab_fracture_at"), "slab_crack_ratio": crack,
            "energy_beyond_cut": energy_beyond_cut(sc, rec),
            "substratum_share": p.substratum_depth / (p.slab_depth + p.weak_layer_thickness + p.substratum_depth),
            "c_p_over_slab": dt_ratio, "fastest_material": fastest,
            "rigid_base": bool(sc.scene.rigid_base) if sc is not None else None,
            "particles": rec.get("particles"), "steps": rec.get("steps"),
            "wall_s": rec.get("wall_s"), **case_readings(run_dir, rec["id"], sc)}


def _median(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def group(rows: list[dict]) -> dict:
    """Counts and medians of one group of cases."""
    ratio = [r["runaway_cut"] / r["recorded_cut"] for r in rows if r["runaway_cut"] and r["w_f_read_back"]]
    cracked = [r for r in rows if r["slab_crack_ratio"] is not None]
    energy = [r["energy_beyond_cut"] for r in rows if r.get("energy_beyond_cut") is not None]
    return {"cases": len(rows), "slab_depth_m": _median([r["slab_depth_m"] for r in rows]),
            "slab_density": _median([r["slab_density"] for r in rows]),
            "slope_deg": _median([r["slope_deg"] for r in rows]), "cut_share": _median([r["cut_share"] for r in rows]),
            "w_f_read_back": sum(r["w_f_read_back"] for r in rows),
            "runaway_over_recorded": _median(ratio), "runaway_over_recorded_cases": len(ratio),
            "slab_cracked": sum(r["slab_crack_ratio"] >= 1.0 for r in cracked), "slab_checked": len(cracked),
            "weac_static_SF": sum(r["static_class"] == "SF" for r in rows),
            "energy_stops": sum(e < 1.0 - 1e-6 for e in energy), "energy_checked": len(energy)}


def cost(rows: list[dict]) -> dict:
    """Where the cases' time goes that the column, not the physics of the crack, decides: the substratum's share
    of the column and whether its P-wave speed (above the slab's) sets the time step."""
    faster = [r["c_p_over_slab"] for r in rows if r["c_p_over_slab"] is not None and r["c_p_over_slab"] > 1.0 + 1e-9]
    return {"cases": len(rows), "substratum_share_median": _median([r["substratum_share"] for r in rows]),
            "substratum_share_range": [min(r["substratum_share"] for r in rows),
                                       max(r["substratum_share"] for r in rows)] if rows else None,
            "substratum_sets_dt": len(faster), "c_p_over_slab_median_there": _median(faster),
            "c_p_over_slab_max": max(faster, default=None),
            "rigid_base": sum(bool(r.get("rigid_base")) for r in rows),
            "faster_materials": sorted({r["fastest_material"].rstrip("_0123456789") for r in rows
                                        if r.get("fastest_material") and r["c_p_over_slab"] is not None
                                        and r["c_p_over_slab"] > 1.0 + 1e-9})}


def main(argv=None) -> int:
    p = parser(__doc__, "the first six cases")
    p.add_argument("runs", nargs="+", help="field batches' runs folders (field_batch.py --runs)")
    p.add_argument("--data", required=True, help="folder of CAAML files the batches read")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    recs = [{**r, "run_dir": run_dir} for r, run_dir in run_records(args.runs) if r.get("observed")]
    recs = recs[:6] if args.quick else recs
    cases, _ = gather([os.path.join(args.data, p) for p in sorted({r["pit"] for r in recs})], calibrate=False)
    by = {(c.pit, c.test): c for c in cases}
    rows = [describe(r, by[(r["pit"], r["test"])], r["run_dir"]) for r in recs if (r["pit"], r["test"]) in by]
    classes = FIELD_CLASSES
    data = {"name": "field_disagreements", "runs": [os.path.basename(os.path.normpath(d)) for d in args.runs],
            "data": os.path.basename(os.path.normpath(args.data)), "environment": environment("cpu"),
            "by_observed": {c: group([r for r in rows if r["observed"] == c]) for c in classes},
            "by_pair": {f"{o}->{q}": group(g) for o in classes for q in sorted({r["predicted"] for r in rows})
                        if (g := [r for r in rows if r["observed"] == o and r["predicted"] == q])},
            "cost": cost(rows), "cases": rows}
    path = write_json("field_disagreements", data, out_dir(args, RESULTS, "field_disagreements"))
    print(f"{path}: {len(rows)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
