"""Sections of the field data: how many real PST records become runnable columns, and why not the others."""

from __future__ import annotations

from .core import section
from .fmt import count, env_note, fx, pct, secs, table

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
