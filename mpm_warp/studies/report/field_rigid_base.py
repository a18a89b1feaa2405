"""Field cases on the old snow and on a rigid base (benchmarks/field/rigid_base.py)."""

from __future__ import annotations

from statistics import median

from .core import section
from .fmt import check_line, count, env_note, fx, spct, table

#: the runaway cut may move by this share (-) between the bases: twice the critical cut's error the snow ladder
#: states at 6 cells across the weak layer (5.6 %, docs/results/convergence.md "Error against run time: the snow
#: ladders")
CUT_SHARE = 0.10


def _cut(x) -> str:
    return "-" if x is None else fx(x, 3)


def _change(c: dict):
    a, b = c["substratum"]["runaway_cut"], c["rigid"]["runaway_cut"]
    return None if not a or not b else b / a - 1.0


def _far_note(cases: list) -> str:
    """Where the cuts that moved beyond :data:`CUT_SHARE` stand in the substratum's compliance."""
    far = [c for c in cases if (ch := _change(c)) is not None and abs(ch) > CUT_SHARE]
    near = [c["compliance_ratio"] for c in cases if (ch := _change(c)) is not None and abs(ch) <= CUT_SHARE]
    if not far or not near:
        return ""
    return (f" Those columns' old snow is {' and '.join(fx(c['compliance_ratio'], 2) for c in far)} times as "
            f"compliant as their weak layer (the others' median {fx(median(near), 2)}), and on the rigid base their "
            f"crack ran away at a {'longer' if all(_change(c) > 0 for c in far) else 'different'} cut: the old snow's "
            "give, which weac's column does not have either, had let it run sooner.")


@section("field", "The rigid base: the same columns without their old snow", "field/results/field_rigid_base.json",
         lambda d: "python benchmarks/field/rigid_base.py RUNDIR1 RUNDIR2  # the runs on the old snow",
         question="What changes when a field column's weak layer lies on a rigid base, as in weac, instead of on "
                  "the profile's old snow?")
def render_rigid_base(data: dict, ctx) -> list[str]:
    cases = data["cases"]
    rows = []
    for c in cases:
        s, r, ch = c["substratum"], c["rigid"], _change(c)
        rows.append([f"`{c['test']}`", c["observed"], f"{s['predicted']} / {r['predicted']}",
                     f"{_cut(s['runaway_cut'])} / {_cut(r['runaway_cut'])}", "-" if ch is None else spct(ch),
                     f"{_cut(s['slab_fracture_at'])} / {_cut(r['slab_fracture_at'])}", fx(c["compliance_ratio"], 2),
                     f"{count(s['particles'])} / {count(r['particles'])}", f"{count(s['steps'])} / {count(r['steps'])}",
                     f"{fx(s['wall_s'], 0)} / {fx(r['wall_s'], 0)}"])
    out = [f"Cases: {data['chosen']}, each run again from its checkpoint's scenario with the substratum replaced by "
           "the rigid base (`scene.rigid_base`) and nothing else changed. Each pair of values is on the old snow / "
           "on the rigid base. The compliance ratio is the substratum's under a normal load over the weak layer's "
           "(`sum d / M` over `D_wl / M_wl`, M the constrained modulus): what the rigid base leaves out.", ""]
    out += table(["record", "observed", "predicted", "runaway cut (m)", "cut change", "slab broke at (m)",
                  "compliance ratio", "particles", "steps", "wall time (s)"], rows)
    same = [c["substratum"]["predicted"] == c["rigid"]["predicted"] for c in cases]
    changes = [ch for ch in map(_change, cases) if ch is not None]
    far = [f"`{c['test']}` {spct(ch)}" for c in cases if (ch := _change(c)) is not None and abs(ch) > CUT_SHARE]
    speed = [c["substratum"]["wall_s"] / c["rigid"]["wall_s"] for c in cases]
    ratios = [c["compliance_ratio"] for c in cases]
    out += ["", check_line("the predicted class on the two bases", "the same in every case", all(same),
                           f"{sum(same)} of {len(same)}"),
            check_line("the runaway cut on the two bases", f"within {fx(100 * CUT_SHARE, 0)} % (twice the snow "
                       "ladder's critical-cut error at 6 cells) in every case that ran away on both",
                       bool(changes) and not far, f"{len(changes) - len(far)} of {len(changes)}, from "
                       f"{spct(min(changes))} to {spct(max(changes))}" + (f"; apart: {', '.join(far)}" if far else "")
                       if changes else "no case ran away"), ""]
    out += [f"- The substratum's compliance is {fx(min(ratios), 2)} to {fx(max(ratios), 2)} times the weak layer's "
            f"(median {fx(median(ratios), 2)}) in these columns: not small. Leaving it out "
            + ("changed no class" if all(same) else f"changed the class in {len(same) - sum(same)}")
            + (f", and moved the runaway cut by more than twice the grid's own error in {len(far)} of {len(changes)}."
               if far else ", and moved no runaway cut by more than twice the grid's own error.")
            + _far_note(cases),
            f"- Cost: the rigid base took {fx(min(speed), 2)} to {fx(max(speed), 2)} times less wall time (median "
            f"{fx(median(speed), 2)}x; median {fx(median(c['substratum']['wall_s'] for c in cases), 0)} s on the old "
            f"snow, {fx(median(c['rigid']['wall_s'] for c in cases), 0)} s on the rigid base), from fewer particles "
            "and, where the old snow was stiffer than the slab, a longer time step. The runs on the old snow are the "
            "batches' own, each beside another case on the 2 cores; each rigid run here shared them with one other "
            "job too.", "", env_note(data)]
    return out
