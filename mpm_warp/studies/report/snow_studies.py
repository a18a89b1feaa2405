"""Sections of the snow studies on the ladder PST: the fracture-energy sweep, the speed trends and weac's static
answers; the stress at the weak layer's interfaces; and the studies whose results are still to come."""

from __future__ import annotations

from ..convergence import loglog_slope
from .core import section
from .fmt import DASH, bracket, cases_load_note, check_line, env_note, finite, fx, pct, secs, spct, table


def _column(data: dict) -> str:
    return " ".join(f"`{o}`" for o in data.get("column") or [])


def _cells(data: dict) -> str:
    """``'6 cells'`` across the weak layer of a study's column (its overrides' layer thickness over dx)."""
    o = dict(s.split("=", 1) for s in data.get("column") or [] if "=" in s)
    try:
        return f"{float(o['scene.weak_layer_thickness']) / float(o['scene.dx']):.0f} cells"
    except (KeyError, ValueError, ZeroDivisionError):
        return "the scenario's cells"


# ----------------------------------------------------------------------------- fracture energy
@section("snow", "Fracture energy sweep", "snow/results/snow_wf_sweep.json",
         lambda d: "python benchmarks/snow/wf_sweep.py --w-f " + ",".join(f"{c['w_f']:g}" for c in d["cases"]),
         figure="snow/results/snow_wf_sweep.png",
         question="How do crack speed and critical cut change with the fracture energy w_f? (Dask tasks, one per w_f.)")
def render_wf_sweep(data: dict, ctx) -> list[str]:
    rows = []
    for c in data["cases"]:
        over = c.get("speed_over") or [None, None]
        rows.append([fx(c["w_f"], 2), fx(c["delta_s"], 3, 1e3), fx(c["kappa_s"], 2), fx(c["debond_energy"], 3),
                     bracket(c["critical_cut"], c["lo"], c["hi"]) if c.get("bracketed") else c.get("note") or DASH,
                     fx(c.get("runaway_cut_of_base"), 3), fx(c.get("speed"), 1), fx(c.get("deflection_speed"), 1),
                     fx(c.get("collapse_height"), 2, 1e3), fx(c.get("heierli_speed_run"), 1), secs(c.get("wall_s"))])
    out = table(["w_f (J/m^2)", "delta_s (mm)", "kappa_s (J/m^3)", "debond energy (J/m^2)", "critical cut (m)",
                 "base run: saw when the crack left it (m)", f"speed over {fx(over[0], 1)}-{fx(over[1], 1)} m (m/s)",
                 "deflection front (m/s)", "collapse height (mm)", "Heierli, the run's collapse (m/s)", "wall time"],
                rows)
    out += ["", env_note(data), "", f"The ladder PST at {_cells(data)} across the layer ({_column(data)}); "
            f"bisection in [{fx(data['bracket'][0], 2)}, {fx(data['bracket'][1], 2)}] m down to a "
            f"{fx(data['bracket'][2], 2)} m bracket; the base run from the longest cut gives the speed.", ""]
    ok = [c for c in data["cases"] if c.get("bracketed") and finite(c.get("critical_cut"))]
    if len(ok) >= 2:
        n = loglog_slope([c["w_f"] for c in ok], [c["critical_cut"] for c in ok])
        g = {c["critical_cut_gaume"] for c in data["cases"] if finite(c.get("critical_cut_gaume"))}
        out.append(f"- The bisected critical cut grows about as w_f^{n:.2f} over w_f = {fx(ok[0]['w_f'], 2)}-"
                   f"{fx(ok[-1]['w_f'], 2)} J/m^2.")
        if len(g) == 1:
            gv = g.pop()
            out.append(f"- Gaume et al. 2017's formula has no w_f in it: {fx(gv, 3)} m, "
                       + ("above" if all(c["critical_cut"] < gv for c in ok) else "not above")
                       + " every bisected value.")
    sp = [c for c in data["cases"] if finite(c.get("speed"))]
    if len(sp) >= 2:
        falls = all(b["speed"] < a["speed"] for a, b in zip(sp, sp[1:], strict=False))
        trend = "falls" if falls else "does not fall monotonically"
        out.append(f"- The crack speed {trend} with w_f: " + ", ".join(f"{fx(c['speed'], 1)}" for c in sp) + " m/s.")
    return out + wf_checks(data["cases"])


def wf_checks(cases: list[dict]) -> list[str]:
    """The pass lines of the w_f sweep against its references: Heierli's speed with the run's collapse (within
    25 %, as for the full PSTs) and Gaume et al. 2017's critical cut (within 20 %); neither has w_f in it."""
    out = [""]
    h = [(c["w_f"], c["speed"] / c["heierli_speed_run"] - 1.0) for c in cases
         if finite(c.get("speed")) and finite(c.get("heierli_speed_run")) and c["heierli_speed_run"]]
    if h:
        ok = all(abs(x) <= 0.25 for _, x in h)
        out.append(check_line("speed against Heierli", "within 25 % of Heierli's with the run's collapse at every "
                              "w_f", ok, ", ".join(f"w_f {fx(w, 2)}: {spct(x)}" for w, x in h)
                              + ("" if ok else "; Heierli's speed has no fracture energy in it, the runs' speed falls "
                                 "with w_f: they meet only near the ladder's w_f")))
    g = [(c["w_f"], c["critical_cut"] / c["critical_cut_gaume"] - 1.0) for c in cases
         if c.get("bracketed") and finite(c.get("critical_cut")) and finite(c.get("critical_cut_gaume"))]
    if g:
        ok = all(abs(x) <= 0.20 for _, x in g)
        out.append(check_line("critical cut against Gaume et al. 2017", "within 20 % of the closed form at every w_f",
                              ok, ", ".join(f"w_f {fx(w, 2)}: {spct(x)}" for w, x in g)
                              + ("" if ok else "; the closed form has no w_f in it, the bisected cut grows with w_f "
                                 "as an energy criterion says (weac's, in the critical-cut study)")))
    return out


# ----------------------------------------------------------------------------- speed trends
_PARAMS = {"slab.E": ("slab E (MPa)", "slab_E", 1e-6, 2), "weak_layer.h_c": ("h_c (mm)", "h_c_calibrated", 1e3, 2)}


@section("snow", "Crack speed against slab stiffness and collapse height", "snow/results/snow_speed_trends.json",
         "python benchmarks/snow/speed_trends.py", figure="snow/results/snow_speed_trends.png",
         question="Does the crack speed grow with the slab's stiffness and fall with the collapse height? (One run per "
                  "case from one cut, Dask tasks.)")
def render_speed_trends(data: dict, ctx) -> list[str]:
    out = [f"The ladder PST at {_cells(data)} across the layer ({_column(data)}), one run per case from a "
           f"{fx(data.get('cut'), 2)} m cut; the WEAC fit of h_c for this layer is "
           f"{fx(data.get('h_c_fit'), 2, 1e3)} mm.", ""]
    for param, t in data["trends"].items():
        label, key, scale, nd = _PARAMS.get(param, (param, "value", 1.0, 3))
        rows = [[fx(c.get(key), nd, scale), "yes" if c.get("propagated") else f"no: the front stops at "
                 f"{fx(c.get('front'), 2)} m", fx(c.get("speed"), 1), fx(c.get("collapse_height"), 2, 1e3),
                 fx(c.get("touchdown"), 3), fx(c.get("heierli_speed_run"), 1), secs(c.get("wall_s"))]
                for c in t["cases"]]
        over = t["cases"][0].get("speed_over") or [None, None]
        out += [f"`{param}`:", ""]
        out += table([label, "crack runs", f"speed over {fx(over[0], 1)}-{fx(over[1], 1)} m (m/s)",
                      "collapse height (mm)", "touchdown (m)", "Heierli, that collapse (m/s)", "wall time"], rows)
        out += ["", f"Log-log slope of the speed against `{param}`: {fx(t.get('slope_speed'), 2)} (Heierli's "
                f"slab-bending speed: {fx(t.get('slope_heierli'), 2)}); monotone: "
                f"{'yes' if t.get('monotone') else 'no'}"
                + (f"; arrested at {', '.join(fx(v, nd, scale) for v in t['arrested'])}" if t.get("arrested") else "")
                + ".", "", trend_check(param, t.get("slope_speed"), t.get("slope_heierli"),
                                      "the mean over 0.7-1.9 m is taken while the crack still accelerates from the "
                                      "cut (see the steady speeds on 8 m columns)"), ""]
    return out + [env_note(data)]


#: A speed trend agrees with Heierli's slab-bending speed when its log-log slope has the same sign and lies
#: within this of Heierli's (the closed form's exponents are +-0.25)
TREND_TOLERANCE = 0.1


def trend_check(param: str, slope, heierli, why_not: str) -> str:
    """The pass line of a speed trend against Heierli's (criterion: :data:`TREND_TOLERANCE`)."""
    ok = finite(slope) and finite(heierli) and slope * heierli > 0 and abs(slope - heierli) <= TREND_TOLERANCE
    return check_line(f"the trend with `{param}` against Heierli", f"the log-log slope of the speed of the same sign "
                      f"as Heierli's (the runs' collapse) and within {fx(TREND_TOLERANCE, 1)} of it", ok,
                      f"{fx(slope, 2)} against {fx(heierli, 2)}" + ("" if ok else f"; {why_not}"))


@section("snow", "Steady crack speed on 8 m columns", "snow/results/snow_long_speed_trends.json",
         "python benchmarks/snow/long_speed_trends.py", figure="snow/results/snow_long_speed_trends.png",
         question="Beyond 5 m of an 8 m column, does the steady crack speed follow the slab's stiffness and the "
                  "collapse height, and stay below the 0.6 c_s of long flat DEM PSTs? (One run per case, Dask tasks.)")
def render_long_speed_trends(data: dict, ctx) -> list[str]:
    t0 = data["trends"]
    out = [f"The ladder PST's snow on an 8 m column ({_column(data)}), one run per case; the WEAC fit of h_c for "
           f"this layer is {fx(t0.get('h_c_fit'), 2, 1e3)} mm. Steady: the median of the damage front's local speeds "
           f"(0.5 m windows) centred beyond {fx(data.get('steady_from'), 0)} m and ending before the far end zone; "
           "early: the mean over the first 3 m from the cut.", ""]
    for param in ("slab.E", "weak_layer.h_c"):
        t = t0[param]
        label, key, scale, nd = _PARAMS.get(param, (param, "value", 1.0, 3))
        rows = [[fx(c.get(key), nd, scale), fx(c.get("cut"), 1),
                 "yes" if c.get("propagated") else f"no: the front stops at {fx(c.get('front'), 2)} m",
                 fx(c.get("steady_speed"), 1), fx(c["steady_speed"] / c["shear_wave_speed"], 2)
                 if finite(c.get("steady_speed")) else DASH, spct(c.get("steady_window_rise")),
                 fx(c.get("early_speed"), 1),
                 fx(c.get("collapse_height"), 2, 1e3), fx(c.get("heierli_speed_run"), 1), secs(c.get("wall_s"))]
                for c in t["cases"]]
        out += [f"`{param}`:", ""]
        out += table([label, "cut (m)", "crack runs", "steady speed (m/s)", "steady / c_s",
                      "change across the steady range", "early speed (m/s)",
                      "collapse height (mm)", "Heierli, that collapse (m/s)", "wall time"], rows)
        out += ["", f"Log-log slopes against `{param}`" + (" (the runs' collapse on the axis)" if param != "slab.E"
                                                          else "") +
                f": steady {fx(t.get('slope_steady'), 2)}, early {fx(t.get('slope_early'), 2)}, Heierli with the "
                f"runs' collapse {fx(t.get('slope_heierli'), 2)} (closed form {t.get('heierli_exponent'):+g}).", "",
                trend_check(param, t.get("slope_steady"), t.get("slope_heierli"),
                            "the steady speed on these columns hardly depends on the collapse height; why it departs "
                            "from Heierli's slab-bending speed is not established here"), ""]
    m = t0.get("max_steady_over_cs")
    out.append(check_line("steady speed against long flat DEM PSTs", "the fastest steady crack at most 0.6 c_s "
                          "(Bobillier et al. 2024)", finite(m) and m <= 0.6, f"{fx(m, 2)} c_s"))
    cases = {c["finished_at"]: c for t in (t0["slab.E"], t0["weak_layer.h_c"]) for c in t["cases"]
             if c.get("finished_at")}
    if data.get("cases_from_earlier_run") and cases:
        out.append(f"- {data['cases_from_earlier_run']} cases come from an earlier invocation, finished between "
                   f"{min(cases)[:16].replace('T', ' ')} and {max(cases)[:16].replace('T', ' ')} UTC"
                   + ("" if all(c.get("environment") for c in cases.values()) else
                      " (their load is not on record: the wall times are not from a quiet machine)") + ".")
    note = cases_load_note(c.get("environment") for c in cases.values())
    return out + ([note] if note else []) + ["", env_note(data)]


# ----------------------------------------------------------------------------- weac
@section("snow", "weac's static answers for the ladder PST", "snow/results/weac_static_pst.json",
         "python benchmarks/snow/weac_static_pst.py",
         question="What does weac's static model (Weissgraeber and Rosendahl 2023, docs/weac.md) say for the "
                  "project's PSTs: critical cuts, column ends, where the slab's tension peaks?")
def render_weac(data: dict, ctx) -> list[str]:
    lad = data.get("ladder") or {}
    rows = [[f"`{k}`", fx(c["critical_cut"], 3), fx(c.get("weac_3_3_1_recorded", c.get("weac_3_3_1")), 3),
             "yes" if c.get("agrees_to_3_digits")
             else "no", fx(c["G_I"] / c["G"], 2) if finite(c.get("G")) and c["G"] else DASH,
             fx(c.get("free_end_deflection_m"), 2, 1e3), fx(c.get("weac_collapse_height_m"), 2, 1e3),
             fx(c.get("critical_cut_weak_layer_weight_on_slab"), 3)] for k, c in lad.items()]
    out = [f"The ladder PST's column, energy criterion at G_c = {fx(data.get('G_c'), 2)} J/m^2:", ""]
    out += table(["case", "critical cut (m)", "weac 3.3.1, recorded (m)", "agree to 3 digits", "G_I / G",
                  "free end's deflection (mm)", "weac collapse height (mm)", "with the layer's weight on the slab (m)"],
                 rows)
    out += ["", env_note(data, verb="computed"), ""]
    source = data.get("weac_3_3_1_source") or "recorded from weac 3.3.1, computed outside this project"
    out += [f"The critical cut is computed with the installed weac ({data['environment'].get('weac') or '?'}); the "
            f"weac 3.3.1 column is not computed here: {source}.", ""]
    chk = (data.get("checks") or {}).get("installed_weac_matches_weac_3_3_1_recorded")
    if chk:
        fails = [k for k, c in chk["cases"].items() if not c["pass"]]
        out += [check_line("installed weac against weac 3.3.1 (recorded)", chk["criterion"], chk["pass"],
                           "off in " + ", ".join(fails) if fails else ""), ""]
    ends = data.get("column_ends") or {}
    if ends:
        out += ["Slope-normal against vertical column ends (the column's length and slope angle in its name):", ""]
        rows = [[f"`{col}`", side, fx(e["slope_normal"], 3), fx(e["vertical"], 3),
                 fx(e["ratio_normal_over_vertical"], 2), fx(e.get("vertical_wedge_lever_fixed"), 3),
                 fx(e.get("wedge_length_m"), 3)] for col, sides in ends.items() for side, e in sides.items()]
        out += table(["column", "saw from", "slope-normal ends (m)", "vertical ends (m)", "ratio",
                      "vertical, wedge lever fixed (m)", "wedge length (m)"], rows) + [""]
    st = data.get("slab_stress") or {}
    if st:
        out += ["Where the slab's largest tensile stress sits at the critical cut:", ""]
        rows = [[f"`{k}`", fx(s["cut"], 3), fx(s["peak_sigma_1"], 0), fx(s["peak_x"], 3), fx(s["peak_depth"], 3),
                 s.get("peak_layer"), fx(s.get("peak_over_cut_sigma_1"), 0), fx(s.get("peak_ratio"), 3)]
                for k, s in st.items()]
        out += table(["case", "cut (m)", "largest sigma_1 (Pa)", "at x (m)", "depth (m)", "layer",
                      "largest over the cut's span (Pa)", "largest sigma_1 / tensile strength"], rows)
    return out


# ----------------------------------------------------------------------------- still to come


# ----------------------------------------------------------------------------- interfaces
def _edge(r: dict, group: str, k: int):
    """The ``k``-th row (from the bottom; -1: the top) of ``group`` among a run's rows near the layer."""
    rows = [x for x in r.get("near") or [] if x["group"] == group]
    return rows[k]["ratio"] if rows else None


@section("snow", "Stress at the weak layer's interfaces", "snow/results/interface_stress_cpu.json",
         "python benchmarks/snow/interface_stress.py", figure="snow/results/interface_stress_cpu.png",
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
