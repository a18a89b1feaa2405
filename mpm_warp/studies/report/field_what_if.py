"""The one renderer of a field what-if result (:mod:`mpm_warp.field.studies.what_if`'s schema), and its parts.

:func:`render_what_if` writes any such result: a line on its cases, one table row a case (each cell a pair,
before / after, of the columns :data:`COLUMNS` names), its checks, its notes and the environment. A study's
section (:mod:`.field_closure`, :mod:`.field_rigid_base`, ...) names its columns, checks and notes; without them
a result renders with :data:`DEFAULT`.
"""

from __future__ import annotations

from statistics import median

from ...field.studies.switches import SWITCHES
from ...scenes.pst.outcome import FIELD_CLASSES as CLASSES
from .fmt import check_line, count, env_note, fx, spct, table

__all__ = ["CLASSES", "CUT_SHARE", "COLUMNS", "DEFAULT", "render_what_if", "labels", "cut", "change", "ran",
           "balanced", "class_check", "cut_check", "failed_lines", "balanced_line", "command"]

#: the runaway cut may move by this share (-) between the two runs: twice the critical cut's error the snow ladder
#: states at 6 cells across the weak layer (5.6 %, docs/results/convergence.md "Error against run time: the snow
#: ladders")
CUT_SHARE = 0.10


def cut(x) -> str:
    """A cut or a position along the column (m), or ``-``."""
    return "-" if x is None else fx(x, 3)


def labels(data: dict) -> tuple[str, str]:
    """How the two sides of a result read: the switch's label of the value before and of the what-if's."""
    s = data["switch"]
    label = SWITCHES[s["name"]].label
    return label(s["before"]), label(s["value"])


def change(c: dict) -> float | None:
    """The runaway cut's change from before to after (-); None unless both ran away."""
    a, b = c["before"]["runaway_cut"], c["after"]["runaway_cut"]
    return None if not a or not b else b / a - 1.0


def ran(cases: list) -> list:
    """The cases run both ways (``status`` ok on both sides)."""
    return [c for c in cases if c["before"].get("status") == "ok" and c["after"].get("status") == "ok"]


def balanced(cases: list, side: str) -> tuple[float | None, dict]:
    """The balanced accuracy of ``side``'s predictions (``c[side]["predicted"]``) over the observed classes
    present, and the recall of each."""
    recall = {}
    for cls in CLASSES:
        of = [c for c in cases if c["observed"] == cls]
        if of:
            recall[cls] = sum(c[side]["predicted"] == cls for c in of) / len(of)
    return (sum(recall.values()) / len(recall) if recall else None), recall


def _pair(a, b) -> str:
    return f"{a} / {b}"


def _cost(c: dict, side: str, key: str):
    return c[side]["cost"].get(key)


def _wall(c: dict, side: str, threads: bool) -> str:
    w = fx(_cost(c, side, "wall_s"), 0)
    return f"{w} ({_cost(c, side, 'threads') or '-'})" if threads else w


#: the table's columns: name -> (header, cell of a case)
COLUMNS = {
    "critical_cut": ("weac's critical cut (m)", lambda c: cut(c["detail"].get("static_cut"))),
    "pre_cut": ("pre-cut (m)", lambda c: cut(c["detail"].get("pre_cut"))),
    "dx": ("dx (mm)", lambda c: _pair(*(fx(x, 2, 1e3) for x in c["detail"]["dx"]))),
    "predicted": ("predicted", lambda c: _pair(c["before"]["predicted"],
                                               c["after"]["predicted"] or c["after"].get("status"))),
    "static": ("weac's static rule", lambda c: _pair(c["before"].get("static_class"),
                                                     c["after"].get("static_class") or "-")),
    "w_f": ("w_f (J/m^2)", lambda c: _pair(fx(c["before"].get("w_f"), 3), fx(c["after"].get("w_f"), 3))),
    "runaway": ("runaway cut (m)", lambda c: _pair(cut(c["before"]["runaway_cut"]), cut(c["after"]["runaway_cut"]))),
    "change": ("cut change", lambda c: "-" if change(c) is None else spct(change(c))),
    "broke": ("slab broke at (m)", lambda c: _pair(cut(c["before"]["slab_fracture_at"]),
                                                   cut(c["after"]["slab_fracture_at"]))),
    "broke_after": ("slab broke at (m), after", lambda c: cut(c["after"]["slab_fracture_at"])),
    "compliance": ("compliance ratio", lambda c: fx(c["detail"].get("compliance_ratio"), 2)),
    "particles": ("particles", lambda c: _pair(count(_cost(c, "before", "particles")),
                                               count(_cost(c, "after", "particles")))),
    "steps": ("steps", lambda c: _pair(count(_cost(c, "before", "steps")), count(_cost(c, "after", "steps")))),
    "wall": ("wall time (s)", lambda c: _pair(_wall(c, "before", False), _wall(c, "after", False))),
    "wall_threads": ("wall time, s (threads)", lambda c: _pair(_wall(c, "before", True), _wall(c, "after", True))),
}


def class_check(data: dict) -> str:
    """The check that the what-if keeps every class, over the cases run both ways, naming those it changed."""
    b, a = labels(data)
    cases = ran(data["cases"])
    same = [c["before"]["predicted"] == c["after"]["predicted"] for c in cases]
    moved = [f"`{c['test']}` ({c['observed']}): {c['before']['predicted']} -> {c['after']['predicted']}"
             for c, s in zip(cases, same, strict=True) if not s]
    return check_line(f"the predicted class {b} and {a}", "the same in every case", all(same),
                      f"{sum(same)} of {len(same)}" + (f"; changed: {'; '.join(moved)}" if moved else ""))


def cut_check(data: dict) -> str:
    """The check that the runaway cut moves by at most :data:`CUT_SHARE` where both runs ran away."""
    b, a = labels(data)
    cases = ran(data["cases"])
    changes = [ch for ch in map(change, cases) if ch is not None]
    far = [f"`{c['test']}` {spct(ch)}" for c in cases if (ch := change(c)) is not None and abs(ch) > CUT_SHARE]
    return check_line(f"the runaway cut {b} and {a}", f"within {fx(100 * CUT_SHARE, 0)} % (twice the snow ladder's "
                      "critical-cut error at 6 cells) in every case that ran away both times",
                      bool(changes) and not far,
                      f"{len(changes) - len(far)} of {len(changes)}, from {spct(min(changes))} to {spct(max(changes))}"
                      + (f"; apart: {', '.join(far)}" if far else "") if changes else "no case ran away both times")


def _why(side: dict) -> str:
    """Why a side did not run: a refusal's reason without its record (``pit: PST ...: reason``), a failure's
    without its exception's name and after its first clause."""
    line = side.get("error") or ""
    if side.get("status") == "refused":
        return line.split(" cm: ", 1)[-1]
    return line.split(": ", 1)[-1].split(";")[0]


def failed_lines(data: dict) -> list[str]:
    """A line on the cases the what-if did not run (failed or refused), each with its reason."""
    not_run = [c for c in data["cases"] if c["after"].get("status") != "ok"]
    if not not_run:
        return []
    b, a = labels(data)
    return [f"- Not run {a} ({len(not_run)}): " + "; ".join(
        f"`{c['test']}` ({c['observed']}" + (f", {c['setup']}" if c.get("setup") else "") + f"): {_why(c['after'])}"
        for c in not_run)
        + f". The runs {b} are the batch's, which finished.", ""]


def balanced_line(data: dict) -> list[str]:
    """The balanced accuracy and recalls both ways, over the cases run both ways, and how many changed class."""
    cases = ran(data["cases"])
    parts = []
    for side, name in zip(("before", "after"), labels(data), strict=True):
        ba, rec = balanced(cases, side)
        parts.append(f"{name} {fx(ba, 2)} (recall " + ", ".join(f"{k} {fx(v, 2)}" for k, v in rec.items()) + ")")
    moved = sum(c["before"]["predicted"] != c["after"]["predicted"] for c in cases)
    return [f"- On the {len(cases)} cases run both ways (drawn by observed class, not a score of the development "
            f"set), {moved} changed their class. The balanced accuracy {parts[0]}; {parts[1]}.", ""]


def _steps_line(data: dict) -> list[str]:
    """The default cost note: steps after over before, and the wall time where both ran on the same threads."""
    cases = ran(data["cases"])
    steps = [c["after"]["cost"]["steps"] / c["before"]["cost"]["steps"] for c in cases
             if c["before"]["cost"].get("steps") and c["after"]["cost"].get("steps")]
    if not steps:
        return []
    return [f"- Cost: steps {labels(data)[1]} over {labels(data)[0]} {fx(min(steps), 2)} to {fx(max(steps), 2)} "
            f"(median {fx(median(steps), 2)}; a run stops at the first frame its outcome is decided).", ""]


def _intro(data: dict) -> str:
    b, a = labels(data)
    return (f"Cases: {data['chosen']}, each run again with {SWITCHES[data['switch']['name']].what} changed, nothing "
            f"else. Each pair of values is {b} / {a}.")


#: a result's rendering without a study's own: intro, columns, checks, notes
DEFAULT = {"intro": _intro,
           "columns": ("predicted", "runaway", "change", "broke", "particles", "steps", "wall_threads"),
           "checks": (class_check, cut_check), "notes": (failed_lines, balanced_line, _steps_line)}


def render_what_if(data: dict, ctx=None, *, intro=None, columns=None, checks=None, notes=None) -> list[str]:
    """The Markdown of a what-if result ``data``: ``intro(data)`` (a paragraph), the table of ``columns`` (names
    of :data:`COLUMNS`, or ``(header, cell)`` pairs of a study's own), one line a check (``check(data) -> str``),
    each note's lines (``note(data) -> list``, or ``note(data, ctx)`` where it takes two) and the environment
    note. What is not given is :data:`DEFAULT`'s."""
    intro, columns = intro or DEFAULT["intro"], columns or DEFAULT["columns"]
    checks = DEFAULT["checks"] if checks is None else checks
    notes = DEFAULT["notes"] if notes is None else notes
    columns = [COLUMNS[k] if isinstance(k, str) else k for k in columns]
    head = ["record", "observed"] + [h for h, _ in columns]
    rows = [[f"`{c['test']}`", c["observed"]] + [cell(c) for _, cell in columns] for c in data["cases"]]
    out = [intro(data), ""] + table(head, rows) + [""]
    out += [check(data) for check in checks] + [""] if checks else []
    for note in notes:
        out += note(data, ctx) if note.__code__.co_argcount == 2 else note(data)
    return out + [env_note(data)]


def command(script: str, option=None) -> callable:
    """The command that reproduces a what-if result of ``benchmarks/field/<script>.py``: its draw's arguments where
    the result has them, and ``option(data)`` (a string of the switch's option, or empty)."""
    def line(d: dict) -> str:
        extra = option(d) if option else ""
        draw = (f" --per-class {d['per_class']} --seed {d['seed']} --max-wall {d['max_wall_s']:g}"
                + (f" --workers {d['workers']} --threads {d['threads']}" if "workers" in d else "")
                if "per_class" in d else "")
        return f"python benchmarks/field/{script}.py DIR --runs RUNDIR{extra}{draw}"
    return line
