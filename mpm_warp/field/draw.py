"""The development set's draw: the measured-density columns and a seeded sample stratified by observed class.

:func:`select` is the draw the field batch runs (benchmarks/field/field_batch.py), in its interleaved order (END,
SF, ARR, END, ...), so that the first N cases of a batch stopped early are as stratified as N allows;
:func:`finished_draw` reads back the records of the drawn cases whose runs have finished, without running or
building anything.
"""

from __future__ import annotations

import random

from .scores import FIELD_CLASSES, field_class

__all__ = ["all_measured", "sample_per_class", "select", "finished_draw"]


def all_measured(case) -> bool:
    """Every slab layer's density was measured in the pit."""
    return all(p.measured for p in case.column.slab)


def sample_per_class(items, per_class: int, seed: int, class_of) -> list[list]:
    """A seeded sample of ``per_class`` of ``items`` (fewer where fewer) for each observed class, in the order of
    :data:`FIELD_CLASSES` (END, SF, ARR): one list a class. ``class_of(item)`` is an item's observed class; one
    ``random.Random(seed)`` draws the classes in turn, so the same items and seed give the same sample."""
    rng = random.Random(seed)
    return [rng.sample(of, min(per_class, len(of))) for of in
            ([x for x in items if class_of(x) == cls] for cls in FIELD_CLASSES)]


def select(cases, per_class: int, seed: int, measured: bool = True) -> tuple[list, dict]:
    """The measured-density columns (when ``measured``) and a seeded sample of ``per_class`` per observed class,
    interleaved; and the counts drawn (``measured``, ``END``, ``SF``, ``ARR``)."""
    chosen = [c for c in cases if measured and all_measured(c)]
    rest = [c for c in cases if not (measured and all_measured(c))]
    takes = sample_per_class(rest, per_class, seed, lambda c: field_class(c.outcome))
    counts = {"measured": len(chosen), **{cls: len(t) for cls, t in zip(FIELD_CLASSES, takes, strict=True)}}
    chosen += [t[k] for k in range(max(map(len, takes), default=0)) for t in takes if k < len(t)]
    return chosen, counts


def finished_draw(data: str, runs: str, per_class: int, seed: int, measured: bool = False,
                  protocol=None) -> tuple[list[dict], dict]:
    """The records of the draw's cases (:func:`select` of the pits in ``data``) whose runs in ``runs`` under
    ``protocol`` (default the field protocol) have finished, in draw order; and what was drawn, with how many of
    the drawn cases without a finished run the protocol refuses when it builds them (``refused_at_build``: the
    particle budget, a column the model cannot represent): with those, the draw is whole."""
    from ..errors import InvalidArgument
    from .batch import case_scenario, finished_records, gather
    from .protocol import FieldProtocol

    proto = (protocol or FieldProtocol()).validate()
    cases, refused = gather([data], calibrate=False)
    chosen, counts = select(cases, per_class, seed, measured=measured)
    missing = []
    recs = finished_records(chosen, runs, proto, missing=missing)
    at_build = 0
    for c in missing:
        try:
            at_build += case_scenario(c, proto)[0] is None
        except InvalidArgument:
            at_build += 1
    return recs, {"runnable": len(cases), "refused": len(refused), **counts, "seed": seed, "per_class": per_class,
                  "finished": len(recs), "refused_at_build": at_build}
