"""The README's few headline numbers, from the same JSON as the results document, and the README block they fill.

The block sits between :data:`BEGIN` and :data:`END` in ``README.md``; without both markers the README is
left alone.
"""

from __future__ import annotations

from ... import markers
from ..snow import DEM_STEADY_MAX, FIELD_SPEED, LONG_PST_SPEED, STEADY_FROM
from .core import PAGES, Context, slug
from .fmt import bracket, finite, fx, ratio_range, spct
from .pages import page_of
from .snow_runs import steady_speed

__all__ = ["BEGIN", "END", "headlines", "block", "with_block"]

BEGIN = "<!-- results:begin -->"
END = "<!-- results:end -->"
#: The block's last line, after the bullets: the results pages, by question.
WHERE = ("Every measured table, with the command that reproduces it and where it was measured, is in the results "
         "pages, each opening with its checks: " + ", ".join(f"[{p.title}]({p.path})" for p in PAGES.values())
         + " (the index: [docs/results.md](docs/results.md)).")


def _link(title: str) -> str:
    """The README's address of the section ``title``: its page's, with its anchor."""
    return f"{page_of(title) or 'docs/results.md'}#{slug(title)}"


def _throughput(ctx: Context, source: str, dim: int, title: str) -> str | None:
    data = ctx.load(source)
    if data is None:
        return None
    rows = [r for r in data["rows"] if r["engine"] == "mpm_warp" and r["dim"] == dim and r["threads"] == 1]
    parts = [f"{ratio_range([r.get('ratio_vs_taichi_cpu_time') for r in rows if r['material'] == m], 2)}x ({m})"
             for m in sorted({r["material"] for r in rows})]
    if not parts:
        return None
    return (f"- **CPU throughput beside Taichi, {dim}D:** {' and '.join(parts)} Taichi's particle-steps per CPU "
            f"second, one thread ([{title}]({_link(title)})).")


def _pst_speed(ctx: Context) -> str | None:
    data = ctx.load("snow/results/snow_pst_flat.json")
    if data is None:
        return None
    r = data["result"]
    v = r.get("damage_speed_mean")
    a, b = r.get("damage_speed_mean_over") or (None, None)
    steady, cs = steady_speed(r, data.get("scene_slab_thickness") or 0.0), r.get("shear_wave_speed")
    if not finite(v) or steady is None or not finite(cs):
        return None

    def where(x, band):
        return "inside" if band[0] <= x <= band[1] else "outside"
    return (f"- **PST crack speed:** on `pst_flat`'s 8 m column the crack settles at {fx(steady, 1)} m/s "
            f"({steady / cs:.2f} c_s) beyond {STEADY_FROM:g} m, {where(steady, LONG_PST_SPEED)} the "
            f"{LONG_PST_SPEED[0]:g}-{LONG_PST_SPEED[1]:g} m/s of long PSTs (Bergfeld et al. 2022) and "
            f"{'below' if steady / cs <= DEM_STEADY_MAX else 'above'} the {DEM_STEADY_MAX:g} c_s of long DEM PSTs "
            f"(Bobillier et al. 2024); over {fx(a, 1)}-{fx(b, 1)} m it averages {fx(v, 1)} m/s, "
            f"{where(v, FIELD_SPEED)} short PSTs' {FIELD_SPEED[0]:g}-{FIELD_SPEED[1]:g} m/s "
            f"([PST: `pst_flat`]({_link('PST: `pst_flat`')})).")


def _slope(ctx: Context) -> str | None:
    cuts = (ctx.load("snow/results/snow_critical_cut.json") or {}).get("cases") or {}
    weac = (ctx.load("snow/results/weac_static_pst.json") or {}).get("ladder") or {}
    flat = [r for r in ((ctx.load("convergence/results/error_vs_runtime_snow.json") or {}).get("ladders") or {})
            .get("pst", []) if r.get("level") == 1 and r["precision"] == "float32" and r.get("bracketed")]
    up, down = cuts.get("ladder_slope"), cuts.get("ladder_slope_cut_downslope_end")
    w = {k: (weac.get(k) or {}).get("critical_cut") for k in ("flat", "upslope_30", "downslope_30")}
    if not (flat and up and down and all(finite(x) for x in w.values())):
        return None
    a0 = flat[0]["critical_cut"]
    title = "Critical cut"
    return (f"- **Slope:** on 30 deg the critical cut from the upslope end is {spct(up['value'] / a0 - 1)} and from "
            f"the downslope end {spct(down['value'] / a0 - 1)} of the flat column's, against weac's "
            f"{spct(w['upslope_30'] / w['flat'] - 1)} and {spct(w['downslope_30'] / w['flat'] - 1)} for the "
            f"same columns: the cut end decides, as the static reference says ([{title}]({_link(title)})).")


def _critical_cut(ctx: Context) -> str | None:
    lad = ctx.load("convergence/results/error_vs_runtime_snow.json")
    weac = ctx.load("snow/results/weac_static_pst.json")
    if lad is None or weac is None:
        return None
    levels = [r for r in lad["ladders"].get("pst", []) if r["precision"] == "float32" and r.get("bracketed")]
    w = (weac.get("ladder") or {}).get("flat", {}).get("critical_cut")
    if not levels or not finite(w):
        return None
    f = max(levels, key=lambda r: r["cells_across_layer"])
    lo, hi = f["critical_cut_bracket"]
    title = "Error against run time: the snow ladders"
    return (f"- **Critical cut:** {bracket(f['critical_cut'], lo, hi)} on the flat ladder PST at "
            f"{f['cells_across_layer']:g} cells across the layer, against weac's static {fx(w, 3)} m "
            f"({spct(f['critical_cut'] / w - 1)}) ([{title}]({_link(title)})).")


def _shear(ctx: Context) -> str | None:
    data = ctx.load("snow/results/snow_shear_test.json")
    if data is None or not data.get("runs"):
        return None
    res = [r["result"] for r in data["runs"]]
    tau = res[0].get("tau_p_calibrated")
    cells = " / ".join(str(r["cells"]) for r in data["runs"])
    return (f"- **Shear test:** peak {' / '.join(fx(x['peak_shear_stress'], 1) for x in res)} Pa at {cells} cells "
            f"against the given tau_p {fx(tau, 0)} Pa "
            f"({' / '.join(spct(x['peak_shear_stress'] / tau - 1) for x in res)}) "
            f"([Shear test]({_link('Shear test')})).")


def _field(ctx: Context) -> str | None:
    data = ctx.load("field/results/field_census.json")
    if data is None:
        return None
    c = data["census"]
    return (f"- **Real pits:** of {c['files']:,} SnowPilot pits, {c['files'] - c['files_unreadable']:,} read, and "
            f"{c['runnable']:,} of {c['field_outcome_records']:,} End/SF/Arr PST records set up as calibrated columns "
            f"({c['runnable_fraction_of_field_outcomes']:.1%}); each other record is refused in one line in field "
            f"terms ([Field pits in]({_link('Field pits in')})).")


def _outcomes(ctx: Context) -> str | None:
    """The field outcomes against the observers: the model's balanced accuracy beside both baselines'."""
    data = ctx.load("field/results/field_batch.json")
    if data is None:
        return None
    sc = data["scores"]
    sel = data["selection"]
    drawn = sum(sel.get(k, 0) for k in ("END", "SF", "ARR"))
    stopped = (f" (a batch stopped early: the {sc['cases']:,} finished of {drawn:,} drawn, not yet a verdict)"
               if sel.get("finished_only") else "")
    iv = (sc.get("uncertainty") or {}).get("intervals") or {}

    def ba(key: str) -> str:
        b = iv.get(key)
        return f"{sc[key]['balanced_accuracy']:.2f}" + (f" [{b[0]:.2f}, {b[1]:.2f}]" if b and b[0] != b[1] else "")

    rec = sc["model"]["recall"]
    m = sc["model"]["balanced_accuracy"]
    above = all(m > sc[k]["balanced_accuracy"] for k in ("majority", "weac_static"))
    verdict = "not judged on part of the draw" if stopped else "above both" if above else "not above both"
    how = ("the columns with measured slab densities and a draw by observed class" if sel.get("measured")
           else "drawn by observed class")
    return (f"- **Field outcomes:** on {sc['cases']:,} real PSTs, {how}{stopped}, the model's "
            f"END/SF/ARR balanced accuracy is {ba('model')}, against {ba('majority')} for always answering one class "
            f"and {ba('weac_static')} for a static rule from weac's slab stress: "
            f"{verdict}. Its recall: END {rec['END']:.0%}, SF {rec['SF']:.0%}, "
            f"ARR {rec['ARR']:.0%} ([Field outcomes against the observers]"
            f"({_link('Field outcomes against the observers')})).")


def _forecast(ctx: Context) -> str | None:
    """The field outcomes as probabilities: the model's skill, its readings' calibrated, and the bar's."""
    data = ctx.load("field/results/field_forecast.json")
    if data is None:
        return None
    f = data["scores"]["forecast"]
    iv = (data["scores"].get("forecast_uncertainty") or {}).get("intervals") or {}
    if not {"model", "calibrated", "information_bar"} <= set(f):
        return None

    def skill(key: str) -> str:
        b = iv.get(key, {}).get("rpss")
        return f"{f[key]['rpss']:.2f}" + (f" [{b[0]:.2f}, {b[1]:.2f}]" if b else "")

    return (f"- **As a probability:** on the same PSTs the model's ranked probability skill against the set's own "
            f"class shares is {skill('model')}; its readings calibrated as a forecaster calibrates a model, "
            f"cross-validated by pit, score {skill('calibrated')}, beside {skill('information_bar')} for the same "
            f"regression on the records' own numbers ([The outcome as a probability: forecast scores]"
            f"({_link('The outcome as a probability: forecast scores')})).")


def headlines(ctx: Context) -> list[str]:
    """The README's headline bullets (a bullet whose results are not committed is left out)."""
    out = [_throughput(ctx, "perf/results/throughput_cpu.json", 3, "Throughput beside Taichi, 3D"),
           _throughput(ctx, "perf/results/throughput_2d_cpu.json", 2, "Throughput beside Taichi, 2D"),
           _pst_speed(ctx), _critical_cut(ctx), _slope(ctx), _shear(ctx), _field(ctx), _outcomes(ctx),
           _forecast(ctx)]
    return [b for b in out if b]


def block(ctx: Context) -> list[str]:
    """The README block's lines: the headline bullets, then where the tables are."""
    bullets = headlines(ctx)
    return bullets + ([""] if bullets else []) + [WHERE]


def with_block(readme: str, bullets: list[str], begin: str = BEGIN, end: str = END) -> str | None:
    """``readme`` with the text between ``begin`` and ``end`` replaced by ``bullets``; None without the markers."""
    return markers.with_block(readme, bullets, begin, end)
