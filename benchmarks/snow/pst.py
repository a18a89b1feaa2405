"""A full-resolution Propagation Saw Test: fronts, speed profiles, touchdown, collapse.

Runs one PST scene (``pst_flat``, ``pst_slope`` or any PST scenario, with ``--set`` overrides) through
:func:`mpm_warp.run` and writes ``benchmarks/snow/results/snow_<name>.json`` (every scalar of the scene's
result, the speed profiles and front paths of the damage and slab-deflection fronts, the frame
series, the references, the environment and the wall time) and ``snow_<name>.png``:

- the two fronts and the saw against time;
- the local front speeds against the distance from the cut, beside field speeds (20-30 m/s,
  Bergfeld et al. 2021), Heierli's anticrack speed (with the run's own collapse height) and the
  slab's shear and Rayleigh wave speeds;
- the slab base's deflection along the column at a few times while the crack runs, with the
  calibrated collapse height and the measured touchdown distance.

Usage (a long run on the CPU; the run file goes to ``--h5dir``, not to the repository)::

    nohup .venv/bin/python benchmarks/snow/pst.py pst_flat --h5dir /tmp/snow > flat.log 2>&1 &
    .venv/bin/python benchmarks/snow/pst.py --quick     # a small PST, results to a temporary folder
    .venv/bin/python benchmarks/snow/pst.py pst_slope --reanalyse   # no run: see below

``--reanalyse`` re-derives the speed analysis of the committed ``snow_<name>.json`` from the front paths it
stores (:func:`mpm_warp.scenes.pst.analysis.rederive_speeds`), with today's code, and rewrites it and its
figure; the run's own record (environment, wall time, series) stays, and ``reanalysis`` says what was redone.
"""

from __future__ import annotations

import datetime
import json
import math
import os
import sys
import time

import numpy as np

import mpm_warp as mw
from mpm_warp.scenes.front_speed import NUCLEATION
from mpm_warp.scenes.pst.analysis import rederive_speeds
from mpm_warp.scenes.pst.saw import sawn
from mpm_warp.scenes.weak_layer import stored_calibration
from mpm_warp.studies.environment import environment, git_commit, write_json
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parser
from mpm_warp.studies.snow import FIELD_SPEED, ladder_pst

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
#: --quick: the ladder PST at 6 cells across its layer (dx 1 cm) on a 1.5 m column, sawn to 0.5 m, to 0.6 s
QUICK = ladder_pst(0.01) + ["scene.length=1.5", "scene.saw.cut_length=0.5", "time.end=0.6"]
#: why a frame's touchdown is null in the results file
TOUCHDOWN_NULL = "null before the deflection front ran 4 bins beyond the cut (no touchdown yet)"


def _plt():
    plt = pyplot()

    return plt


def deflection_profiles(run, params, times) -> list[dict]:
    """The slab base's downward deflection since the end of settling along the column at ``times`` (s)."""
    x0 = run.static["x0"]
    groups = [g["name"] for g in run.attrs["groups"]]
    slab = np.nonzero(run.static["group"] == groups.index("slab"))[0]
    base = slab[x0[slab, 1] <= x0[slab, 1].min() + 1e-6]
    order = np.argsort(x0[base, 0])
    base = base[order]
    k_ref = int(np.searchsorted(run.times, params.saw_start - 1e-12))
    y_ref = run.frame(k_ref)["x"][base, 1].astype(float)
    out = []
    for t in times:
        k = int(np.argmin(np.abs(run.times - t)))
        y = run.frame(k)["x"][base, 1].astype(float)
        s = params.distance_from_cut_end(x0[base, 0])
        out.append({"t": float(run.times[k]), "s": s.tolist(), "w": (y_ref - y).tolist()})
    return out


def _nan(values) -> list[float]:
    """A results file's list with its nulls as nan (for plotting)."""
    return [math.nan if v is None else float(v) for v in values]


def reanalyse(name: str, folder: str) -> str:
    """Re-derive the speeds of ``RESULTS/snow_<name>.json`` from its stored paths; write it and its figure to
    ``folder``; return the JSON's path (module docstring)."""
    with open(os.path.join(RESULTS, f"snow_{name}.json")) as fh:
        res = json.load(fh)
    sc = mw.load_scenario(res["scenario"], res["overrides"])
    r = res["result"]
    p = sawn(sc.scene, _nan([r.get("saw_stopped_at")])[0])     # a saw stopped on runaway: the cut it made
    stored = (r["cut_length"], r["column_length"], r["shear_wave_speed"])
    today = (float(p.saw.cut_length), float(p.length), p.equivalent_slab().material().s_wave_speed)
    if not all(math.isclose(a, b, rel_tol=1e-9) for a, b in zip(stored, today, strict=True)):
        raise SystemExit(f"{name}: the scenario today ({today}) is not the one run ({stored}): rerun it")
    res["result"] = rederive_speeds(p, r)
    res["series"]["touchdown_null"] = TOUCHDOWN_NULL
    res["reanalysis"] = {"commit": git_commit(), "date": datetime.datetime.now(datetime.timezone.utc).isoformat(
        timespec="seconds"), "command": f"python benchmarks/snow/pst.py {name} --reanalyse",
        "note": "the speeds (profiles, means, largest, jumps) re-derived from the stored front paths; the run "
                "itself is the environment's commit"}
    path = write_json(f"snow_{name}", res, folder, end_load=False)
    figure(res, res["deflection_profiles"], os.path.join(folder, f"snow_{name}.png"))
    return path


def figure(res: dict, profiles: list[dict], path: str) -> None:
    """Fronts against time, speed profiles, deflection profiles (module docstring)."""
    plt = _plt()
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.6))
    t, s = np.asarray(res["times"]), res["series"]
    ax[0].plot(t, s["front"], "-", color="C3", lw=2, label="damage front (bond <= 1/2)")
    ax[0].plot(t, s["deflection_front"], "--", color="C0", lw=1.5, label="slab-deflection front (0.1 h_c)")
    ax[0].plot(t, s["saw"], ":", color="k", lw=1.5, label="saw blade")
    ax[0].set(xlabel="time t [s]", ylabel="distance from the cut end [m]", title="fronts and saw")
    ax[0].legend(fontsize=8)
    r = res["result"]
    for key, style, color, label in (("damage", "o-", "C3", "damage front"),
                                     ("deflection", "s--", "C0", "deflection front")):
        prof = r[f"{key}_speed_profile"]
        ax[1].plot(prof["s"], _nan(prof["speed"]), style, color=color, ms=3, label=label)
        for k, j in enumerate(r.get(f"{key}_jumps") or []):
            ax[1].axvspan(j["start"], j["end"], color=color, alpha=0.15, zorder=0,
                          label=f"{key}: {NUCLEATION} (no speed)" if k == 0 else None)
    ax[1].axhspan(*FIELD_SPEED, color="0.85", label="field 20-30 m/s")
    ax[1].axhline(r["heierli_speed_run"], color="C2", ls="-.",
                  label=f"Heierli, run's h_c: {r['heierli_speed_run']:.3g} m/s")
    ax[1].axhline(r["shear_wave_speed"], color="0.4", ls=":", label=f"slab c_s {r['shear_wave_speed']:.3g} m/s")
    ax[1].axhline(0.6 * r["shear_wave_speed"], color="0.6", ls=":", label="0.6 c_s")
    ax[1].axhline(r["rayleigh_speed"], color="C1", ls=":", label=f"slab Rayleigh c_R {r['rayleigh_speed']:.3g} m/s")
    # up to the end zone (the last slab thickness, where the far end's own failure spoils a speed)
    s_max = r["column_length"] - max(float(res["scene_slab_thickness"]), 0.0)
    top = 1.1 * r["shear_wave_speed"]
    for key in ("damage", "deflection"):
        prof = r[f"{key}_speed_profile"]
        inside = [v for x, v in zip(prof["s"], _nan(prof["speed"]), strict=True) if x <= s_max and math.isfinite(v)]
        if inside:
            top = max(top, min(1.05 * max(inside), 2.0 * r["shear_wave_speed"]))
    ax[1].axvspan(s_max, r["column_length"], color="0.93", zorder=0, label="end zone (one slab thickness)")
    ax[1].set(xlabel="distance from the cut end [m]", ylabel="local front speed [m/s] (0.5 m windows)",
              title="crack speed along the column", ylim=(0, top))
    ax[1].legend(fontsize=7)
    h_c = r["collapse_height_calibrated"]
    for prof in profiles:
        ax[2].plot(prof["s"], 1e3 * np.asarray(prof["w"]), "-", lw=1, label=f"t = {prof['t']:.3f} s")
    ax[2].axhline(1e3 * h_c, color="k", ls="--", lw=1, label=f"calibrated collapse h_c {1e3 * h_c:.2g} mm")
    ax[2].set(xlabel="distance from the cut end [m]", ylabel="slab-base deflection since settling [mm]",
              title=f"slab base (touchdown {r['touchdown']:.3g} m behind the front)")
    ax[2].invert_yaxis()
    ax[2].legend(fontsize=7)
    fig.suptitle(res["description"], fontsize=9)
    save_figure(fig, path)


def main(argv=None) -> int:
    ap = parser(__doc__, "pst_flat as the ladder PST at 6 cells (dx 1 cm) on a 1.5 m column, sawn to 0.5 m, to 0.6 s")
    ap.add_argument("scene", nargs="?", default=None, help="a PST scenario: pst_flat, pst_slope, or a file "
                                                           "(--quick: pst_flat)")
    ap.add_argument("--set", dest="overrides", action="append", default=[], help="scenario override KEY=VALUE")
    ap.add_argument("--name", default=None, help="result name (default: the scenario's name)")
    ap.add_argument("--h5dir", default=os.environ.get("TMPDIR", "/tmp"), help="folder of the run file")
    ap.add_argument("--resume", action="store_true",
                    help="continue an interrupted run of this scene in --h5dir from its checkpoint")
    ap.add_argument("--prior-wall-s", type=float, default=0.0,
                    help="with --resume: wall seconds the interrupted part ran (added to the reported wall time)")
    ap.add_argument("--reanalyse", action="store_true",
                    help="no run: re-derive the speeds of the committed snow_<name>.json from its stored front paths")
    a = ap.parse_args(argv)
    if a.reanalyse:
        if a.scene is None:
            ap.error("--reanalyse needs the scene (pst_flat, pst_slope)")
        print("wrote", reanalyse(a.name or os.path.splitext(os.path.basename(a.scene))[0], out_dir(a, RESULTS, "pst")))
        return 0
    if a.quick:
        a.scene, a.overrides = a.scene or "pst_flat", QUICK + a.overrides
    if a.scene is None:
        ap.error("a PST scenario is needed (or --quick)")
    sc = mw.load_scenario(a.scene, a.overrides)
    name = (a.name or sc.name) + ("_quick" if a.quick else "")
    folder = out_dir(a, RESULTS, "pst")
    os.makedirs(a.h5dir, exist_ok=True)
    h5 = os.path.join(a.h5dir, f"snow_{name}.h5")
    print(stored_calibration(sc).describe(), flush=True)
    t0 = time.perf_counter()
    if a.resume:
        rr = mw.resume(h5, device=a.device)
    else:
        rr = mw.run(sc, h5, device=a.device, overwrite=True)
    wall = time.perf_counter() - t0 + a.prior_wall_s
    mon = rr.monitor
    keep = ("front", "deflection_front", "saw", "collapse_height", "touchdown")
    res = {"name": name, "scenario": a.scene, "scene_slab_thickness": sc.scene.slab_thickness,
           "overrides": a.overrides, "description": sc.description,
           "environment": environment(a.device), "wall_s": wall,
           "resumed": bool(a.resume), "steps": rr.steps, "particles": rr.n_particles,
           "particle_steps_per_s": rr.particle_steps_per_s, "h5": h5,
           "weak_layer": stored_calibration(sc).to_dict(),
           "result": rr.scene_result, "times": list(mon.times),
           "series": {k: list(mon.series[k]) for k in keep}}
    res["series"]["touchdown_null"] = TOUCHDOWN_NULL
    r = rr.scene_result
    # deflection profiles while the crack runs: when the deflection front is at 1/4, 1/2 and 3/4 of its run
    df = np.asarray(mon.series["deflection_front"])
    cut, L = float(sc.scene.saw.cut_length), float(sc.scene.length)
    times = [float(np.asarray(mon.times)[min(int(np.searchsorted(df, cut + f * (L - cut))), len(df) - 1)])
             for f in (0.25, 0.5, 0.75)]
    profiles = deflection_profiles(mw.read_run(h5), sc.scene, times)
    res["deflection_profiles"] = profiles
    print("wrote", write_json(f"snow_{name}", res, folder), flush=True)
    figure(res, profiles, os.path.join(folder, f"snow_{name}.png"))
    print(f"{name}: wall {wall:.0f} s, {rr.steps} steps, {rr.n_particles} particles; propagated {r['propagated']}, "
          f"speed {r['speed']:.3g} m/s (max {r['damage_speed_max']:.3g}), runaway cut {r['runaway_cut']:.3g} m, "
          f"touchdown {r['touchdown']:.3g} m (Heierli {r['heierli_touchdown_run']:.3g}), front agreement "
          f"{r['front_agreement']:.3g}, collapse {1e3 * r['collapse_height']:.3g} mm", flush=True)
    return 0 if math.isfinite(wall) else 1


if __name__ == "__main__":
    sys.exit(main())
