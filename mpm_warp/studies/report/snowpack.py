"""Sections of the snowpack studies: the field's three PST outcomes, and the critical cut of layered slabs and of
slope-normal against vertical column ends, each beside weac's static answer."""

from __future__ import annotations

from .core import section
from .fmt import DASH, bracket, env_note, finite, fx, secs, spct, table


def _modulus(ly: dict) -> str:
    return f"{fx(ly['E'], 1, 1e-6)} MPa" if finite(ly.get("E")) and ly["E"] > 0 else "E from its density"


def _slab(layers: list) -> str:
    """``'10 + 10 + 10 cm (1.0 MPa / 5.0 MPa / 20.0 MPa, top first)'`` or ``'30 cm, 250 kg/m^3, 5.0 MPa'``."""
    if not layers:
        return DASH
    if len(layers) == 1:
        ly = layers[0]
        return f"{fx(ly['thickness'], 0, 100)} cm, {fx(ly['density'], 0)} kg/m^3, {_modulus(ly)}"
    return (" + ".join(f"{fx(ly['thickness'], 0, 100)}" for ly in layers) + " cm ("
            + " / ".join(_modulus(ly) for ly in layers) + ", top first)")


def _where(o: dict) -> str:
    if o.get("class") == "SF" and finite(o.get("slab_fracture_at")):
        return f"slab broke {fx(o['slab_fracture_at'], 2)} m from the cut end"
    if o.get("class") == "ARR" and finite(o.get("arrest_at")):
        return f"crack stopped {fx(o['arrest_at'], 2)} m from the cut end"
    return o.get("note") or DASH


@section("snow", "The three field outcomes: END, SF, ARR", "snow/results/pst_outcomes.json",
         lambda d: "python benchmarks/snow/pst_outcomes.py " + " ".join(d["cases"]),
         question="Does a PST end as the field writes it (the crack reaches the end, the slab breaks, the crack "
                  "arrests), with the slab's break beside weac's peak tensile stress?")
def render_outcomes(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    rows = [[name, c["what"], _slab(c["slab_layers"]), f"`{c['outcome']['field_line']}`", _where(c["outcome"]),
             fx((c.get("weac") or {}).get("critical_cut"), 3), f"{c['particles']:,}", f"{c['steps']:,}",
             secs(c["wall_s"])] for name, c in cases.items()]
    out = table(["case", "column", "slab", "field line", "where", "weac critical cut (m)", "particles", "steps",
                 "wall time"], rows)
    out += ["", env_note(*[c for c in cases.values()]), "",
            "Each column is `pst_demo`'s with the overrides in the JSON and `scene.slab_fracture = true` (tensile "
            "strength and fracture energy from each slab layer's density, docs/model.md §9); the class comes from "
            "the run itself (docs/model.md §9), the field line as an observer writes it."]
    sf = (cases.get("SF") or {}).get("weac_slab_stress")
    if sf and finite(sf.get("peak_at")):
        out += ["", f"- **Where the slab broke (SF):** {fx(sf['mpm_break_at'], 2)} m from the cut end, with the saw at "
                f"{fx(sf['cut'], 2)} m. weac's static solution of the same column at that cut puts the slab's largest "
                f"tensile stress ({fx(sf['peak_stress'], 2, 1e-3)} kPa) at {fx(sf['peak_at'], 2)} m, "
                f"{fx(sf['peak_depth'], 3, 100)} cm below the slab surface, and its largest ratio to the layer's "
                f"strength ({fx(sf['peak_over_strength'], 2)}) at {fx(sf['peak_over_strength_at'], 2)} m: the break is "
                f"{fx(sf['mpm_break_at'] - sf['peak_over_strength_at'], 2)} m from weac's peak ratio."]
    for name, c in cases.items():
        png = f"snow/results/{c['picture']}"
        if ctx.exists(png):
            out += ["", f"![{name}: {c['outcome']['field_line']}](../benchmarks/{png})"]
    return out


def _classes(c: dict) -> str:
    k = c.get("classes") or {}
    return f"{k.get('below') or 'no run'} / {k.get('above') or DASH}" if k else DASH


@section("snow", "The snowpack's critical cut: layering and column ends", "snow/results/snowpack_critical_cut.json",
         lambda d: "python benchmarks/snow/snowpack_critical_cut.py " + " ".join(d["cases"]),
         figure="snow/results/snowpack_critical_cut.png",
         question="Does the snowpack change the critical cut as weac says (layered slabs, slope-normal against "
                  "vertical ends)?")
def render_snowpack_cut(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    rows = []
    for name, c in cases.items():
        w = (c.get("weac") or {}).get("critical_cut")
        cut = bracket(c["value"], c["lo"], c["hi"]) if c.get("bracketed") else c.get("note") or DASH
        rows.append([name, _slab(c["slab_layers"]), fx(c["slope_angle"], 0), c["cut_from"], c["column_ends"], cut,
                     _classes(c), fx(w, 3), spct(c.get("relative_to_weac")), secs(c["wall_s"])])
    out = table(["case", "slab", "slope (deg)", "cut from", "column ends", "critical cut (m)",
                 "class below / above", "weac (m)", "against weac", "wall time"], rows)
    out += ["", env_note(*[c for c in cases.values()]), "",
            "The ladder PST's column (2.2 m, 6 cm weak layer at 6 cells across it), bisected by "
            "`mpm_warp.scenes.pst.critical_cut`; weac's energy criterion G = G_c = w_f for the same column "
            "(docs/weac.md)."]
    checks = data.get("checks") or {}
    lay = checks.get("layering")
    if lay:
        same = "the same" if lay["same_direction"] else "not the same"
        within = "yes" if lay["within_20_percent_of_weac"] else "no"
        out += ["", f"- **Layering:** the stiff-on-top slab's cut minus the stiff-at-the-bottom one's is "
                f"{fx(lay['stiff_top_minus_stiff_bottom'], 3)} m, weac's "
                f"{fx(lay['weac_stiff_top_minus_stiff_bottom'], 3)} m: {same} direction; each within 20 % of weac's "
                f"value: {within}."]
    for end in ("downslope", "upslope"):
        r = checks.get(f"ends_ratio_{end}")
        if r:
            out.append(f"- **Column ends, cut from the {end} end:** slope-normal over vertical {fx(r['mpm'], 2)}, weac "
                       f"{fx(r['weac'], 2)} (Birkeland et al. 2025 measured slope-normal ends' critical cuts up to "
                       f"50 % shorter, the ratio down to 0.5).")
    return out
