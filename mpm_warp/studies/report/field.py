"""Sections of the field data: how many real PST records become runnable columns, and why not the others."""

from __future__ import annotations

from statistics import median

from ...scenes.pst.outcome import FIELD_CLASSES
from .convergence import field_level_errors
from .core import section
from .fmt import count, env_note, fx, pct, secs, spct, table
from .pages import ref

#: the share of End/SF/Arr records that must become runnable columns (issue: real pits in)
TARGET = 0.80


@section("field", "Field pits in", "field/results/field_census.json",
         lambda d: f"python benchmarks/field/census.py DIR  # DIR: the {count(d['census']['files'])} pits",
         question="How many of a season's real PST records can the model set up, and why not the others?")
def render_census(data: dict, ctx) -> list[str]:
    c, r = data["census"], data["readers"]
    b = c["before"]
    frac = c["runnable_fraction_of_field_outcomes"]
    out = table(["reader", "files read", "PST records", "layers", "wall time"],
                [[name, f"{count(v['files_read'])} of {count(c['files'])}", count(v["pst_records"]),
                  count(v["layers"]), secs(v["wall_s"])] for name, v in r.items()])
    out += ["", f"Before: {count(b['files_read'])} of {count(b['files'])} files read and {count(b['records_set_up'])} "
            f"of {count(b['records_read'])} records set up (the snowprofile reader, the whole profile layer as the "
            f"weak layer). Now: {count(c['files'] - c['files_unreadable'])} of {count(c['files'])} files read, "
            f"{count(c['runnable'])} of {count(c['field_outcome_records'])} End/SF/Arr records set up as columns "
            f"({pct(frac)}), weak layer calibrated.", ""]
    by = c["records_by_outcome"]
    rows = [[o, count(by.get(o, 0)), count(c["runnable_by_outcome"].get(o, 0)),
             pct(c["runnable_by_outcome"].get(o, 0) / by[o]) if by.get(o) else "-"] for o in ("End", "SF", "Arr", "X")]
    out += table(["outcome", "records", "runnable columns", "share"], rows)
    verdict = "pass" if frac >= TARGET else "fail"
    out += ["", f"**Check:** at least {pct(TARGET, 0)} of the End/SF/Arr records become runnable columns: "
            f"{pct(frac)}, **{verdict}**.", ""]
    ex = c["refusal_examples"]
    rows = [[k, count(n), ", ".join(f"{o} {count(m)}" for o, m in c["refusals_by_outcome"].get(k, {}).items()),
             f"`{ex[k][0]}`" if ex.get(k) else "-"] for k, n in c["refusals"].items()]
    out += table(["reason", "records", "by outcome", "an example"], rows)
    w, d = c["implied_w_f"], c["weak_layer_thickness_m"]
    out += ["", f"- **Weak layer:** {', '.join(f'{k}: {count(v)}' for k, v in c['weak_layer_choice'].items())} "
            f"(thickness {fx(d['min'], 1, 100)}-{fx(d['max'], 1, 100)} cm, median {fx(d['median'], 1, 100)} cm).",
            f"- **Implied fracture energy:** read back for {count(w['read'])} columns (median "
            f"{fx(w['median_J_m2'], 3)} J/m^2, 10-90 % {fx(w['p10'], 3)}-{fx(w['p90'], 3)}, range "
            f"{fx(w['min'], 3)}-{fx(w['max'], 2)}); not read "
            f"for {', '.join(f'{count(v)} ({k})' for k, v in w['not_read'].items())}: those run with the default.",
            f"- **Fallback densities:** {count(c['columns_with_density_fallback'])} columns have a slab layer whose "
            "density is a flagged fallback (no hardness, no grain, or a grain without a law; docs/profiles.md).",
            f"- Setting up every record, calibration included, took {secs(c['wall_s'])}.", "", env_note(data)]
    return out


def _ba(s: dict) -> str:
    v = s.get("balanced_accuracy")
    return "-" if v is None else f"{v:.2f}"


def _recall(s: dict, c: str) -> str:
    v = (s.get("recall") or {}).get(c)
    return "-" if v is None else f"{v:.2f}"


#: the median field case's wall time the issue asks for (s, 2 CPU cores)
CASE_BUDGET_S = 60.0


def _batch_command(d: dict, out: str = "") -> str:
    sel = d["selection"]
    return (f"python benchmarks/field/field_batch.py DIR --runs RUNDIR --per-class {sel['per_class']} --seed "
            f"{sel['seed']}" + (" --no-measured" if not sel.get("measured") else "")
            + (f" --workers {d['workers']}" if d.get("workers") else "")
            + (f" --threads {d['threads_per_case']}" if d.get("threads_per_case", 1) != 1 else "")
            + (f" --limit {sel['limit']}" if sel.get("limit") else "")
            + (" --finished-only" if sel.get("finished_only") else "")
            + ("" if _rigid(sel) else " --elastic-substratum")
            + f" --pre-cut-share {(sel.get('protocol') or {}).get('pre_cut_share', 0.0):g}"
            + (f" --out {out}" if out else ""))


def _rigid(sel: dict) -> bool:
    """Whether the batch ran its columns on a rigid base (a file from before the protocol said so: the old snow)."""
    return bool((sel.get("protocol") or {}).get("rigid_base"))


def _base(sel: dict) -> str:
    share = (sel.get("protocol") or {}).get("pre_cut_share")
    pre = (f", each pre-cut {share:g} of weac's critical cut" if share else
           ", sawn from the end (no pre-cut)" if _rigid(sel) else "")
    return (f"The columns ran on a rigid base{pre}." if _rigid(sel) else
            "The columns ran on the profile's old snow, sawn from the end, as the field protocol did before the "
            "rigid base and the pre-cut (the command says so).")


def _interval(iv) -> str:
    return "" if not iv else f" [{iv[0]:.2f}, {iv[1]:.2f}]"


def _signed(v: float) -> str:
    return "0.00" if abs(v) < 0.005 else f"{v:+.2f}"


def _differences(unc: dict) -> str:
    """The model less each baseline, with its bootstrap interval (mpm_warp.field.uncertainty)."""
    diffs = unc.get("differences") or {}
    if not diffs:
        return ""
    words = {"majority": "the majority class", "weac_static": "weac's static rule"}
    parts = [f"{words.get(k, k)} {_signed(v['value'])} [{_signed(v['interval'][0])}, {_signed(v['interval'][1])}], "
             "higher in "
             f"{fx(100 * v['share_above'], 0)} % of the resamples" for k, v in diffs.items()]
    return (f" The model less each baseline, on the same cases resampled within each observed class "
            f"({count(unc['resamples'])} resamples, {fx(100 * unc['level'], 0)} % intervals): " + "; ".join(parts)
            + ". An interval that holds 0 does not tell the model from that baseline.")


def _judged(data: dict) -> bool:
    """Whether the batch ran its whole draw of at least 150 columns: every drawn column was run or refused in field
    terms when built (a refusal is the protocol's answer for that column, not a case left out)."""
    sel = data["selection"]
    drawn = sum(sel.get(k, 0) for k in ("measured", *FIELD_CLASSES))
    refused = len(data.get("refused_at_build") or [])
    return not sel.get("finished_only") and drawn >= 150 and data["scores"]["cases"] + refused >= drawn


def _verdict(data: dict, m, best: float) -> str:
    if not _judged(data):
        return "open"
    return "pass" if m is not None and m > best else "fail"


def _case_median(sc: dict) -> tuple[float | None, str, str]:
    """The median case's wall time the check reads, what it is over, and the medians of the other configurations.

    Where some cases ran one at a time on 2 threads (one worker: the case had both cores), the check reads theirs;
    otherwise the median over all cases."""
    groups = sc.get("wall_s_by_config") or []
    both = [g for g in groups if g["threads"] == 2 and g["workers"] == 1]
    if not both or len(groups) < 2:
        return sc["wall_s"]["median"], "", ""
    rest = "; ".join(f"{count(g['cases'])} case{'s' if g['cases'] != 1 else ''} on {_threads(g['threads'] or 1)}"
                     f" each, {_workers(g['workers']) if g['workers'] else 'workers not recorded'}: median "
                     f"{secs(g['median'])}" for g in groups if g not in both)
    return (both[0]["median"], f", one case at a time on 2 threads ({count(both[0]['cases'])} cases)",
            f"the others: {rest}; ")


def _threads(n: int) -> str:
    return "one thread" if n == 1 else f"{n} threads"


def _workers(n) -> str:
    return "one worker per core" if not n else f"{n} worker{'s' if n != 1 else ''}"


def _cases(n: int) -> str:
    return "the one case" if n == 1 else f"the {n} cases"


LADDER = "convergence/results/error_vs_runtime_snow.json"
RESOLUTION = "field/results/field_resolution.json"


def _resolution(data: dict, ctx) -> list[str]:
    """The cells across the weak layer the cases ran at, and the snow ladder's error there."""
    cells = [c["setup"].split(" cells across")[0] for c in data.get("cases", [])
             if c.get("status") == "ok" and " cells across" in (c.get("setup") or "")]
    if not cells:
        return []
    n = {k: cells.count(k) for k in sorted(set(cells), reverse=True)}
    used = ", ".join(f"{count(v)} at {k} cells" for k, v in n.items())
    want = data["selection"].get("protocol", {}).get("cells_across")
    ladder = ctx.load(LADDER) or {}
    errs = field_level_errors(ladder)
    lv = (ladder.get("field_level") or {}).get("record", {})
    if errs and want is not None and round(lv.get("cells_across_layer", -1)) == want:
        said = (f"On the snow ladder's PST at {want} cells (a 30 cm slab on a 6 cm layer, dx {fx(lv['dx'], 0, 1e3)} "
                f"mm; {ref('Error against run time: the snow ladders')}), the error against the ladder's "
                f"reference: {'; '.join(errs)}. A field column's layer is thinner, so its slab has more cells "
                "than the ladder's at the same cells across the layer.")
    else:
        said = f"The snow ladder has no level at {want} cells across the layer: the resolution's error is not stated."
    budget = (f" ({want - 1} where {want} would exceed the particle budget)" if want and str(want - 1) in n else "")
    res = ctx.load(RESOLUTION)
    if res and res.get("cases"):
        same = sum(c["before"]["predicted"] == c["after"]["predicted"] for c in res["cases"])
        said += (f" On field columns themselves, {same} of {len(res['cases'])} drawn cases kept their class at "
                 f"{res['switch']['value']} cells across the weak layer "
                 f"({ref('The grid: the same columns at 6 cells across the weak layer')}).")
    return ["", f"- **Resolution:** cells across the weak layer: {used}{budget}. " + said]


def _command_to(out: str):
    return lambda d: _batch_command(d, out)


@section("field", "Field outcomes against the observers", "field/results/field_batch.json", _batch_command,
         question="Does the model predict a real PST's outcome (END, SF, ARR) better than the majority class and "
                  "weac's static rule?")
def render_batch(data: dict, ctx) -> list[str]:
    sc, sel = data["scores"], data["selection"]
    unc = sc.get("uncertainty") or {}
    names = (("model", "the model (MPM, field protocol)"), ("majority", "majority class"),
             ("weac_static", "weac's static rule"))
    rows = [[label, count(sc[key]["n"]), _ba(sc[key]) + _interval((unc.get("intervals") or {}).get(key)),
             _recall(sc[key], "END"), _recall(sc[key], "SF"), _recall(sc[key], "ARR")] for key, label in names]
    built = data.get("refused_at_build") or []
    drawn = (f"drawn from the {count(sel['runnable'])} records set up before calibration: {sel.get('measured', 0)} "
             f"with measured slab densities, and {sel.get('END', 0)} END, {sel.get('SF', 0)} SF, {sel.get('ARR', 0)} "
             f"ARR by class (seed {sel['seed']})")
    if sel.get("finished_only"):
        n_sel = sel.get("measured", 0) + sel.get("END", 0) + sel.get("SF", 0) + sel.get("ARR", 0)
        out = [f"Cases: {count(sc['cases'])} scored ({count(sc['failed'])} failed) of the {count(n_sel)} selected, "
               f"{drawn}. **A batch stopped early:** these are the cases whose runs had finished, scored with "
               "`--finished-only`; the selection runs its classes interleaved, so the finished ones are spread "
               "over the three classes, but the rest are not run yet.", ""]
    else:
        out = [f"Cases: {count(sc['cases'])} scored ({count(sc['failed'])} failed), {drawn}; {count(len(built))} of "
               "those refused when built (the per-case budget, or the calibration), in the JSON's "
               "`refused_at_build`.", ""]
    out[-2] += " " + _base(sel)
    level = f" ({fx(100 * unc['level'], 0)} % interval)" if unc.get("intervals") else ""
    out += table(["predictor", "cases", f"balanced accuracy{level}", "recall END", "recall SF", "recall ARR"], rows)
    conf = sc["model"]["confusion"]
    out += ["", "The model's confusion matrix (rows: observed; columns: predicted):", ""]
    out += table(["observed", *conf["columns"]], [[r, *[count(n) for n in c]] for r, c in zip(conf["rows"],
                                                                                          conf["counts"], strict=True)])
    m, best = sc["model"]["balanced_accuracy"], max(sc["majority"]["balanced_accuracy"] or 0.0,
                                                    sc["weac_static"]["balanced_accuracy"] or 0.0)
    med, alone, by_config = _case_median(sc)
    out += ["", f"**Check:** the model's balanced accuracy above both baselines': {_ba(sc['model'])} against "
            f"{best:.2f}, **{_verdict(data, m, best)}**"
            + (" (too few cases to tell: a whole draw of at least 150 columns, 50 per class, is needed; a balanced "
               "accuracy is over the observed classes present)" if not _judged(data) else
               f" (the whole draw: {count(len(data.get('refused_at_build') or []))} of its columns refused when "
               f"built, {count(sc['cases'])} scored)") + "." + _differences(unc), "",
            f"**Check:** the median field case within {CASE_BUDGET_S:g} s of wall time{alone}: {secs(med)}, "
            f"**{'pass' if med is not None and med <= CASE_BUDGET_S else 'fail'}** ({by_config}particle budget "
            f"{count(sel['max_particles'])}, {_threads(data.get('threads_per_case', 1))} per case, "
            f"{_workers(data.get('workers'))}; "
            + (f"{fx(data['cases_per_hour'], 0)} cases per hour)." if data.get("cases_per_hour") else
               f"{count(data['resumed_cases'])} cases were run by earlier invocations of the same command (a batch "
               "stopped and resumed), which this one found finished and scored: the batch's rate is not measured "
               "here; each case's wall time is its own run's, on this shared machine).")]
    ran = [c for c in data.get("cases", []) if c.get("status") == "ok" and c.get("particles") and c.get("steps")]
    if alone:   # the cost of the cases the check reads
        ran = [c for c in ran if c.get("threads") == 2 and c.get("workers") == 1]
    if ran:
        work = median([c["particles"] * c["steps"] for c in ran])
        ns = median([c["wall_s"] / (c["particles"] * c["steps"]) * 1e9 for c in ran])
        over = "the cases" + (" run one at a time on 2 threads" if alone else "")
        out += ["", f"- **Cost:** medians over {over}: {count(median([c['particles'] for c in ran]))} particles, "
                f"{count(median([c['steps'] for c in ran]))} steps, {fx(work / 1e9, 2)} G particle-steps (particles "
                f"times steps), {fx(ns, 0)} ns of wall time a particle-step. {CASE_BUDGET_S:g} s at that rate is "
                f"{fx(CASE_BUDGET_S / ns, 2)} G particle-steps: the median case's work is "
                f"{fx(work * ns / 1e9 / CASE_BUDGET_S, 1)}x that."]
    out += _resolution(data, ctx)
    read = [c for c in data.get("cases", []) if c.get("w_f_source") == "read back" and c.get("runaway_cut")
            and c.get("recorded_cut")]
    if read:
        d = [c["runaway_cut"] / c["recorded_cut"] - 1.0 for c in read]
        span = spct(d[0]) if len(d) == 1 else f"{spct(min(d))} to {spct(max(d))}"
        out += ["", f"- **Where the crack ran away:** in {_cases(len(read))} whose fracture energy was read back "
                f"from the recorded cut (weac's G there), the run's runaway cut is {span} "
                "off the recorded one, where weac's energy criterion puts it exactly (it gave the fracture energy). "
                "What follows the runaway is the model's own."]
    out += ["", env_note(data)]
    return out


section("field", "Field outcomes: every column with measured slab densities", "field/results/measured/field_batch.json",
        _command_to("benchmarks/field/results/measured"),
        question="On the records whose every slab density was measured in the pit (no density from hardness or "
                 "grain), does the model predict the observed outcome?")(render_batch)

MEASURED = "field/results/measured/field_batch.json"


@section("field", "Field batch: one worker of two threads", "field/results/rate/field_batch.json",
         _command_to("benchmarks/field/results/rate"), question="How long does a field case take, and how many cases "
         "an hour does the batch run, with one Dask worker whose cases each step on both cores?")
def render_rate(data: dict, ctx) -> list[str]:
    """:func:`render_batch`, and the same cases against their run in the measured-density batch: each case's wall
    time there over here, where both batches ran one protocol."""
    out = render_batch(data, ctx)
    other = ctx.load(MEASURED) or {}
    there = {c["id"]: c for c in other.get("cases", []) if c.get("status") == "ok"}
    pairs = [(there[c["id"]]["wall_s"], c["wall_s"]) for c in data.get("cases", [])
             if c.get("status") == "ok" and c["id"] in there]
    if not pairs:
        return out
    proto, proto_there = data["selection"].get("protocol"), other["selection"].get("protocol")
    if proto != proto_there:
        out[-1:-1] = ["- **Against the measured-density batch:** not compared: the two batches ran different field "
                      "protocols (the JSONs' `selection.protocol`), so a case's wall time there is another run's.", ""]
        return out
    config = (f"{_workers(other.get('workers'))} of {_threads(other.get('threads_per_case', 1))}")
    r = sorted(a / b for a, b in pairs)
    med = median(r)
    rate = (f", {fx(other['cases_per_hour'], 0)} cases an hour over its {count(other['scores']['cases'])} cases"
            if other.get("cases_per_hour") else "")
    out[-1:-1] = [f"- **Against {config}:** the same {len(pairs)} cases took "
                  f"{', '.join(secs(a) for a, _ in pairs)} each in the measured-density batch ({config}{rate}) and "
                  f"{', '.join(secs(b) for _, b in pairs)} here: each case {fx(med, 2)}x "
                  f"{'sooner' if med >= 1 else 'later'} here (median; {fx(r[0], 2)}-{fx(r[-1], 2)}x).", ""]
    return out


def _group_row(name: str, g: dict) -> list[str]:
    ratio = (f"{fx(g['runaway_over_recorded'], 2)} ({g['runaway_over_recorded_cases']})"
             if g.get("runaway_over_recorded") is not None else "-")
    return [name, count(g["cases"]), fx(g["slab_depth_m"], 0, 100), fx(g["slab_density"], 0), fx(g["slope_deg"], 0),
            pct(g["cut_share"], 0) if g.get("cut_share") is not None else "-", count(g["w_f_read_back"]), ratio,
            f"{g['slab_cracked']} of {g['slab_checked']}", count(g["weac_static_SF"]),
            f"{g['energy_stops']} of {g['energy_checked']}" if "energy_checked" in g else "-"]


@section("field", "Where the model and the observers disagree", "field/results/field_disagreements.json",
         lambda d: "python benchmarks/field/disagreements.py " + " ".join(
             "RUNDIR" + str(k + 1) for k in range(len(d["runs"]))) + " --data DIR  # " + ", ".join(
             f"RUNDIR{k + 1}: {r}" for k, r in enumerate(d["runs"])),
         question="What do the columns the model gets wrong have in common (docs/field.md)?")
def render_disagreements(data: dict, ctx) -> list[str]:
    heads = ["observed -> predicted", "cases", "slab depth (cm)", "slab density (kg/m^3)", "slope (deg)",
             "cut / column", "w_f read back", "runaway / recorded cut (cases)", "slab cracked", "weac static: SF",
             "G falls below w_f beyond the cut"]
    rows = [_group_row(f"{k} (all)", g) for k, g in data["by_observed"].items() if g["cases"]]
    rows += [_group_row(k.replace("->", " -> "), g) for k, g in data["by_pair"].items()]
    return (["Medians over each group of the batch's scored cases; counts where a column is a count. The slab cracked: "
             "its largest effective tensile stress reached its strength somewhere (kappa, docs/model.md §9), "
             "whether or not it broke through. G falls below w_f: weac's energy release rate (touchdown on), read at "
             "12 cuts from the recorded one to 5 cm before the far end, drops below the fracture energy the run "
             "took, so that a static energy balance alone would stop the crack (docs/field.md).", ""]
            + table(heads, rows) + _substratum(data.get("cost")) + ["", env_note(data, verb="computed")])


def _substratum(c: dict | None) -> list[str]:
    if not c or not c.get("cases"):
        return []
    lo, hi = c["substratum_share_range"]
    faster = (f"sets the time step in {c['substratum_sets_dt']} of {c['cases']} cases (by "
              f"{fx(c['c_p_over_slab_median_there'], 2)}x, median; up to {fx(c['c_p_over_slab_max'], 2)}x): those "
              "cases take that many more steps than their slab needs")
    median, spread = f"{pct(c['substratum_share_median'], 0)} of the column's height", f"{pct(lo, 0)}-{pct(hi, 0)}"
    rigid = c.get("rigid_base", 0)
    if rigid and rigid == c["cases"]:
        who = " and ".join(m.replace("_", " ") for m in c.get("faster_materials", [])) or "another material"
        return ["", "- **The column's cost beside the crack:** every run stands on a rigid base, so the profile's "
                f"snow below the weak layer ({median}, median; {spread}) is not run. A material faster than the slab "
                f"(its P-wave speed; here the {who}) {faster}."]
    return ["", f"- **The column's cost beside the crack:** the substratum (the profile's snow below the weak layer, "
            f"docs/profiles.md) is {median} (median; {spread}), and its P-wave speed, above the slab's, {faster}."]
