"""Field cases set up again on a softer weak layer, a what-if on its stiffness (benchmarks/field/weak_modulus.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_closure import CLASSES, _balanced
from .field_rigid_base import _cut
from .field_strength import sf_verdict
from .fmt import check_line, count, env_note, fx, table


def _ran(cases: list) -> list:
    """The cases run both ways (the batch's run, and the softer layer's)."""
    return [c for c in cases if c["softer"].get("status") == "ok" and c["scene"].get("status") == "ok"]


def _sf(cases: list, cls: str, side: str, key: str = "predicted") -> tuple[int, int]:
    of = [c for c in cases if c["observed"] == cls]
    return sum(c[side][key] == "SF" for c in of), len(of)


def _why(line: str) -> str:
    """A refusal's reason without its record (``pit: PST ...: reason``)."""
    return (line or "").split(" cm: ", 1)[-1]


@section("field", "The weak layer's stiffness: the same columns on a softer weak layer",
         "field/results/field_weak_modulus.json",
         lambda d: f"python benchmarks/field/weak_modulus.py DIR --runs RUNDIR --modulus {d['modulus_mpa']:g} "
                   f"--per-class {d['per_class']} --seed {d['seed']} --max-wall {d['max_wall_s']:g} "
                   f"--workers {d['workers']} --threads {d['threads']}",
         question="A pit records no stiffness, and every field column's weak layer has the scene's modulus, the top of "
                  "the field's range. Would a softer weak layer tell the outcomes apart? The same columns set up "
                  "again on a softer layer (a what-if, not a calibration: no default changes).",
         follows="Plane strain against a 30 cm wide column: the slab's stress at the recorded cut", page="field_slab")
def render_weak_modulus(data: dict, ctx) -> list[str]:
    e0, e1 = data["scene_modulus_mpa"], data["modulus_mpa"]
    cases = data["cases"]
    rows = []
    for c in cases:
        a, b = c["scene"], c["softer"]
        rows.append([f"`{c['test']}`", c["observed"], f"{a['predicted']} / {b['predicted'] or b.get('status')}",
                     f"{a.get('static_class')} / {b.get('static_class') or '-'}",
                     f"{fx(a.get('w_f'), 3)} / {fx(b.get('w_f'), 3)}",
                     f"{_cut(a['runaway_cut'])} / {_cut(b.get('runaway_cut'))}", _cut(b.get("slab_fracture_at")),
                     f"{count(a['steps'])} / {count(b.get('steps'))}"])
    out = [f"Cases: {data['chosen']}, each set up again from its pit as the batch set it up (the same key), then "
           f"again with the weak layer's Young's modulus at {fx(e1, 2)} MPa instead of the scene's {fx(e0, 2)} MPa, "
           "as the batch would set it up on that layer: the fracture energy read back again from the recorded cut "
           "(weac's G there, on the softer layer) and the layer calibrated again; nothing else changed. "
           f"{fx(e1, 2)} MPa is weac's default; field weak layers span 0.05-1 MPa (docs/model.md §6). Each pair of "
           f"values is at {fx(e0, 2)} MPa (the batch's run) / at {fx(e1, 2)} MPa; the steps, not the wall times, "
           "compare the cost: the two sides ran at different times on a shared machine.", ""]
    out += table(["record", "observed", "predicted", "weac's static rule", "w_f (J/m^2)", "runaway cut (m)",
                  "slab broke at (m), softer", "steps"], rows)
    ran = _ran(cases)
    got = {cls: _sf(ran, cls, "softer") for cls in CLASSES}
    was = {cls: _sf(ran, cls, "scene") for cls in CLASSES}
    (a, n), (b, m) = got["SF"], got["END"]
    p, passed = sf_verdict(a, n, b, m)
    why = (", ".join(f"{cls} records {got[cls][0]} of {got[cls][1]} ({was[cls][0]})" for cls in CLASSES)
           + f", at the scene's modulus in brackets; p = {fx(p, 2)}"
           + {None: "; too few cases to tell", True: "", False: "; no larger share of the SF records"}[passed])
    out += ["", check_line(f"a weak layer of {fx(e1, 2)} MPa breaks the slab where the observer saw SF rather than "
                           "END", "a larger share of the SF records than of the END records predicted SF, beyond "
                           "chance (one-sided Fisher exact test, p <= 0.05)", passed, why), ""]
    parts = []
    for side, name in (("scene", f"at {fx(e0, 2)} MPa"), ("softer", f"at {fx(e1, 2)} MPa")):
        ba, rec = _balanced(ran, side)
        parts.append(f"{name} {fx(ba, 2)} (recall " + ", ".join(f"{k} {fx(v, 2)}" for k, v in rec.items()) + ")")
    moved = sum(c["scene"]["predicted"] != c["softer"]["predicted"] for c in ran)
    arr = sum(c["softer"]["predicted"] == "ARR" for c in ran)
    out += [f"- On the {len(ran)} cases run both ways (drawn by observed class, not a score of the development set), "
            f"{moved} changed their class; {arr} predicted ARR. The balanced accuracy {parts[0]}; {parts[1]}.", ""]
    static = ", ".join(f"{cls} {_sf(ran, cls, 'softer', 'static_class')[0]} of {_sf(ran, cls, 'softer')[1]} "
                       f"({_sf(ran, cls, 'scene', 'static_class')[0]})" for cls in CLASSES)
    wf = [c["softer"]["w_f"] / c["scene"]["w_f"] for c in ran
          if c["scene"].get("w_f_source") == "read back" and c["softer"].get("w_f_source") == "read back"]
    out += [f"- weac's static rule on the softer layer predicts SF in {static} records (at the scene's modulus in "
            "brackets)." + (f" The fracture energy read back from the recorded cut, where it was read both ways "
                            f"({len(wf)} cases): {fx(median(wf), 2)} times the scene's (median; {fx(min(wf), 2)} to "
                            f"{fx(max(wf), 2)})." if wf else ""), ""]
    refused = [c for c in cases if c["softer"].get("status") != "ok"]
    if refused:
        out += [f"- Not run on the softer layer ({len(refused)}): " + "; ".join(
            f"`{c['test']}` ({c['observed']}): {_why(c['softer'].get('error'))}" for c in refused) + ".", ""]
    out += [env_note(data)]
    return out
