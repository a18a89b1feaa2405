"""The field slab's stress against its strength and weac's static beam (benchmarks/field/slab_stress.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .fmt import check_line, count, env_note, fx, secs, spct, table

#: the run's slab stress up to the crack's onset agrees with weac's beam at that cut within this share (-)
AGREE = 0.2


def _layers(c: dict) -> str:
    return ", ".join(f"{fx(ly['thickness_m'], 1, 100)} cm of {fx(ly['density'], 0)} ({fx(ly['cells'], 1)} cells)"
                     for ly in c["layers"])


def _r(v) -> str:
    return "-" if v is None else fx(v, 2)


def _off(c: dict) -> float | None:
    """The run's slab stress up to the onset against weac's over the cut at the onset; None without an onset, or
    with an onset shorter than the slab is deep (a beam's bending stress does not hold there)."""
    w = c.get("weac_at_onset") or {}
    if c.get("mpm_ratio_to_onset") is None or not w.get("over_cut") or c["onset_cut"] < c["slab_depth_m"]:
        return None
    return c["mpm_ratio_to_onset"] / w["over_cut"] - 1.0


#: the tensile law caps a particle's stress at its strength and the frames sample it: a peak within this share of
#: the strength has reached it
REACHED = 0.99

#: a layer resolved by fewer grid cells than this is named beside a failing comparison
THIN_CELLS = 2.0


def _thin(cases: list) -> str:
    """The failing comparisons' slab layers resolved by fewer than :data:`THIN_CELLS` grid cells."""
    notes = []
    for c in cases:
        off = _off(c)
        if off is None or abs(off) <= AGREE:
            continue
        thin = [ly for ly in c["layers"] if ly["cells"] < THIN_CELLS]
        notes.append(f"`{c['test']}`: " + ("; ".join(
            f"its {fx(ly['thickness_m'], 1, 100)} cm layer of {fx(ly['density'], 0)} kg/m^3 has "
            f"{fx(ly['cells'], 1)} cells" for ly in thin) if thin else "no slab layer under "
            f"{fx(THIN_CELLS, 0)} cells"))
    return "; where the run and weac part: " + "; ".join(notes) if notes else ""


def _where(at) -> str:
    """``[x0, depth, sigma_xx, sigma_yy, sigma_xy]`` of the run's peak as words: where, and the stress it is."""
    if not at:
        return "-"
    x, depth, sxx, syy, sxy = at
    which = "along the bed" if abs(sxx) >= max(abs(syy), abs(sxy)) else (
        "normal to the bed" if abs(syy) >= abs(sxy) else "shear")
    return f"{fx(x, 2)} m, {fx(depth * 100, 1)} cm deep; {which} ({fx(max(sxx, syy, sxy) / 1e3, 1)} kPa)"


def _selected(data: dict) -> str:
    sel = data.get("selection") or {"observed": "SF", "predicted": "END"}
    if sel.get("cases"):
        return "The given cases"
    what = f"The {sel['observed']} records the model called {sel['predicted']}"
    return what + (f", a sample of {sel['sample']} drawn with seed {sel['seed']}" if sel.get("sample") else "")


def _command(d: dict, out: str = "") -> str:
    sel = d.get("selection") or {}
    opts = "" if not sel or sel.get("cases") else (
        f" --observed {sel['observed']} --predicted {sel['predicted']}"
        + (f" --sample {sel['sample']} --seed {sel['seed']}" if sel.get("sample") else ""))
    dirs = " ".join("RUNDIR" + str(k + 1) for k in range(len(d["runs"])))
    tail = ("" if d.get("control") else " --no-control") + (f" --out {out}" if out else "")
    return (f"python benchmarks/field/slab_stress.py {dirs}{opts}{tail}  # "
            + ", ".join(f"RUNDIR{k + 1}: {r}" for k, r in enumerate(d["runs"])))


@section("field", "Why the slab did not break", "field/results/field_slab_stress.json",
         _command,
         question="Where the observer saw the slab break (SF) and the model did not, how close did the run's slab "
                  "come to its tensile strength, and what does weac's static beam say at the same cut?",
         page="field_slab")
def render_slab_stress(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    where = any(c.get("peak_at") for c in cases)
    heads = ["record", "predicted", "slab, top to bottom", "onset / recorded cut (m)", "run: peak",
             *(["run's peak: where, which stress"] if where else []), "run: to onset",
             "weac at onset: over the cut, tip", "weac at the recorded cut: over the cut, tip", "run against weac",
             "wall time"]
    rows = []
    for c in cases:
        wo, wr = c.get("weac_at_onset") or {}, c["weac_at_recorded_cut"]
        off = _off(c)
        rows.append([f"`{c['test']}`", c["predicted"], _layers(c),
                     f"{_r(c['onset_cut'])} / {fx(c['recorded_cut'], 2)}", _r(c["mpm_peak_ratio"]),
                     *([_where(c.get("peak_at"))] if where else []), _r(c["mpm_ratio_to_onset"]),
                     f"{_r(wo.get('over_cut'))}, {_r(wo.get('tip'))}",
                     f"{_r(wr.get('over_cut'))}, {_r(wr.get('tip'))}", "-" if off is None else spct(off),
                     secs(c["wall_s"])])
    offs = [o for o in map(_off, cases) if o is not None]
    within = sum(abs(o) <= AGREE for o in offs)
    out = [f"{_selected(data)} ({count(len(cases))} of the {count(data.get('selected', len(cases)))} selected), each "
           "run again from its own scenario with the particles' stress stored at every frame. "
           "Every stress is a ratio to the layer's tensile strength (Sigrist 2006 from density, the run's). Run: "
           "the largest over the slab's particles, over the whole run (peak) and while the blade had cut no more "
           f"than the onset, where the damage front first led the blade by {fx(data['onset_cells'], 0)} cells. "
           "weac: its static beam at the same cut, largest over the cut (the cantilever's bending) and at the "
           "crack tip (where the beam takes the weak layer's reaction); its tip value at the recorded cut is what "
           "the batch's static rule reads. A layer's cells: its thickness over the grid spacing. The run's values "
           "are the largest over every slab particle, wherever it sits (the top surface in bending, the row next "
           "to the weak layer, a thin layer): where they stand far above weac's beam at the same cut, they are "
           "not the cantilever's bending.", ""]
    out += table(heads, rows)
    ctl = data.get("control")
    if ctl:
        beam = [r for r in ctl["rows"] if r["cut"] >= ctl["slab_depth_m"] - 1e-9]
        devs = [r["run"] / r["weac"] - 1.0 for r in beam]
        ok = all(abs(d) <= AGREE for d in devs)
        out = [f"**The control** ({ctl['what']}, dx {fx(ctl['dx'] * 1e3, 1)} mm; {secs(ctl['wall_s'])}): the run's "
               "slab stress over strength while the blade had cut at most each length, against weac's beam over "
               "the cut there: " + ", ".join(f"{r['cut']:g} m: {fx(r['run'], 3)} / {fx(r['weac'], 3)}"
                                            for r in ctl["rows"])
               + ". A cut shorter than the slab is deep leaves a deep cantilever, whose stress is not a beam's "
               "(and the largest stress in the slab is then not the bending's).", "",
               check_line("the control against weac's beam", f"within {fx(100 * AGREE, 0)} % at every cut at least "
                          f"as long as the slab is deep ({fx(ctl['slab_depth_m'], 2)} m)", ok and bool(devs),
                          ", ".join(spct(d) for d in devs)), "", *out]
    if offs:
        out += ["", check_line("the field columns against weac's beam",
                               "where the crack started at a cut at least as long as the slab is deep, the run's "
                               f"slab stress up to the onset within {fx(100 * AGREE, 0)} % of weac's over the cut "
                               "at the onset, as on the control", within == len(offs),
                               f"{within} of {len(offs)}: " + ", ".join(spct(o) for o in offs) + _thin(cases))]
    return out + ["", env_note(data)]


SF_SOURCE = "field/results/field_slab_stress.json"


def ranked_above(high: list, low: list) -> float:
    """The share of pairs in which a value of ``high`` exceeds one of ``low`` (ties half): the area under the ROC
    curve of telling the two apart by the value."""
    return sum(1.0 if a > b else 0.5 if a == b else 0.0 for a in high for b in low) / (len(high) * len(low))


@section("field", "The slab's stress where the observer saw END", "field/results/end/field_slab_stress.json",
         lambda d: _command(d, "benchmarks/field/results/end"),
         question="Beside the SF records: how close does the run's slab come to its strength in END records the "
                  "model also called END? (A slab stress that tells SF from END would come closer in SF records.)",
         page="field_slab")
def render_end(data: dict, ctx) -> list[str]:
    """:func:`render_slab_stress`, and how well the run's peak slab stress ranks the SF records above these."""
    out = render_slab_stress(data, ctx)
    sf = [c["mpm_peak_ratio"] for c in (ctx.load(SF_SOURCE) or {}).get("cases", [])]
    end = [c["mpm_peak_ratio"] for c in data["cases"]]
    if sf and end:
        reached = sum(v >= REACHED for v in sf)
        reached_end = sum(v >= REACHED for v in end)
        out[-1:-1] = [f"- **SF against END:** the run's peak slab stress over strength, median {fx(median(sf), 2)} "
                      f"in the {len(sf)} SF records (the section above) and {fx(median(end), 2)} in these "
                      f"{len(end)} END records. It ranks an SF record above an END record in "
                      f"{fx(100 * ranked_above(sf, end), 0)} % of the {len(sf) * len(end)} pairs (the area "
                      f"under the ROC curve; 50 % is chance). The slab reached its strength (within "
                      f"{fx(100 * (1 - REACHED), 0)} %: the tensile law caps the stress there) in {reached} of the "
                      f"{len(sf)} SF records and in {reached_end} of these {len(end)} END records.", ""]
    return out
