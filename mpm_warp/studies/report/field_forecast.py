"""Sections of the field outcome as a forecast: which mechanism carries the records' signal, and the probabilistic
scores of the model against the climatology, the majority class, weac's rule and the information bar."""

from __future__ import annotations

from ...field.scores import FIELD_CLASSES
from .core import section
from .fmt import check_line, env_note, fx, table

#: the forecasts in the order the tables list them
NAMES = ("model", "calibrated", "information_bar", "weac_static", "majority", "climatology")


def _iv(iv, nd: int = 2) -> str:
    return "" if not iv else f" [{fx(iv[0], nd)}, {fx(iv[1], nd)}]"


@section("field", "Why thin, light slabs break: each candidate mechanism against the records",
         "field/results/field_mechanisms.json",
         lambda d: "python benchmarks/field/mechanisms.py --data DIR",
         question="The observers' SF slabs are thin and light. Which quantity of the column, from the records, the "
                  "run, weac or a closed form of published laws, tells their SF records from their END records, and "
                  "how well? Nothing is fitted.",
         follows="The weak layer's stiffness: the same columns on a softer weak layer", page="field_slab")
def render_mechanisms(data: dict, ctx) -> list[str]:
    c = data["candidates"]
    rows = [[f"`{k}`", v["what"], v["direction"], fx(v["sf_vs_end"]["auc"], 3), fx(v["arr_vs_rest"]["auc"], 3),
             " / ".join(fx(v["median"][k2], 3) for k2 in FIELD_CLASSES)] for k, v in c.items()]
    n = data["counts"]
    out = [f"On the {sum(n.values())} scored columns of the development set (END {n['END']}, SF "
           f"{n['SF']}, ARR {n['ARR']}; `{data['cases_from']}`), each set up again from its pit. AUC: the chance "
           "that an SF record's value lies further in the candidate's direction than an END record's (0.5: no "
           "skill; below 0.5: the signal runs the other way); ARR against the rest in the same direction.", ""]
    out += table(["candidate", "what", "direction", "AUC SF vs END", "AUC ARR vs rest", "median END / SF / ARR"],
                 rows)
    best_record = max(c["slab_depth"]["sf_vs_end"]["auc"], c["slab_density"]["sf_vs_end"]["auc"])
    td = c["touchdown_distance"]["sf_vs_end"]["auc"]
    out += ["", check_line("a mechanism from published laws carries the records' SF signal",
                           "its SF-against-END AUC at least that of slab depth or density alone, the records' "
                           "own numbers", td >= best_record,
                           f"Heierli's touchdown distance {fx(td, 3)}, against {fx(best_record, 3)}"), ""]
    r = data["touchdown_rule"]
    out += [f"- **The touchdown rule** ({r['rule']}: the slab lands on its collapsed weak layer inside the column): "
            f"balanced accuracy {fx(r['balanced_accuracy'], 2)}, recall END {fx(r['recall']['END'], 2)}, SF "
            f"{fx(r['recall']['SF'], 2)}, ARR {fx(r['recall']['ARR'], 2)} on these {r['n']} columns.",
            *_bar_line(data.get("information_bar")),
            *_run_line(c),
            f"- **Brittleness** runs the other way ({fx(c['brittleness']['sf_vs_end']['auc'], 3)}): thin, light "
            "slabs are the least brittle by this measure (the shortest depth for their characteristic length), so "
            "brittleness does not explain why they break.", *_calibrated_lines(data.get("calibrated")), "",
            env_note(data)]
    return out


def _missing_note(missing: dict) -> str:
    """How many cases lacked each reading, where any did."""
    if not missing:
        return ""
    listed = ", ".join(f"`{k}` in {n} case{'s' if n != 1 else ''}" for k, n in missing.items())
    return f"; a missing reading takes the training folds' median ({listed})"


#: the calibration's table: the forecasts in order, and what each reads
CALIBRATED = {"calibrated": "the model's readings, calibrated", "run_readings": "the run's readings alone",
              "static_readings": "weac's and the closed forms' readings alone",
              "records_and_readings": "the records' four numbers and the model's readings",
              "information_bar": "the records' four numbers",
              "model": "the model's raw probability", "weac_static": "weac's static rule",
              "majority": "the majority class", "climatology": "the set's class shares"}


def _calibrated_lines(cal: dict | None) -> list[str]:
    """The model's readings calibrated (``mpm_warp.field.calibrated``) beside the bar and the raw forecasts, with
    the calibration's paired differences; none in an older file."""
    if not cal:
        return []
    sc, unc = cal["scores"], cal["uncertainty"]
    iv, diff = unc["intervals"], unc["differences"]
    rows = [[f"`{k}`", what, fx(sc[k]["rpss"], 2) + _iv(iv[k].get("rpss")),
             fx(sc[k]["balanced_accuracy"], 2) + _iv(iv[k].get("balanced_accuracy")),
             fx(sc[k]["auc"]["SF"], 2), fx(sc[k]["auc"]["ARR"], 2),
             " / ".join(fx(sc[k]["brier"][c], 3) for c in FIELD_CLASSES)] for k, what in CALIBRATED.items() if k in sc]
    missing = {k: n for k, n in cal.get("missing_readings", {}).items() if n}
    out = ["", "**The model's readings, calibrated** (`mpm_warp/field/calibrated.py`): the information bar's own "
           "regression and pit-grouped folds, reading the model's "
           f"{len(cal['readings'])} readings of the table above (every candidate but the records' depth and "
           "density) where the bar reads the records' four numbers. Its coefficients are statistics fitted on "
           "other pits, not physical parameters (docs/field.md). Intervals: 95 %, paired bootstrap within each "
           "class" + _missing_note(missing) + ".", ""]
    out += table(["forecast", "reads", "RPSS", "balanced accuracy", "AUC SF", "AUC ARR", "Brier END / SF / ARR"],
                 rows)
    out += [""]
    for k in ("information_bar", "model", "weac_static"):
        if k in diff:
            d = diff[k]
            out.append(f"- calibrated minus `{k}`: RPSS {fx(d['rpss']['value'], 2)}{_iv(d['rpss']['interval'])} "
                       f"(better in {fx(d['rpss']['share_better'], 2)} of the draws), balanced accuracy "
                       f"{fx(d['balanced_accuracy']['value'], 2)}{_iv(d['balanced_accuracy']['interval'])}.")
    both = cal.get("records_and_readings_vs_bar")
    if both:
        out.append("- the records and the model's readings together, minus the bar: RPSS "
                   f"{fx(both['rpss']['value'], 2)}{_iv(both['rpss']['interval'])} (better in "
                   f"{fx(both['rpss']['share_better'], 2)} of the draws), "
                   f"balanced accuracy {fx(both['balanced_accuracy']['value'], 2)}"
                   f"{_iv(both['balanced_accuracy']['interval'])}: what the model's readings add to the records'.")
    c, bar, weac = sc["calibrated"], sc["information_bar"], sc.get("weac_static", {}).get("rpss")
    out += ["", check_line("the model's readings, calibrated, have skill",
                           "RPSS above the climatology's (0) and above weac's rule's",
                           c["rpss"] > 0.0 and (weac is None or c["rpss"] > weac),
                           f"{fx(c['rpss'], 2)} against weac's {fx(weac, 2)}"),
            check_line("the model's readings, calibrated, carry what the records carry",
                       "balanced accuracy of the most probable class at least the information bar's",
                       c["balanced_accuracy"] >= bar["balanced_accuracy"],
                       f"{fx(c['balanced_accuracy'], 3)} against {fx(bar['balanced_accuracy'], 3)}")]
    return out


#: what the model's probability read, by the key each case names (``slab_reading``; none in an older file)
READINGS = {"slab_peak_body_stress_ratio": "the slab body's peak stress over the run",
            "slab_body_stress_ratio_at_call": "the slab body's stress at the call, from the run's final checkpoint",
            "slab_peak_stress_ratio": "the whole slab's peak stress over the run"}


def _reading(data: dict) -> str:
    """What the model's probabilities read, with how many cases read each where they differ."""
    keys = [c.get("slab_reading", "slab_peak_stress_ratio") for c in data.get("cases", [])]
    counts = {k: keys.count(k) for k in READINGS if k in keys}
    if len(counts) <= 1:
        return READINGS[next(iter(counts), "slab_peak_stress_ratio")]
    return "; ".join(f"{READINGS[k]} ({n} case{'s' if n != 1 else ''})" for k, n in counts.items())


def _run_line(c: dict) -> list[str]:
    """The run's own readings (``run_*``) against weac's static stress at the recorded cut."""
    runs = {k: v["sf_vs_end"]["auc"] for k, v in c.items()
            if k.startswith("run_") and v["sf_vs_end"]["auc"] is not None}
    if not runs:
        return []
    best = max(runs, key=runs.get)
    listed = ", ".join(f"`{k}` {fx(a, 3)}" for k, a in runs.items())
    td = c["touchdown_distance"]["sf_vs_end"]["auc"]
    verdict = ("above" if runs[best] > td else "below")
    return [f"- **The run's own readings** (SF against END): {listed}; weac's static stress at the recorded cut "
            f"{fx(c['static_peak_ratio']['sf_vs_end']['auc'], 3)}. The best of the run's, `{best}`, lies {verdict} "
            f"Heierli's touchdown distance ({fx(td, 3)}), the closed form of where the slab lands beyond the cut."]


def _bar_line(bar: dict | None) -> list[str]:
    """The information bar's line on the mechanisms' columns (none in an older file)."""
    if not bar:
        return []
    return [f"- **The information bar** (slab depth, density, slope and cut share in a logistic regression, "
            f"cross-validated by pit) on the same columns: SF-against-END AUC {fx(bar['auc_sf_vs_end'], 3)}, "
            f"balanced accuracy {fx(bar['balanced_accuracy'], 2)} (recall END {fx(bar['recall']['END'], 2)}, SF "
            f"{fx(bar['recall']['SF'], 2)}, ARR {fx(bar['recall']['ARR'], 2)}), ranked probability skill "
            f"{fx(bar['rpss'], 2)} against the set's climatology."]


@section("field", "The outcome as a probability: forecast scores", "field/results/field_forecast.json",
         lambda d: (f"python benchmarks/field/forecast.py DIR --runs RUNDIR --per-class "
                    f"{d['selection'].get('per_class')} --seed {d['selection'].get('seed')}"
                    + (" --no-measured" if not d["selection"].get("measured") else "")),
         figure="field/results/field_forecast.png",
         question="Scored as forecasters score, does the model's probability of END, SF and ARR beat the set's "
                  "climatology, weac's static rule and what the records alone carry?",
         follows="Why thin, light slabs break: each candidate mechanism against the records")
def render_forecast(data: dict, ctx) -> list[str]:
    sc = data["scores"]
    f, iv = sc["forecast"], (sc.get("forecast_uncertainty") or {}).get("intervals", {})
    sel = data["selection"]
    rows = []
    for name in NAMES:
        if name not in f:
            continue
        s, i = f[name], iv.get(name, {})
        rows.append([name, fx(s["rps"], 3), fx(s["rpss"], 2) + _iv(i.get("rpss")),
                     " / ".join(fx(s["brier"][k], 3) for k in FIELD_CLASSES),
                     fx(s["auc"]["SF"], 2) + _iv(i.get("auc_SF")), fx(s["auc"]["ARR"], 2) + _iv(i.get("auc_ARR")),
                     fx(s["balanced_accuracy"], 2) + _iv(i.get("balanced_accuracy"))])
    drawn = sum(sel.get(k, 0) for k in FIELD_CLASSES) + sel.get("measured", 0)
    what = (f"the {sel['measured']} columns with measured slab densities and the draw by class, "
            if sel.get("measured") else "the stratified draw, ")
    at_build = sel.get("refused_at_build")
    built = "" if at_build is None else f"{at_build} refused when built, "
    out = [f"The {sc['cases']} finished cases of {what}{drawn} drawn ({built}{sel.get('per_class')} a class, seed "
           f"{sel.get('seed')}), interleaved by class. The model: one run a case, read at first order "
           f"({_reading(data)} under snow's Weibull strength scatter, docs/field.md). Intervals: 95 %, "
           "paired bootstrap within each class.", ""]
    out += table(["forecast", "RPS", "RPSS (vs climatology)", "Brier END / SF / ARR", "AUC SF", "AUC ARR",
                  "balanced accuracy (most probable)"], rows)
    for name, why in sc.get("forecast_missing", {}).items():
        out += ["", f"- `{name}`: no forecast: {why}."]
    complete = sc["cases"] + (at_build or 0) >= drawn
    for name, who in (("model", "the model's"), ("calibrated", "the calibrated readings'")):
        if name in f:
            out += ["", *_aim_checks(who, f[name], f, complete, sc["cases"], drawn)]
    out += ["", env_note(data)]
    return out


def _aim_checks(who: str, m: dict, f: dict, complete: bool, cases: int, drawn: int) -> list[str]:
    """The issue's aim for one forecast ``m``: skill above the climatology's and weac's, balanced accuracy at least
    the information bar's (open while the draw is not complete)."""
    weac = f.get("weac_static", {}).get("rpss")
    bar = f.get("information_bar", {}).get("balanced_accuracy")
    return [check_line(f"{who} skill", "RPSS above the climatology's (0) and above weac's rule's",
                       (m["rpss"] > 0.0 and (weac is None or m["rpss"] > weac)) if complete else None,
                       f"{fx(m['rpss'], 2)} against weac's {fx(weac, 2)}"
                       + ("" if complete else f"; {cases} of {drawn} drawn cases finished")),
            check_line(f"{who} classes against the information bar",
                       "balanced accuracy of its most probable class at least the bar's",
                       (bar is None or m["balanced_accuracy"] >= bar) if complete else None,
                       f"{fx(m['balanced_accuracy'], 3)} against {fx(bar, 3)}"
                       + ("" if complete else "; the draw is not complete"))]


@section("field", "The landing: the columns called END, run on as the slab lands", "field/results/field_landing.json",
         lambda d: f"python benchmarks/field/landing.py --runs RUNDIR --work DIR --after {d['after_s']:g}"
                   + (" --cases field_disagreements.json" if d.get("cases_from") else "")
                   + (f" --observed {','.join(d['observed'])}" if d.get("observed") else ""),
         question="The batch stops a case once it calls END; the cut slab then falls onto its collapsed weak layer "
                  "in front of the observer. Does the model's slab break as it lands, and more often where the "
                  "observer wrote SF?",
         follows="Why thin, light slabs break: each candidate mechanism against the records", page="field_slab")
def render_landing(data: dict, ctx) -> list[str]:
    s = data["summary"]
    by = s["by_observed"]
    body = "auc_body_peak_after" in s
    rows = [[c, str(v["cases"]), str(v["through_crack"]), str(v["touchdown_inside"]),
             str(v["through_crack_touchdown_inside"]), fx(v["median_peak_after"], 1 if not body else 2)]
            + ([fx(v["median_body_peak_after"], 2) + f" ({v['body_read']})",
                fx(v.get("median_body_at_end"), 2) + f" ({v.get('body_at_end_read', 0)})",
                str(v.get("body_cracked_at_end", "-"))] if body else []) for c, v in by.items() if v["cases"]]
    ok = [c for c in data["cases"] if c["status"] == "ok"]
    stopped = data.get("planned", len(data["cases"])) > len(data["cases"])
    out = [(f"{len(data['cases'])} of the {data['planned']} scored cases" if stopped else
            f"The {len(data['cases'])} cases") + f" of the batch `{data['runs']}` called END whose runs had "
           "finished" + (f" (the {' and '.join(data['observed'])} records of `{data['cases_from']}`)"
                         if data.get("cases_from") else "") + ", each "
           f"resumed on a copy for {fx(data['after_s'], 2)} s past its call, stopping at a crack through the slab "
           "(the batch's own detector). Touchdown inside: Heierli's touchdown distance shorter than the column."
           + (" The study was stopped there: the others were not run on (the cases are taken in the order of "
              "their ids, interleaved between two processes)." if stopped else ""), ""]
    out += table(["observed", "cases", "slab cracked through", "touchdown inside the column",
                  "of those, cracked through", "median peak stress over strength after the call, whole slab"]
                 + (["the slab body's peak after the call (runs read)", "the body's at the end (runs read)",
                     "bodies cracked at the end"] if body else []), rows)
    through = sum(v["through_crack"] for v in by.values())
    above = sum(c["peak_stress_ratio_after"] is not None and c["peak_stress_ratio_after"] >= 1.0 for c in ok)
    out += ["", f"- {through} of {len(ok)} slabs cracked through within {fx(data['after_s'], 2)} s of the call; "
            f"{above} of {len(ok)} reached their strength somewhere after it (the whole slab, its rows tied to the "
            "weak layer included). The peak stress over strength after the "
            f"call tells SF from END with an AUC of {fx(s['auc_peak_after'], 2)} ({s['sf_end_cases']} SF and END "
            "records)."
            + (" In the model, the landing damages the slab without breaking it through, in every class." if
               through == 0 and above else "")]
    if body:
        out += [f"- **The slab's body** (its rows beyond the grid's tie to the weak layer, the reading of the model's "
                f"P(SF)): its peak over the frames after the call tells SF from END with an AUC of "
                f"{fx(s['auc_body_peak_after'], 2)} ({s['sf_end_body_cases']} SF and END records whose run file has "
                f"the body's series); its carried stress at the end of the run-on, from the final checkpoint, with "
                f"{fx(s.get('auc_body_at_end'), 2)} ({s.get('sf_end_body_at_end_cases', 0)} records). The stress is "
                "what a particle carries over its strength: 1 once it has cracked, never more.", "", env_note(data)]
    else:
        out += ["- The peak stress column was read by the monitor of that commit, which took a cracked particle's "
                "unsoftened stress: past a particle's strength it measures how far its crack opened, not what it "
                "carries (never more than its strength). docs/field.md, \"Why the slab's stress read 20-124 times "
                "its strength\", has the slab's carried stress: at most 0.38-0.45 of its strength up to the call on "
                "two of these columns.", "", env_note(data)]
    return out
