"""The development set's draw: the measured-density columns and a seeded sample stratified by observed class.

:func:`select` is the draw the field batch runs (benchmarks/field/field_batch.py), in its interleaved order (END,
SF, ARR, END, ...), so that the first N cases of a batch stopped early are as stratified as N allows;
:func:`finished_draw` reads back the records of the drawn cases whose runs have finished, without running or
building anything.
"""

from __future__ import annotations

import random

from .scores import FIELD_CLASSES, field_class

__all__ = ["all_measured", "select", "finished_draw"]


def all_measured(case) -> bool:
    """Every slab layer's density was measured in the pit."""
    return all(p.measured for p in case.column.slab)


def select(cases, per_class: int, seed: int, measured: bool = True) -> tuple[list, dict]:
    """The measured-density columns (when ``measured``) and a seeded sample of ``per_class`` per observed class,
    interleaved; and the counts drawn (``measured``, ``END``, ``SF``, ``ARR``)."""
    chosen = [c for c in cases if measured and all_measured(c)]
    rest = [c for c in cases if not (measured and all_measured(c))]
    rng = random.Random(seed)
    counts = {"measured": len(chosen)}
    takes = []
    for cls in FIELD_CLASSES:
        pool = [c for c in rest if field_class(c.outcome) == cls]
        takes.append(rng.sample(pool, min(per_class, len(pool))))
        counts[cls] = len(takes[-1])
    chosen += [t[k] for k in range(max(map(len, takes), default=0)) for t in takes if k < len(t)]
    return chosen, counts


def finished_draw(data: str, runs: str, per_class: int, seed: int, measured: bool = False,
                  protocol=None) -> tuple[list[dict], dict]:
    """The records of the draw's cases (:func:`select` of the pits in ``data``) whose runs in ``runs`` under
    ``protocol`` (default the field protocol) have finished, in draw order; and what was drawn."""
    from .batch import finished_records, gather
    from .protocol import FieldProtocol

    cases, refused = gather([data], calibrate=False)
    chosen, counts = select(cases, per_class, seed, measured=measured)
    recs = finished_records(chosen, runs, (protocol or FieldProtocol()).validate())
    return recs, {"runnable": len(cases), "refused": len(refused), **counts, "seed": seed, "per_class": per_class,
                  "finished": len(recs)}
