"""Sections of the snow studies on the stress at the weak layer's interfaces: the rows beside a stiffness jump,
with and without the laminate closure (and the PST ladder off and on it), and the shear test's free ends.

They follow the ladder PST's sections of :mod:`.snow_studies` on the snow page.
"""

from __future__ import annotations

from .core import section
from .fmt import DASH, check_line, env_note, finite, fx, pct, secs, spct, table


def _edge(r: dict, group: str, k: int):
    """The ``k``-th row (from the bottom; -1: the top) of ``group`` among a run's rows near the layer."""
    rows = [x for x in r.get("near") or [] if x["group"] == group]
    return rows[k]["ratio"] if rows else None


@section("snow", "Stress at the weak layer's interfaces", "snow/results/interface_stress_cpu.json",
         "python benchmarks/snow/interface_stress.py", figure="snow/results/interface_stress_cpu.png",
         follows="weac's static answers for the ladder PST",
         question="How much load do the rows next to a stiffness jump carry, with and without the laminate closure "
                  "(`scene.interface_closure`, docs/model.md §5b)?")
def render_interface_stress(data: dict, ctx) -> list[str]:
    out = []
    col = data.get("column")
    if col:
        rows = []
        for a, b in zip(col["off"], col["on"], strict=True):
            rows.append([fx(a["cells"], 0), fx(a["dx"], 2, 1e3), pct(a["worst"]), pct(b["worst"]),
                         f"{fx(_edge(a, 'weak_layer', 0))} / {fx(_edge(b, 'weak_layer', 0))}",
                         f"{fx(_edge(a, 'weak_layer', -1))} / {fx(_edge(b, 'weak_layer', -1))}",
                         f"{fx(_edge(a, 'substratum', -1))} / {fx(_edge(b, 'substratum', -1))}",
                         f"{fx(_edge(a, 'slab', 0))} / {fx(_edge(b, 'slab', 0))}",
                         f"{secs(a['wall_s'])} / {secs(b['wall_s'])}"])
        out += ["The settled column: `pst_demo`'s substratum, 3 cm weak layer and slab between slip walls, settled as "
                "the PST settles; per particle row `sigma_yy` over the overburden at its height (rows within 3 cells "
                "of the layer; off / on the closure):", ""]
        out += table(["cells across the layer", "dx (mm)", "worst row, off", "worst row, on",
                      "layer's bottom row", "layer's top row", "substratum's top row", "slab's bottom row",
                      "wall time, off / on"], rows)
        ok = all(r["worst"] < data.get("tolerance", 0.05) for r in col["on"])
        out += ["", env_note(col), "",
                check_line("rows against the overburden, with the closure", f"every row within "
                           f"{pct(data.get('tolerance', 0.05), 0)} of the overburden at every resolution", ok,
                           f"worst {pct(max(r['worst'] for r in col['on']))}"),
                "- Without the closure the worst row is "
                + ", ".join(pct(r["worst"], 0) for r in col["off"]) + " off at "
                + ", ".join(fx(r["cells"], 0) for r in col["off"]) + " cells: the artefact does not shrink with "
                "dx, it covers fewer rows.", ""]
    m1 = data.get("model1d")
    if m1:
        schemes = [k for k in ("none", "bbar", "closure") if k in m1]
        label = {"none": "plain MLS-MPM", "bbar": "B-bar-like (per cell and layer)", "closure": "laminate closure"}
        rows = [[label[k]] + [pct(r["worst"]) + (f" ({r['zero_energy_modes']} zero-energy mode)"
                                                 if r.get("zero_energy_modes") else "") for r in m1[k]]
                for k in schemes]
        out += ["The same column as a 1D static problem (`mpm_warp.studies.interface_model1d`; the stencil's own "
                "answer, the 2D column's to about 1 %): the worst row for each candidate:", ""]
        out += table(["scheme"] + [f"{fx(r['cells'], 0)} cells" for r in m1[schemes[0]]], rows)
        out += ["", "At 4 cells the layer's interfaces fall inside grid cells (the 10 cm substratum is 13.3 cells); "
                "at 3, 6, 12 and 24 cells on cell faces. Averaging the strain over a layer's own particles per cell "
                "works only for interfaces on cell faces, and leaves a zero-energy mode there.", ""]
    co = data.get("cost")
    if co:
        b = co["best_s_per_particle_step"]
        n = co["on"][0]
        out += [f"Cost: `pst_demo` while settling ({n['particles']:,} particles, {n['closure_particles']:,} of them "
                f"in the closure's band), CPU time per particle-step, the best of {len(co['off'])} alternated "
                f"rounds: {fx(1e9 * b['off'], 1)} ns off, {fx(1e9 * b['on'], 1)} ns on, ratio "
                f"{fx(co['ratio_on_over_off'], 3)}. Scenes without the option launch exactly the kernels they "
                "did (`tests/test_interface_closure.py`).", ""]
    fr = data.get("free")
    if fr:
        a, b = fr["off"], fr["on"]
        rows = [[x["group"], fx(x["y0"], 2, 1e3), fx(x["sigma_yy"], 0), fx(y["sigma_yy"], 0), fx(x["overburden"], 0)]
                for x, y in zip(a["near"], b["near"], strict=True)]
        out += [f"`pst_demo` itself settled (free ends, no saw), the particle column at x = {fx(a['x'], 3)} m:", ""]
        out += table(["layer", "initial height (mm)", "sigma_yy off (Pa)", "sigma_yy on (Pa)", "overburden (Pa)"],
                     rows)
        out += ["", env_note(fr), ""]
    ps = data.get("pst")
    if ps and ps["off"].get("near") and ps["on"].get("near"):
        a, b = ps["off"], ps["on"]
        rows = [[x["group"], fx(x["y0"], 2, 1e3), fx(x["sigma_yy"], 0), fx(y["sigma_yy"], 0), fx(x["tau"], 0),
                 fx(y["tau"], 0), fx(x["overburden"], 0)] for x, y in zip(a["near"], b["near"], strict=True)]
        out += [f"`pst_demo` running: the rows {fx(a['x'] - a['front'], 2)} m ahead of the damage front (off: front "
                f"{fx(a['front'], 2)} m at {fx(a['t'], 3)} s; on: {fx(b['front'], 2)} m at {fx(b['t'], 3)} s):", ""]
        out += table(["layer", "initial height (mm)", "sigma_yy off (Pa)", "sigma_yy on (Pa)", "tau off (Pa)",
                      "tau on (Pa)", "overburden at rest (Pa)"], rows)
        out += ["", env_note(ps), ""]
    sh = data.get("shear")
    if sh:
        rows = [[fx(a["cells"], 0), fx(a.get("sample_length"), 2), fx(a["peak_shear_stress"], 0),
                 fx(b["peak_shear_stress"], 0), fx(a["tau_p"], 0), spct(a["peak_over_tau_p"] - 1.0),
                 spct(b["peak_over_tau_p"] - 1.0)] for a, b in zip(sh["off"], sh["on"], strict=True)]
        out += ["The shear test (`shear_test`), its peak against the given tau_p:", ""]
        out += table(["cells", "sample length (m)", "peak off (Pa)", "peak on (Pa)", "tau_p (Pa)", "off", "on"],
                     rows)
        out += ["", env_note(sh), ""]
        first = sh["off"][0].get("sample_length", 0.0)
        long = [r for r in sh["off"] if finite(r.get("sample_length")) and r["sample_length"] > first]
        if long:
            moved = max(abs(b["peak_over_tau_p"] - a["peak_over_tau_p"])
                        for a, b in zip(sh["off"], sh["on"], strict=True))
            out += [f"- The closure moves the peak by at most {pct(moved, 2)} of tau_p; a sample twice as long "
                    f"brings it to {spct(long[0]['peak_over_tau_p'] - 1.0)}: the deficit is the sample's free ends, "
                    "not the interfaces.", ""]
    lad = data.get("ladder")
    if lad:
        out += _ladder(lad, ctx)
    return out


@section("snow", "The shear test's free ends", "snow/results/shear_free_ends_cpu.json",
         "python benchmarks/snow/shear_free_ends.py", figure="snow/results/shear_free_ends_cpu.png",
         follows="Stress at the weak layer's interfaces",
         question="Why does the shear test peak below tau_p: the interfaces, or the sample's free ends?")
def render_shear_free_ends(data: dict, ctx) -> list[str]:
    rows = []
    for cells, runs in data["runs"].items():
        for r in runs:
            rows.append([cells, fx(r["sample_length"], 2), spct(r["peak_over_tau_p"] - 1.0),
                         spct(r["interior_peak_over_tau_p"] - 1.0), secs(r["wall_s"])])
        f = data["fit"][cells]
        rows.append([cells, "endless (fit)", spct(f["a"] - 1.0), DASH, DASH])
    out = ["The shear test against its sample's length: the structural peak (push force over the sample's area) and "
           "the interior's own peak (the layer's mean `sigma_xy` at least one layer thickness from both ends, at its "
           "maximum over time), both against the calibrated tau_p; the endless sample's peak from the fit "
           "`a - b / L` of the structural peaks:", ""]
    out += table(["cells", "sample length (m)", "structural peak", "interior's peak", "wall time"], rows)
    out += ["", env_note(data), ""]
    for cells, f in data["fit"].items():
        out.append(f"- {cells} cells: the ends cost the peak {fx(1e3 * f['b'], 1)} mm of sample (largest residual of "
                   f"the fit {pct(f['max_residual'], 2)} of tau_p).")
    for cells, runs in data["runs"].items():
        r = max(runs, key=lambda x: x["sample_length"])
        vals = [x["tau_over_tau_p"] for x in r["rows"]]
        out.append(f"- Per particle row of the interior at the structural peak, {cells} cells, "
                   f"{fx(r['sample_length'], 2)} m, bottom to top: " + ", ".join(spct(v - 1.0) for v in vals)
                   + f" of tau_p (in uniform simple shear every row would carry the same; here they span "
                   f"{pct(max(vals) - min(vals))} of tau_p).")
    on = data.get("closure_on")
    if on:
        off = next((r for r in data["runs"].get("4", []) if abs(r["sample_length"] - on["sample_length"]) < 1e-9),
                   None)
        if off:
            out.append(f"- The interface closure, 4 cells, {fx(on['sample_length'], 2)} m: structural peak "
                       f"{spct(on['peak_over_tau_p'] - 1.0)} (off: {spct(off['peak_over_tau_p'] - 1.0)}).")
    return out


_LADDER_Q = (("critical_cut", "critical cut (m)", 3, 1.0), ("speed", "speed (m/s)", 1, 1.0),
             ("touchdown", "touchdown (m)", 3, 1.0), ("collapse_height", "collapse height (mm)", 2, 1e3))


def _ladder(lad: dict, ctx) -> list[str]:
    """The PST ladder's coarsest levels off and on, beside the committed finer levels of the error ladder."""
    conv = ctx.load("convergence/results/error_vs_runtime_snow.json") or {}
    finer = [lv for lv in (conv.get("ladders") or {}).get("pst") or []
             if lv.get("dx", 1.0) < min(r["dx"] for r in lad["off"]) - 1e-12]
    rows = []
    for a, b in zip(lad["off"], lad["on"], strict=True):
        rows.append([fx(a["dx"], 1, 1e3), fx(a["cells_across_layer"], 0)]
                    + [f"{fx(a.get(k), nd, sc)} / {fx(b.get(k), nd, sc)}" for k, _, nd, sc in _LADDER_Q]
                    + [f"{secs(a['wall_s'])} / {secs(b['wall_s'])}"])
    for lv in finer:
        rows.append([fx(lv["dx"], 1, 1e3), fx(lv.get("cells_across_layer"), 0)]
                    + [f"{fx(lv.get(k), nd, sc)} (off)" for k, _, nd, sc in _LADDER_Q] + [secs(lv.get("wall_time_s"))])
    out = ["The PST ladder (`pst_flat` as the error ladder runs it, 6 cm layer), its two coarsest levels off / on "
           "the closure; the finer levels as the committed error ladder has them (off):", ""]
    out += table(["dx (mm)", "cells across the layer"] + [q[1] for q in _LADDER_Q] + ["wall time"], rows)
    out += ["", env_note(lad), ""]
    if finer:
        ref = finer[-1]
        for k, label, _, _ in _LADDER_Q:
            moves = []
            for a, b in zip(lad["off"], lad["on"], strict=True):
                cells = f"{fx(a['cells_across_layer'], 0)} cells: "
                if finite(a.get(k)) and finite(b.get(k)) and finite(ref.get(k)):
                    da, db = abs(a[k] - ref[k]), abs(b[k] - ref[k])
                    moves.append(cells + ("unchanged" if abs(b[k] - a[k]) <= 1e-9 * abs(a[k]) else
                                          "towards the finest level" if db < da else "away from the finest level"))
                elif finite(b.get(k)) and not finite(a.get(k)):
                    moves.append(cells + "measured with the closure only (the run without it has none)")
            if moves:
                out.append(f"- {label.split(' (')[0]}: " + "; ".join(moves) + ".")
        out.append("")
    return out
