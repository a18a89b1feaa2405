"""The field slab's stress against a static FE that resolves every layer (benchmarks/field/slab_fe.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_slab import ranked_above
from .fmt import check_line, env_note, fx, spct, table

#: a run's or weac's slab stress agrees with the resolved FE within this share (-): the line the control holds
#: against weac's beam in the slab-stress study
AGREE = 0.2
#: layer ratios below this (of the strength) are left out of the per-layer comparison: far from a break, and a
#: few hundred Pa, where a share says little
SMALL = 0.1
#: grid cells: a layer whose base lies within this of the weak layer shares the grid's stencil (3 cells wide)
#: with it, where docs/model.md §5b measures the smeared strain of a stiffness jump
STENCIL_CELLS = 2.0


def _at_base(c: dict) -> set[int]:
    """The slab layers (0 = top) whose base lies within :data:`STENCIL_CELLS` of the weak layer."""
    cells, out, below = c["layer_cells"], set(), 0.0
    for k in range(len(cells) - 1, -1, -1):
        if below <= STENCIL_CELLS:
            out.add(k)
        below += cells[k]
    return out


def _v(x) -> str:
    return "-" if x is None else fx(x, 2)


def _pairs(cases: list, basal: bool) -> list[tuple[str, int, float, float, float]]:
    """``(record, layer, cells, run, FE)`` of every slab layer at the onset frame: the layers at the weak layer's
    stencil (``basal``, :func:`_at_base`) or the others; layers where both stay below :data:`SMALL` are left out."""
    out = []
    for c in cases:
        o, run = c.get("at_onset"), c.get("run_layers_at_onset")
        if not o or not run:
            continue
        fe = o["fe"][-1]["layers"]
        base = _at_base(c)
        for k in range(len(fe)):
            if (k in base) == basal and max(run[k], fe[k]) >= SMALL:
                out.append((c["test"], k, c["layer_cells"][k], run[k], fe[k]))
    return out


def _auc(cases: list, value) -> tuple[float, int] | None:
    """How often ``value(case)`` ranks an observed SF record above an END one (ties half), and the pairs."""
    sf = [value(c) for c in cases if c["observed"] == "SF"]
    end = [value(c) for c in cases if c["observed"] == "END"]
    if not sf or not end:
        return None
    return ranked_above(sf, end), len(sf) * len(end)


def _peak(c: dict) -> str:
    """The run's slab peak in the onset frame: its zone, depth and which stress it is."""
    at = c.get("run_peak_at_onset")
    if not at:
        return "-"
    sxx, syy, sxy = at["sigma"]
    which = "along the bed" if abs(sxx) >= max(abs(syy), abs(sxy)) else (
        "normal to the bed" if abs(syy) >= abs(sxy) else "shear")
    return f"{at['zone']}, {fx(at['from_end_face'], 2)} m, {fx(at['depth'] * 100, 1)} cm deep, {which}"


def _zones(cases: list, basal: list) -> str:
    """Where the run's peak sat in the onset frame, over the records of ``basal``'s pairs that part from the FE."""
    tests = {t for (t, _, _, r, f) in basal if abs(r / f - 1.0) > AGREE}
    zones = [c["run_peak_at_onset"]["zone"] for c in cases if c["test"] in tests and c.get("run_peak_at_onset")]
    if not zones:
        return ""
    words = {"blade": "at the blade", "end face": "at an end face", "inside": "inside the column"}
    return "; in those records the run's slab peak of the onset frame sat " + ", ".join(
        f"{zones.count(z)} {w}" for z, w in words.items() if zones.count(z))


def _off(pairs) -> list[float]:
    return [run / fe - 1.0 for _, _, _, run, fe in pairs]


@section("field", "A resolved slab: the run and weac against a static FE", "field/results/field_slab_fe.json",
         lambda d: "python benchmarks/field/slab_fe.py RUNDIR1 RUNDIR2  # the runs of the slab-stress studies",
         question="Is a field run's slab stress, or weac's, nearer a continuum that resolves every layer? The "
                  "columns of the two slab-stress studies, solved statically at the crack's onset.", page="field_slab")
def render_slab_fe(data: dict, ctx) -> list[str]:
    cases = [c for c in data["cases"] if c.get("at_onset")]
    mm = " and ".join(f"{fx(m * 1e3, 0)} mm" for m in data["meshes_m"])
    out = ["Each column of the two slab-stress sections above (its layers' E and strength, its weak layer, slope "
           "and ends, as the run had them) is solved statically at the cut where the run's crack started, by a "
           f"plane-strain FE of 9-node elements ({mm} wide, two at least through every layer: "
           "`mpm_warp.validation.column_fe`, checked against statics and composite-beam theory in "
           "`tests/test_column_fe.py`). Every value is the largest principal stress over the layer's tensile "
           f"strength. The FE's leaves out the zones within {fx(data['corner_m'] * 100, 0)} cm of the corner where "
           "the sawn weak layer ends and of the column's end faces, where linear elasticity is singular (the "
           "edges column: their largest value on the finer mesh). The run's is its own, over the whole slab, while "
           "the blade had cut no more than the onset (the dynamics of the saw and the settling included), and in the "
           "frame of the onset itself, which the checks compare, with where its slab peak sat then: at the blade or "
           f"an end face (within {fx(data['corner_m'] * 100, 0)} cm along the column), or inside. The layers at the "
           "base are those whose base lies "
           f"within {fx(STENCIL_CELLS, 0)} grid cells of the weak layer: the grid's stencil spans both.", ""]
    ctl = data.get("control")
    if ctl:
        rows = [[f"{r['cut']:g}", *[fx(f["peak"], 3) for f in r["fe"]], fx(r["weac"]["peak"], 3), fx(r["run"], 3),
                 spct(r["run"] / r["fe"][-1]["peak"] - 1.0), spct(r["weac"]["peak"] / r["fe"][-1]["peak"] - 1.0)]
                for r in ctl["rows"]]
        out += [f"**The control** ({ctl['what']}):", ""]
        out += table(["cut (m)", *[f"FE, {fx(m * 1e3, 0)} mm" for m in data["meshes_m"]], "weac", "run",
                      "run against FE", "weac against FE"], rows)
        beam = [r for r in ctl["rows"] if r["cut"] >= ctl["slab_depth_m"] - 1e-9]
        devs = [r["run"] / r["fe"][-1]["peak"] - 1.0 for r in beam]
        out += ["", check_line("the control's run against the FE", f"within {fx(100 * AGREE, 0)} % at every cut at "
                               f"least as long as the slab is deep ({fx(ctl['slab_depth_m'], 2)} m)",
                               bool(devs) and all(abs(d) <= AGREE for d in devs), ", ".join(map(spct, devs))), ""]
    rows = []
    for c in cases:
        o = c["at_onset"]
        fe = o["fe"][-1]
        rows.append([f"`{c['test']}`", c["observed"], fx(c["onset_cut"], 3),
                     ", ".join(fx(v, 1) for v in c["layer_cells"]), ", ".join(fx(v, 2) for v in fe["layers"]),
                     ", ".join(fx(v, 2) for v in c.get("run_layers_at_onset") or []),
                     ", ".join(fx(v, 2) for v in c.get("run_layers_to_onset") or []), fx(fe["edges"], 2),
                     _peak(c), _v(o["weac"]["peak"]), spct(o["fe_refinement_change"])])
    out += table(["record", "observed", "onset (m)", "layers' cells, top to bottom", "FE per layer",
                  "run per layer, at the onset", "run per layer, largest to the onset", "FE edges",
                  "run's peak at the onset: zone, from the cut end, depth, stress", "weac", "FE under refinement"],
                 rows)
    above, basal = _pairs(cases, basal=False), _pairs(cases, basal=True)
    off_a, off_b = _off(above), _off(basal)
    bad = [f"`{t}` layer {k + 1} ({fx(cells, 1)} cells): {fx(r, 2)} against {fx(f, 2)}"
           for (t, k, cells, r, f), d in zip(above, off_a, strict=True) if abs(d) > AGREE]
    wf = [(o["weac"]["peak"] / o["fe"][-1]["peak"] - 1.0) for o in (c["at_onset"] for c in cases)]
    out += ["", check_line("the run's slab layers clear of the base against the FE",
                           f"within {fx(100 * AGREE, 0)} % at the onset, in every layer where either reaches "
                           f"{fx(SMALL, 1)} of its strength", bool(off_a) and not bad,
                           f"{len(off_a) - len(bad)} of {len(off_a)}, median {spct(median(off_a))}"
                           + (f"; apart: {'; '.join(bad)}" if bad else "") if off_a else "none"),
            check_line("the run's slab layers at the base against the FE", f"within {fx(100 * AGREE, 0)} % at the "
                       f"onset, where either reaches {fx(SMALL, 1)} of its strength",
                       bool(off_b) and all(abs(d) <= AGREE for d in off_b),
                       f"{sum(abs(d) <= AGREE for d in off_b)} of {len(off_b)}; the run over the FE "
                       f"{fx(min(r / f for *_, r, f in basal), 1)} to {fx(max(r / f for *_, r, f in basal), 0)} "
                       f"times, median {fx(median(r / f for *_, r, f in basal), 1)}: a stress the static continuum "
                       "does not have away from its singular corners" + _zones(cases, basal) if off_b else "none"),
            check_line("weac's static beam against the FE", f"the slab's peak within {fx(100 * AGREE, 0)} % at "
                       "the onset", bool(wf) and all(abs(d) <= AGREE for d in wf),
                       f"{sum(abs(d) <= AGREE for d in wf)} of {len(wf)}; from {spct(min(wf))} to {spct(max(wf))}, "
                       f"median {spct(median(wf))}" if wf else "none"), ""]
    fe_auc = _auc(cases, lambda c: c["at_onset"]["fe"][-1]["peak"])
    run_auc = _auc(cases, lambda c: c["run_to_onset"])
    if fe_auc and run_auc:
        out += [f"- **SF against END at the onset:** the FE's slab peak ranks an SF record above an END record in "
                f"{fx(100 * fe_auc[0], 0)} % of the {fe_auc[1]} pairs, the run's largest slab stress to the onset "
                f"in {fx(100 * run_auc[0], 0)} % (50 % is chance; the SF records are those the model called END, "
                "the END records a sample of those it called END).", ""]
    return out + [env_note(data)]
