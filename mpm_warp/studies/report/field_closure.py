"""Field cases without and with the laminate closure at their layer interfaces (benchmarks/field/closure.py, a what-if
of :mod:`.field_what_if`), and the slab's stress at the weak layer against the FE (benchmarks/field/closure_stress.py).
"""

from __future__ import annotations

from statistics import median

from .core import section
from .field_what_if import balanced_line, command, failed_lines, ran, render_what_if
from .fmt import check_line, env_note, fx, table


def _cost(data: dict) -> list[str]:
    """Steps with over without the closure, and the wall time where both ran on the same threads and workers."""
    cases = ran(data["cases"])
    a, b = [c["before"]["cost"] for c in cases], [c["after"]["cost"] for c in cases]
    same_threads = [y["wall_s"] / x["wall_s"] for x, y in zip(a, b, strict=True)
                    if x.get("wall_s") and (x.get("threads"), x.get("workers")) == (y.get("threads"), y.get("workers"))]
    steps = [y["steps"] / x["steps"] for x, y in zip(a, b, strict=True) if x.get("steps") and y.get("steps")]
    if not steps:
        return []
    return [f"- Cost: steps with over without the closure {fx(min(steps), 2)} to {fx(max(steps), 2)} (median "
            f"{fx(median(steps), 2)}; a run stops at the first frame its outcome is decided)"
            + (f"; wall time, where both ran on the same threads and workers ({len(same_threads)} cases), "
               f"{fx(min(same_threads), 2)} to {fx(max(same_threads), 2)} times (median "
               f"{fx(median(same_threads), 2)})" if same_threads else
               "; no case ran on the same threads and workers both times, so their wall times are not compared")
            + ".", ""]


def _intro(data: dict) -> str:
    return (f"Cases: {data['chosen']}, each set up again from its pit as the batch set it up (the same key: the same "
            "parameters, the same protocol) and run with the closure on, nothing else changed. Each pair of values is "
            "without / with the closure; the run without it is the batch's own.")


@section("field", "The laminate closure: the same columns without and with it", "field/results/field_closure.json",
         command("closure"),
         question="Does a field case keep its class, and its runaway cut, when its column runs with the laminate "
                  "closure at its layer interfaces (docs/model.md §5b), which removes the grid's bimaterial artefact "
                  "at the weak layer?",
         follows="A resolved slab: the run and weac against a static FE", page="field_slab")
def render_closure(data: dict, ctx) -> list[str]:
    return render_what_if(data, ctx, intro=_intro, notes=(failed_lines, balanced_line, _cost),
                          columns=("predicted", "runaway", "change", "broke", "steps", "wall_threads"))


STRESS_ON = "field/results/closure/field_closure_stress_on.json"
STRESS_OFF = "field/results/closure/field_closure_stress_off.json"


def _base_summary(fe_rows: list, basal: bool) -> tuple[int, int, float | None]:
    """Of the slab layers at (``basal``) or clear of the weak layer's stencil: how many agree with the FE within
    :data:`~.field_slab_fe.AGREE` at the onset, of how many, and the median run over FE."""
    from .field_slab_fe import AGREE, _pairs  # not at the top: this module's sections follow that one's

    pairs = _pairs(fe_rows, basal=basal)
    ratios = [r / f for *_, r, f in pairs]
    return sum(abs(x - 1.0) <= AGREE for x in ratios), len(ratios), (median(ratios) if ratios else None)


def _layers(v: list | None) -> str:
    return ", ".join(fx(x, 2) for x in v) if v else "-"


@section("field", "The laminate closure: the slab's stress at the weak layer against the FE", STRESS_ON,
         lambda d: "python benchmarks/field/closure_stress.py RUNDIR --closure on  # and --closure off; RUNDIR: "
                   "closure.py's runs",
         question="Is the slab's stress next to the weak layer, far above a static FE's in the field runs, the "
                  "grid's bimaterial artefact that the closure removes?",
         follows="The laminate closure: the same columns without and with it", page="field_slab")
def render_closure_stress(data: dict, ctx) -> list[str]:
    from .field_slab_fe import AGREE, SMALL, _at_base, _auc

    off = ctx.load(STRESS_OFF) if ctx is not None else None
    on_rows = [c for c in data["cases"] if c["fe"].get("at_onset")]
    off_by = {c["id"]: c for c in (off or {}).get("cases", []) if c["fe"].get("at_onset")}
    rows = []
    for c in on_rows:
        o, f = off_by.get(c["id"]), c["fe"]
        base = sorted(_at_base(f))
        fe_layers = f["at_onset"]["fe"][-1]["layers"]
        onset = f"{fx(o['onset_cut'], 3) if o else '-'} / {fx(c['onset_cut'], 3)}"
        rows.append([f"`{c['test']}`", c["observed"], onset,
                     ", ".join(str(k + 1) for k in base),
                     _layers([o["fe"]["run_layers_at_onset"][k] for k in base]) if o else "-",
                     _layers([f["run_layers_at_onset"][k] for k in base]), _layers([fe_layers[k] for k in base]),
                     f"{o['predicted'] if o else '-'} / {c['predicted']}"])
    out = [f"The SF and END columns of the section above, each run from its scenario without and with the closure "
           "(nothing else changed), the particles' stress stored at every frame, and solved statically at the run's "
           "onset by the FE of \"A resolved slab\" (the same elements, the same zones left out at the singular "
           f"corners). Values are the largest principal stress over the layer's tensile strength in the onset frame; "
           f"the layers at the base are those within {fx(2, 0)} grid cells of the weak layer, numbered from the top. "
           "Each pair is without / with the closure; the runs without it: "
           + (ctx.link(STRESS_OFF) if ctx is not None else STRESS_OFF) + ".", ""]
    out += table(["record", "observed", "onset (m)", "layers at the base", "run without", "run with", "FE",
                  "predicted"], rows)
    out += [""]
    on_fe, off_fe = [c["fe"] for c in on_rows], [c["fe"] for c in off_by.values()]
    summary = {basal: (_base_summary(on_fe, basal), _base_summary(off_fe, basal) if off_fe else (0, 0, None))
               for basal in (True, False)}
    for basal, what in ((True, "at the base"), (False, "clear of the base")):
        (a_on, k_on, m_on), (a_off, k_off, m_off) = summary[basal]
        out.append(check_line(f"the run's slab layers {what} against the FE, with the closure",
                              f"within {fx(100 * AGREE, 0)} % at the onset, where either reaches {fx(SMALL, 1)} of "
                              "its strength", k_on > 0 and a_on == k_on,
                              f"{a_on} of {k_on}, the run over the FE median {fx(m_on, 2)}; without the closure "
                              f"{a_off} of {k_off}, median {fx(m_off, 2)}"))
    med_on, med_off = summary[True][0][2], summary[True][1][2]
    if med_on is not None and med_off is not None and med_on > 1.0 + AGREE:
        out += ["", f"- The closure takes the base layers' stress from {fx(med_off, 2)} to {fx(med_on, 2)} times "
                "the FE's (medians): most of the excess stays, so it is not the settled column's bimaterial artefact, "
                "which the closure removes (\"Stress at the weak layer's interfaces\"). What is left lies among what "
                "the static FE leaves out at the onset: the saw's and the settling's dynamics, and a weak layer that "
                "softens ahead of the blade where the FE's stays elastic up to the cut."]
    fe_auc = _auc(on_fe, lambda c: c["at_onset"]["fe"][-1]["peak"])
    aucs = [(name, _auc(fe_rows, lambda c: c["run_to_onset"]))
            for name, fe_rows in (("without", off_fe), ("with", on_fe))]
    if fe_auc and all(a for _, a in aucs):
        out += ["", f"- **SF against END at the onset:** the FE's slab peak ranks an SF record above an END record in "
                f"{fx(100 * fe_auc[0], 0)} % of the {fe_auc[1]} pairs; the run's largest slab stress to the onset "
                + " and ".join(f"{fx(100 * a[0], 0)} % {name} the closure" for name, a in aucs)
                + " (50 % is chance)."]
    return out + ["", env_note(data)]
