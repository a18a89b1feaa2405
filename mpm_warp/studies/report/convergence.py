"""Sections of the convergence results: the reference problems' error against run time, the snow ladders
(PST and shear test, level by level), and the weak layer's mesh study."""

from __future__ import annotations

from .core import section
from .fmt import DASH, bracket, check_line, count, env_note, finite, fx, pct, ratio_range, secs, spct, table

# ----------------------------------------------------------------------------- reference problems


def _time_to(t: dict | None) -> str:
    """A ``time_to`` record: ``'1,352 s (interpolated)'`` or ``'not reached (1.3 % at the finest)'``."""
    if not t:
        return DASH
    if finite(t.get("wall_time_s")):
        return f"{secs(t['wall_time_s'])}: {t.get('status', '')}"
    if finite(t.get("error_at_finest_compared")):
        return f"{t.get('status', 'not reached')} ({pct(t['error_at_finest_compared'])} at the finest)"
    return t.get("status", DASH)


@section("convergence", "Error against run time: the reference problems", "convergence/results/error_vs_runtime.json",
         lambda d: f"python benchmarks/convergence/error_vs_runtime.py --threads {d['environment'].get('n_threads', 1)}"
                   f" --repeats {d['settings'].get('repeats')}",
         figure="convergence/results/error_vs_runtime.png",
         question="How does the error of each reference problem fall with dx and the CFL factor, against run time?")
def render_error_vs_runtime(data: dict, ctx) -> list[str]:
    st = data.get("settings") or {}
    target = st.get("target_error")
    rows = []
    for name, p in data["problems"].items():
        s = p["summary"]
        t = s.get("time_to_1pct") or {}
        rows.append([name, p["precision"], fx(s.get("observed_order_dx"), 2), fx(s.get("observed_order_dx_finest3"), 2),
                     fx(s.get("error_time_slope"), 2), _time_to(t),
                     fx(t.get("dx"), 4, unit="m") if finite(t.get("dx")) else DASH,
                     fx(s.get("observed_order_cfl_of_change"), 2)])
    out = table(["problem", "precision", "order in dx", "order, finest three", "slope of log error against log time",
                 f"stepping time to {pct(target, 0)} error", "at dx", "order in the CFL factor"], rows)
    out += ["", env_note(data)] + reference_checks(data["problems"]) + ["",
            f"dx halving at CFL {fx(st.get('cfl_dx_ladder'), 1)}, {st.get('particles_per_cell_per_axis')} particles "
            f"per cell and axis; the CFL ladder ({', '.join(fx(c, 1) for c in st.get('cfl_ladder', []))}) at one dx. "
            f"Wall time: stepping only, median of {st.get('repeats')} runs, {data['environment'].get('n_threads')} "
            "CPU thread(s). The references:", ""]
    out += [f"- `{name}`: {p['reference']}." for name, p in data["problems"].items()]
    for name, p in data["problems"].items():
        out += ["", f"`{name}`, every level:", ""]
        lv = [("dx", r) for r in p["dx_ladder"]] + [("CFL", r) for r in p["dt_ladder"]]
        out += table(["ladder", "dx (m)", "CFL", "mean dt (s)", "steps", "particles", "error", "wall (s)",
                      "M particle-steps/s"],
                     [[k, f"{r['dx']:.5g}", fx(r["cfl"], 1), f"{r['dt_mean_s']:.3g}", count(r["steps"]),
                       count(r["n_particles"]), spct(r["signed_error"], 3), f"{r['wall_time_s']:.3g}",
                       fx(r["particle_steps_per_s"], 2, 1e-6)] for k, r in lv])
    return out


#: The reference problems' pass line: at least first order in dx (linear shape functions; 0.9 allows the
#: fit's scatter) and the finest level within 1 % of the exact answer
ORDER_MIN, FINEST_ERROR_MAX = 0.9, 0.01


def reference_checks(problems: dict) -> list[str]:
    """The pass lines of the reference problems against their exact answers (:data:`ORDER_MIN`, ...)."""
    orders = {n: p["summary"].get("observed_order_dx") for n, p in problems.items()}
    finest = {n: abs(p["dx_ladder"][-1]["signed_error"]) for n, p in problems.items()
              if p["dx_ladder"] and finite(p["dx_ladder"][-1].get("signed_error"))}
    out = [""]
    if orders and all(finite(o) for o in orders.values()):
        out.append(check_line("order in dx", f"at least {fx(ORDER_MIN, 1)} in every problem",
                              min(orders.values()) >= ORDER_MIN,
                              ", ".join(f"`{n}` {fx(o, 2)}" for n, o in orders.items())))
    if finest:
        out.append(check_line("finest level against the exact answer", f"within {pct(FINEST_ERROR_MAX, 0)} in every "
                              "problem", max(finest.values()) <= FINEST_ERROR_MAX,
                              ", ".join(f"`{n}` {pct(e, 3)}" for n, e in finest.items())))
    return out


# ----------------------------------------------------------------------------- the snow ladders
#: quantity -> (label, scale, unit, decimals), per ladder.
QUANTITIES = {
    "pst": {"critical_cut": ("critical cut", 1.0, "m", 3), "speed": ("crack speed", 1.0, "m/s", 1),
            "touchdown": ("touchdown behind the front", 1.0, "m", 3),
            "collapse_height": ("collapse height (outside the far end zone)", 1e3, "mm", 2)},
    "shear": {"peak": ("peak shear stress", 1.0, "Pa", 1),
              "delta_s": ("softening slip delta_s (the interior's bond)", 1e3, "mm", 3),
              "delta_s_whole_layer": ("delta_s, the whole layer's bond", 1e3, "mm", 3),
              "collapse": ("collapse 1 - J_P", 1.0, "", 3)},
}


def ladder_levels(data: dict, name: str, precision: str = "float32") -> list[dict]:
    """The ladder's levels of one precision, coarsest first."""
    return sorted((r for r in data["ladders"][name] if r["precision"] == precision), key=lambda r: r["level"])


def _value(rec: dict, key: str, spec) -> str:
    label, scale, unit, nd = spec
    if key == "critical_cut" and finite(rec.get(key)):
        lo, hi = rec["critical_cut_bracket"]
        return bracket(rec[key], lo, hi, nd)
    return fx(rec.get(key), nd, scale, unit)


def changes(values) -> list[float]:
    """Relative change from each level to the next (where both are finite)."""
    return [b / a - 1.0 for a, b in zip(values, values[1:], strict=False) if finite(a) and finite(b) and a != 0]


def _changes(values) -> str:
    ch = changes(values)
    return ", ".join(spct(c) for c in ch) if ch else DASH


def _overlap(a: dict, b: dict) -> bool:
    """The two levels' critical-cut brackets share more than an end point: their change is not resolved."""
    (a0, a1), (b0, b1) = a["critical_cut_bracket"], b["critical_cut_bracket"]
    return max(a0, b0) < min(a1, b1) - 1e-9 * abs(min(a1, b1))   # (a shared end point, in round-off, is not)


def _half_width(rec: dict) -> float:
    lo, hi = rec["critical_cut_bracket"]
    return 0.5 * (hi - lo) / rec["critical_cut"]


def _bracketed(levels: list[dict], s: dict, errs: list[str], targets) -> tuple[str, list[str], list[str]]:
    """The critical cut's changes, errors and times to each error where its bisection brackets decide them: a
    change between levels whose brackets overlap is not resolved, nor an error below the finest's half width."""
    runs = [r for r in levels if finite(r.get("critical_cut"))]
    ch = [spct(b["critical_cut"] / a["critical_cut"] - 1.0) + (" (brackets overlap: not resolved)"
                                                                 if _overlap(a, b) else "")
          for a, b in zip(runs, runs[1:], strict=False)]
    fin = runs[-1] if runs else None
    out = []
    for r, e in zip(levels, errs, strict=True):
        if fin is None or not finite(r.get("critical_cut")):
            out.append(e)
        elif r is fin:
            out.append(f"reference (bracket +/-{pct(_half_width(fin))})")
        else:
            out.append(f"{e}: not resolved (brackets overlap)" if _overlap(r, fin) else e)
    hw = _half_width(fin) if fin else None
    times = [f"not resolved: the finest bracket is +/-{pct(hw)}" if hw is not None and hw > float(k.rstrip("%")) / 100
             else _time_to(s["time_to"].get(k)) for k in targets]
    return ", ".join(ch) if ch else DASH, out, times


def _cells(rec: dict) -> str:
    return f"{rec['cells_across_layer']:g} cells"


def render_ladder(data: dict, name: str) -> list[str]:
    """The tables of one ladder: its levels, the quantities per level, their errors and times to 5 % and 1 %."""
    levels = ladder_levels(data, name)
    summ = data["summary"][name]
    heads = [_cells(r) for r in levels]
    out = table(["level", "dx (m)", "particles", "steps", "wall time", "M particle-steps/s"],
                [[_cells(r), f"{r['dx']:g}", count(r["n_particles"]), count(r["steps"]), secs(r["wall_time_s"]),
                  fx(r["particle_steps_per_s"], 1, 1e-6)] for r in levels])
    out += [""]
    rows, errs = [], []
    targets = next(iter(summ.values()))["time_to"].keys()
    for key, spec in QUANTITIES[name].items():
        s = summ.get(key)
        if s is None:
            continue
        use_rich = s.get("reference_used_for_time_to") == "richardson"
        rich = fx(s.get("richardson"), spec[3], spec[1], spec[2])
        e = [pct(x) for x in (s["error_vs_richardson"] if use_rich else s["error_vs_finest"])]
        chg, times = _changes(s["values"]), [_time_to(s["time_to"].get(k)) for k in targets]
        if key == "critical_cut" and not use_rich:
            chg, e, times = _bracketed(levels, s, e, targets)
        rows.append([spec[0], *[_value(r, key, spec) for r in levels], chg, fx(s.get("observed_order"), 2), rich])
        errs.append([spec[0], *e, "extrapolated " + rich if use_rich else "the finest level", *times])
    out += table(["quantity", *heads, "changes per halving", "observed order", "extrapolated"], rows)
    growing = [QUANTITIES[name][k][0] for k, s in summ.items() if k in QUANTITIES[name]
               and len(changes(s["values"])) >= 2
               and all(abs(b) > abs(a) for a, b in zip(changes(s["values"]), changes(s["values"])[1:], strict=False))]
    if growing:
        out += ["", "The change grows with every halving (no observed order, not converging at these levels): "
                + "; ".join(growing) + "."]
    out += ["", "Errors against the reference (the Richardson extrapolation where the three finest levels change "
            "monotonically with an order in the range `mpm_warp.studies.convergence.richardson` accepts, else the "
            "finest level), and the wall time to each error on this CPU:", ""]
    out += table(["quantity", *heads, "reference", *[f"time to {k.replace('%', ' %')}" for k in targets]], errs)
    notes = [f"{_cells(r)}: {r['note']}" for r in levels if r.get("note")]
    if notes:
        out += ["", "Notes of the levels: " + "; ".join(notes) + "."]
    out += _precision(data, name, levels)
    return out


def _precision(data: dict, name: str, levels: list[dict]) -> list[str]:
    """float32 against float64 at the level run in both."""
    out = []
    for r64 in ladder_levels(data, name, "float64"):
        r32 = next((r for r in levels if r["level"] == r64["level"]), None)
        if r32 is None:
            continue
        parts = []
        for key, spec in QUANTITIES[name].items():
            a, b = r32.get(key), r64.get(key)
            if key == "critical_cut" and finite(a):
                same = list(r32["critical_cut_bracket"]) == list(r64["critical_cut_bracket"])
                parts.append(f"{spec[0]}: {'the same bracket' if same else 'different brackets'}")
            elif finite(a) and finite(b) and b != 0:
                parts.append(f"{spec[0]} {abs(a / b - 1):.1e} apart")
        out += ["", f"float32 against float64 at {_cells(r64)} (relative): " + "; ".join(parts) + "."]
    return out


def field_level_errors(data: dict) -> list[str] | None:
    """The PST's error per quantity at the field protocol's resolution (``field_level``, off the ladder), as
    ``'critical cut 5.6 %'``; None where that level has not run."""
    fl = data.get("field_level")
    if not fl:
        return None
    runs = [r for r in ladder_levels(data, "pst") if finite(r.get("critical_cut"))]
    out = []
    for key, spec in QUANTITIES["pst"].items():
        e = fl["errors"].get(key)
        if e is None:
            continue
        if not finite(e["error"]):
            out.append(f"{spec[0]}: no value")
        elif key == "critical_cut" and runs and finite(fl["record"].get(key)) and _overlap(fl["record"], runs[-1]):
            out.append(f"{spec[0]} {pct(e['error'])} (the brackets overlap: not resolved)")
        else:
            out.append(f"{spec[0]} {pct(e['error'])}")
    return out


def _field_level(data: dict) -> list[str]:
    """The paragraph of the field protocol's resolution below the PST ladder."""
    errs = field_level_errors(data)
    if errs is None:
        return []
    r = data["field_level"]["record"]
    vals = [f"{spec[0]} {_value(r, key, spec)}" for key, spec in QUANTITIES["pst"].items()]
    note = f" ({r['note']})" if r.get("note") else ""
    return ["", f"**At the field protocol's resolution** ({_cells(r)} across the layer, dx {fx(r['dx'], 1, 1e3)} mm, "
            "a level off the halving ladder, `--field-level`; the field batch resolves every weak layer so, "
            f"docs/field.md): {'; '.join(vals)}{note}. Off each quantity's reference in the table above: "
            f"{'; '.join(errs)}. {count(r['n_particles'])} particles, {secs(r['wall_time_s'])} of wall time "
            f"(commit {str(r.get('git_commit'))[:7]}{_load(data.get('environment_field_level'))})."]


def _load(env: dict | None) -> str:
    """``', load average 2.4 at the start and 2.5 at the end'`` of an environment record ('' without one)."""
    if not env or not env.get("load_average_1_5_15_min"):
        return ""
    end = env.get("load_average_at_end_1_5_15_min")
    return (f", {env['date'][:10]}, load average {fx(env['load_average_1_5_15_min'][0], 1)} at the start"
            + (f" and {fx(end[0], 1)} at the end" if end else "") + " on the 2 cores")


@section("convergence", "Error against run time: the snow ladders", "convergence/results/error_vs_runtime_snow.json",
         "python benchmarks/convergence/error_vs_runtime_snow.py",
         figure="convergence/results/error_vs_runtime_snow.png",
         question="How fine must a PST and a shear test be for a given error, and how long does that take? "
                  "(dx halving, 2D, float32)")
def render_snow_ladders(data: dict, ctx) -> list[str]:
    out = []
    if "shear" in data["ladders"]:
        out += ["**Shear test** (SI Note 2's case, the whole push), per number of cells across the layer:", ""]
        out += render_ladder(data, "shear") + [""]
    if "pst" in data["ladders"]:
        lv = ladder_levels(data, "pst")
        over = lv[0].get("speed_over") if lv else None
        out += ["**Flat PST** (the ladder PST: `pst_flat`'s slab, layer and saw on a shorter column, "
                "`mpm_warp.studies.snow.LADDER_PST`); each level one bisection of the critical cut plus the base run"
                + (f", whose crack speed is the mean over {fx(over[0], 1)}-{fx(over[1], 1)} m" if over else "") + ":",
                ""]
        out += render_ladder(data, "pst") + _field_level(data) + [""]
    out += [env_note(data, verb="last written") + " The levels ran on several dates and commits (each level's "
            "`git_commit` in the JSON); wall times are upper bounds on the shared CPU."]
    return out


# ----------------------------------------------------------------------------- the mesh study
@section("convergence", "The weak layer's collapse under a slab: mesh study", "convergence/results/mesh_study.json",
         "python benchmarks/convergence/mesh_study.py", figure="convergence/results/mesh_study.png",
         question="How does the weak layer's collapse depend on dx, xi and the load (Gaume et al. 2018, SI Note 3)?")
def render_mesh_study(data: dict, ctx) -> list[str]:
    cells = sorted({c for s in data["summary"] for c in s["cells"]})
    rows = []
    for s in data["summary"]:
        err = dict(zip(s["cells"], s["error"], strict=True))
        rows.append([fx(s["xi"], 2), fx(s["rho_slab"], 0), s["precision"], fx(s["W_mean"], 0),
                     fx(s["collapse_theory"], 4), *[spct(err.get(c)) for c in cells],
                     pct(s.get("spread_8_cells_up")), fx(s.get("observed_order_4_cells_up"), 2)])
    out = [f"Plain Cam-Clay layer of {fx(data['set_up']['D_wl'], 3, 1e2)} cm under an elastic slab in a laterally "
           f"confined column, gravity ramped; the layer's mean 1 - J_P against the closed form `{data['closed_form']}`"
           ".", ""]
    out += table(["xi", "slab rho (kg/m^3)", "precision", "load W (Pa)", "closed form 1 - J_P",
                  *[f"error at {c} cells" for c in cells], "spread from 8 cells on", "order from 4 cells on"], rows)
    out += ["", env_note(data), "", "The error of the float64 cases, by cells across the layer:", ""]
    f64 = [s for s in data["summary"] if s["precision"] == "float64"]
    for c in cells:
        e = [dict(zip(s["cells"], s["error"], strict=True)).get(c) for s in f64]
        if any(finite(x) for x in e):
            out.append(f"- {c} cells: {ratio_range([100 * x for x in e], 1)} %.")
    return out + mesh_checks(data["summary"])


#: The mesh study's pass line: from 16 cells across the layer on, every case within this of the closed form,
#: converging at least at first order from 4 cells on (the MPM's linear shape functions)
MESH_TOLERANCE = 0.03


def mesh_checks(summary: list[dict]) -> list[str]:
    """The pass lines of the mesh study against the closed form (criteria: :data:`MESH_TOLERANCE`, order 1)."""
    fine = [(s, c, e) for s in summary for c, e in zip(s["cells"], s["error"], strict=True) if c >= 16 and finite(e)]
    orders = [s.get("observed_order_4_cells_up") for s in summary]
    out = [""]
    if fine:
        worst = max(abs(e) for _, _, e in fine)
        out.append(check_line("collapse against the closed form", f"every case within {pct(MESH_TOLERANCE, 0)} of "
                              "the closed form from 16 cells across the layer on", worst <= MESH_TOLERANCE,
                              f"worst {pct(worst)}"))
    if all(finite(o) for o in orders):
        out.append(check_line("convergence order", "at least first order from 4 cells on in every case",
                              min(orders) >= 1.0, f"{fx(min(orders), 2)}-{fx(max(orders), 2)}"))
    return out
