"""A PST ends as the field writes it: one column per outcome, END, SF and ARR, with the slab that can break.

Three columns with realistic field parameters (``pst_demo``'s snow unless said, ``scene.slab_fracture`` on,
tensile strength and fracture energy from each layer's density, docs/model.md §9):

- ``SF``: a soft, thin slab, 20 cm of new snow (120 kg/m^3, E 0.85 MPa from the density, tensile strength
  1.7 kPa), on a weak layer of 700 Pa shear strength that collapses by a fifth (6 mm of its 3 cm, the "about
  20 %" of Gaume et al. 2018's shear test), a 2 m column sawn to 0.6 m: the slab breaks;
- ``END``: ``pst_demo`` itself (0.3 m slab of 250 kg/m^3 at 5 MPa, tensile strength 10 kPa, a 2.5 m
  column sawn to 0.6 m): the crack reaches the far end;
- ``ARR``: the same slab on a tougher weak layer (fracture energy 1.2 J/m^2, the upper part of the field's
  0.1-1.7 J/m^2) sawn to 0.8 m: the crack runs beyond the saw and stops.

For the SF column the slab's break position is compared with where weac's static solution of the same
column at the same cut (the saw's position when the slab broke) puts the slab's largest tensile stress
(:func:`mpm_warp.scenes.weac_reference.slab_stress`); for the ARR column, weac's energy release rate with
touchdown along the crack's path from the saw on (does a static balance with the slab resting on the
collapsed layer stop the crack, and where). Writes ``results/pst_outcomes.json`` and one picture
per column, ``results/pst_outcome_<class>.png`` (:func:`mpm_warp.post.pst_picture.pst_picture`).

Usage::

    python benchmarks/snow/pst_outcomes.py            # the three columns (about 40 min on 2 cores)
    python benchmarks/snow/pst_outcomes.py SF         # one of them
    python benchmarks/snow/pst_outcomes.py --quick    # a 0.8 m SF column (12 cm slab) in about a minute
"""

from __future__ import annotations

import dataclasses
import os
import sys
import time

import numpy as np

import mpm_warp as mw
from mpm_warp.finite_json import load_json
from mpm_warp.post.pst_picture import pst_picture
from mpm_warp.scenes.pst.static import static_column
from mpm_warp.scenes.snowpack import SnowLayer
from mpm_warp.scenes.weac_reference import energy_release_rate, slab_stress, weac_unavailable
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parse_cases, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
OUT = "pst_outcomes"
FIELDS = "output.fields=['x','log_jp','damage']"
#: the columns: (overrides of pst_demo, slab layers replacing its slab or None, what the case stands for)
CASES = {
    "SF": (["scene.length=2.0", "scene.saw.cut_length=0.6", "scene.weak_layer.tau_p=700", "scene.weak_layer.h_c=0.006",
            "time.end=0.9"],
           (SnowLayer(0.2, 120.0),), "soft, thin slab: 20 cm of new snow, 120 kg/m^3"),
    "END": (["time.end=0.9"], None, "pst_demo's stiff slab: 0.3 m of 250 kg/m^3 at 5 MPa"),
    "ARR": (["scene.weak_layer.w_f=1.2", "scene.saw.cut_length=0.8", "time.end=1.1"], None,
            "pst_demo's slab on a tougher weak layer (w_f 1.2 J/m^2)"),
}
QUICK = (["scene.dx=0.01", "scene.weak_layer_thickness=0.04", "scene.substratum_thickness=0.05", "scene.length=0.8",
          "scene.saw.cut_length=0.5", "time.end=0.7", "scene.weak_layer.h_c=0.008"], (SnowLayer(0.12, 120.0),),
         "a 0.8 m column, 12 cm slab on a 4 cm layer collapsing by 8 mm")


def scenario(overrides, layers) -> mw.Scenario:
    """``pst_demo`` with the overrides, the slab that can break and, given ``layers``, a layered slab."""
    sc = mw.load_scenario("pst_demo", [*overrides, "scene.slab_fracture=true", FIELDS])
    if layers is None:
        return sc
    defaults = mw.scenes.pst.PSTParams()
    p = dataclasses.replace(sc.scene, slab=defaults.slab, slab_thickness=defaults.slab_thickness,
                            slab_layers=tuple(layers))
    return mw.scenes.pst.build(p, sc.time, sc.output, name=sc.name, precision=sc.precision)


def weac_break(sc: mw.Scenario, outcome: dict, times, saw) -> dict:
    """weac's largest slab tensile stress for the same column at the saw's position when the slab broke."""
    if weac_unavailable() is not None:
        return {"weac": None, "note": weac_unavailable()}
    k = min(int((abs(times - outcome["slab_fracture_time"])).argmin()), len(saw) - 1)
    cut = float(saw[k])
    p = sc.scene
    st = slab_stress(static_column(p), cut, [ly.strength for ly in p.slab_stack()])
    return {"cut": cut, "peak_stress": st["peak_sigma_1"], "peak_at": st["peak_x"], "peak_depth": st["peak_depth"],
            "peak_over_strength": st["peak_ratio"], "peak_over_strength_at": st["peak_ratio_x"],
            "peak_over_strength_depth": st["peak_ratio_depth"], "mpm_break_at": outcome["slab_fracture_at"],
            "note": "x from the cut end (m), depth below the slab surface (m); weac's cut part carries no springs "
                    "(docs/weac.md)"}


def weac_touchdown(sc: mw.Scenario, outcome: dict, step: float = 0.05) -> dict:
    """weac's G with touchdown along the crack's path, from the saw's cut to near the far end: where, if anywhere,
    a static energy balance with the slab resting on the collapsed layer stops the crack (G < G_c = w_f)."""
    if weac_unavailable() is not None:
        return {"weac": None, "note": weac_unavailable()}
    p = sc.scene
    col, G_c, L = static_column(p), float(p.weak_layer.w_f), float(p.length)
    cuts = sorted({round(float(a), 6) for a in np.arange(outcome["cut"], 0.96 * L, step)} | {outcome["arrest_at"]})
    G = [energy_release_rate(col, a, touchdown=True)[0] for a in cuts]
    k = int(np.argmin(G))
    stop = next((a for a, g in zip(cuts, G, strict=True) if g < G_c), None)
    return {"G_c": G_c, "cuts": cuts, "G": G, "G_min": G[k], "G_min_at": cuts[k],
            "G_at_arrest": G[cuts.index(outcome["arrest_at"])], "arrest_at": stop,
            "note": "weac's differential G (J/m^2) with touchdown (weac's collapse height) at cuts (m) from the cut "
                    "end; arrest_at: the first cut past the saw where G < G_c, None if G stays above it"}


def run_case(name: str, folder: str, device: str) -> dict:
    overrides, layers, what = QUICK if name == "quick" else CASES[name]
    sc = scenario(overrides, layers)
    path = os.path.join(folder, f"pst_outcome_{name.lower()}.h5")
    if os.path.exists(path):
        os.remove(path)
    t0 = time.perf_counter()
    res = mw.run(sc, output=path, device=device)
    wall = time.perf_counter() - t0
    o = res.scene_result["outcome"]
    run = mw.read_run(path)
    frame = None if o["class"] == "END" else run.n_frames - 1
    png = pst_picture(run, os.path.join(folder, f"pst_outcome_{name.lower()}.png"), frame=frame)
    out = {"what": what, "overrides": overrides,
           "slab_layers": [dataclasses.asdict(ly) for ly in sc.scene.slab_stack()],
           "slab_strengths": [ly.strength for ly in sc.scene.slab_stack()],
           "slab_fracture_energies": [ly.toughness_energy for ly in sc.scene.slab_stack()],
           "outcome": o, "runaway_cut": res.scene_result["runaway_cut"],
           "damage_front_final": res.scene_result["damage_front_final"], "weac": res.scene_result["weac"],
           "wall_s": wall, "particles": res.n_particles, "steps": res.steps, "picture": os.path.basename(png),
           "environment": environment(device)}
    if o["class"] == "SF":
        out["weac_slab_stress"] = weac_break(sc, o, run.times, run.scalars["saw"])
    if o["class"] == "ARR" and o.get("arrest_at") is not None:
        out["weac_touchdown"] = weac_touchdown(sc, o)
    os.remove(path)          # the run file is large; the picture and the JSON are what the results keep
    print(f"{name}: {o['field_line']} ({wall:.0f} s); {o.get('note', '')}", flush=True)
    return out


def main(argv=None) -> int:
    ap = parser(__doc__, "a 0.8 m column with a 12 cm soft slab: SF")
    a = parse_cases(ap, argv, CASES)
    names = ["quick"] if a.quick else (a.cases or list(CASES))
    folder = out_dir(a, RESULTS, "pst_outcomes")
    data = {"cases": {}}
    old = os.path.join(folder, OUT + ".json")
    if os.path.isfile(old) and not a.quick:
        with open(old) as fh:
            data = load_json(fh)
    for name in names:
        data["cases"][name] = run_case(name, folder, a.device)
        print("wrote", write_json(OUT, data, folder), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
