"""Sections of the snow studies on the ladder PST: the fracture-energy sweep, the crack-speed trends and weac's
static answers (the stress at the weak layer's interfaces follows them, from :mod:`.snow_interfaces`)."""

from __future__ import annotations

from ..convergence import loglog_slope
from .core import section
from .fmt import DASH, bracket, cases_load_note, check_line, env_note, finite, fx, secs, spct, table


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
