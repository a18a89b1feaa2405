"""Field cases on the old snow and on a rigid base (benchmarks/field/rigid_base.py): a what-if of the base."""

from __future__ import annotations

from statistics import median

from .core import section
from .field_what_if import CUT_SHARE, change, class_check, command, cut_check, failed_lines, render_what_if
from .fmt import fx


def _to_rigid(data: dict) -> bool:
    """Whether the what-if moved the columns onto the rigid base (the committed run), not off it."""
    return data["switch"]["value"] is True


def _far_note(cases: list) -> str:
    """Where the cuts that moved beyond :data:`CUT_SHARE` stand in the substratum's compliance."""
    far = [c for c in cases if (ch := change(c)) is not None and abs(ch) > CUT_SHARE]
    near = [c["detail"]["compliance_ratio"] for c in cases if (ch := change(c)) is not None and abs(ch) <= CUT_SHARE]
    if not far or not near:
        return ""
    return (f" Those columns' old snow is {' and '.join(fx(c['detail']['compliance_ratio'], 2) for c in far)} times "
            f"as compliant as their weak layer (the others' median {fx(median(near), 2)}), and on the rigid base "
            f"their crack ran away at a {'longer' if all(change(c) > 0 for c in far) else 'different'} cut: the old "
            "snow's give, which weac's column does not have either, had let it run sooner.")


def _notes(data: dict) -> list[str]:
    """What the old snow's compliance and the rigid base's cost say (a run onto the rigid base)."""
    cases = data["cases"]
    if not _to_rigid(data):
        return failed_lines(data)
    same = [c["before"]["predicted"] == c["after"]["predicted"] for c in cases]
    changes = [ch for ch in map(change, cases) if ch is not None]
    far = [c for c in cases if (ch := change(c)) is not None and abs(ch) > CUT_SHARE]
    speed = [c["before"]["cost"]["wall_s"] / c["after"]["cost"]["wall_s"] for c in cases]
    ratios = [c["detail"]["compliance_ratio"] for c in cases]
    return [f"- The substratum's compliance is {fx(min(ratios), 2)} to {fx(max(ratios), 2)} times the weak layer's "
            f"(median {fx(median(ratios), 2)}) in these columns: not small. Leaving it out "
            + ("changed no class" if all(same) else f"changed the class in {len(same) - sum(same)}")
            + (f", and moved the runaway cut by more than twice the grid's own error in {len(far)} of {len(changes)}."
               if far else ", and moved no runaway cut by more than twice the grid's own error.")
            + _far_note(cases),
            f"- Cost: the rigid base took {fx(min(speed), 2)} to {fx(max(speed), 2)} times less wall time (median "
            f"{fx(median(speed), 2)}x; median {fx(median(c['before']['cost']['wall_s'] for c in cases), 0)} s on the "
            f"old snow, {fx(median(c['after']['cost']['wall_s'] for c in cases), 0)} s on the rigid base), from fewer "
            "particles and, where the old snow was stiffer than the slab, a longer time step. The runs on the old "
            "snow are the batches' own, each beside another case on the 2 cores; each rigid run here shared them "
            "with one other job too.", ""]


def _intro(data: dict) -> str:
    b, a = ("old snow", "rigid base") if _to_rigid(data) else ("rigid base", "old snow")
    return (f"Cases: {data['chosen']}, each run again with the base under its weak layer moved from the {b} to the "
            f"{a} (`scene.rigid_base`) and nothing else changed. Each pair of values is on the {b} / on the {a}. The "
            "compliance ratio is the substratum's under a normal load over the weak layer's (`sum d / M` over "
            "`D_wl / M_wl`, M the constrained modulus): what the rigid base leaves out.")


@section("field", "The rigid base: the same columns without their old snow", "field/results/field_rigid_base.json",
         command("rigid_base"),
         question="What changes when a field column's weak layer lies on a rigid base, as in weac, instead of on "
                  "the profile's old snow?")
def render_rigid_base(data: dict, ctx) -> list[str]:
    return render_what_if(data, ctx, intro=_intro, columns=("predicted", "runaway", "change", "broke", "compliance",
                                                            "particles", "steps", "wall"),
                          checks=(class_check, cut_check), notes=(_notes,))
