"""Field cases set up again on a softer weak layer, a what-if on its stiffness (benchmarks/field/weak_modulus.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_strength import sf_check, sf_counts
from .field_what_if import CLASSES, COLUMNS, balanced_line, command, failed_lines, labels, ran, render_what_if
from .fmt import fx


def _static(data: dict) -> list[str]:
    """weac's static rule and the fracture energy on the softer layer, and the arrests it predicts."""
    cases = ran(data["cases"])
    _, a = labels(data)
    static = ", ".join(f"{cls} {sf_counts(cases, cls, 'after', 'static_class')[0]} of "
                       f"{sf_counts(cases, cls, 'after')[1]} ({sf_counts(cases, cls, 'before', 'static_class')[0]})"
                       for cls in CLASSES)
    wf = [c["after"]["w_f"] / c["before"]["w_f"] for c in cases
          if c["before"].get("w_f_source") == "read back" and c["after"].get("w_f_source") == "read back"]
    arr = sum(c["after"]["predicted"] == "ARR" for c in cases)
    return [f"- {arr} of the {len(cases)} predicted ARR {a}. weac's static rule on the softer layer predicts SF in "
            f"{static} records (at the scene's modulus in brackets)."
            + (f" The fracture energy read back from the recorded cut, where it was read both ways ({len(wf)} cases): "
               f"{fx(median(wf), 2)} times the scene's (median; {fx(min(wf), 2)} to {fx(max(wf), 2)})." if wf else ""),
            ""]


def _intro(data: dict) -> str:
    e0, e1 = data["switch"]["before"], data["switch"]["value"]
    return (f"Cases: {data['chosen']}, each set up again from its pit as the batch set it up (the same key), then "
            f"again with the weak layer's Young's modulus at {fx(e1, 2)} MPa instead of the scene's {fx(e0, 2)} MPa, "
            "as the batch would set it up on that layer: the fracture energy read back again from the recorded cut "
            "(weac's G there, on the softer layer) and the layer calibrated again; nothing else changed. "
            f"{fx(e1, 2)} MPa is weac's default; field weak layers span 0.05-1 MPa (docs/model.md §6). Each pair of "
            f"values is at {fx(e0, 2)} MPa (the batch's run) / at {fx(e1, 2)} MPa; the steps, not the wall times, "
            "compare the cost: the two sides ran at different times on a shared machine.")


@section("field", "The weak layer's stiffness: the same columns on a softer weak layer",
         "field/results/field_weak_modulus.json",
         command("weak_modulus", lambda d: f" --modulus {d['switch']['value']:g}"),
         question="A pit records no stiffness, and every field column's weak layer has the scene's modulus, the top of "
                  "the field's range. Would a softer weak layer tell the outcomes apart? The same columns set up "
                  "again on a softer layer (a what-if, not a calibration: no default changes).",
         follows="Plane strain against a 30 cm wide column: the slab's stress at the recorded cut", page="field_slab")
def render_weak_modulus(data: dict, ctx) -> list[str]:
    e1 = data["switch"]["value"]
    return render_what_if(
        data, ctx, intro=_intro, notes=(balanced_line, _static, failed_lines),
        columns=("predicted", "static", "w_f", "runaway", ("slab broke at (m), softer", COLUMNS["broke_after"][1]),
                 "steps"),
        checks=(lambda d: sf_check(d, f"a weak layer of {fx(e1, 2)} MPa breaks the slab where the observer saw SF "
                                      "rather than END", "at the scene's modulus"),))
