"""One what-if driver and the one schema it writes: drawn field cases run again with one switch changed.

:func:`run_what_if` takes batch rows (:func:`~.drawn.draw_rows`), sets each case up again from its pit as its
batch did, changes it by one switch of :data:`~.switches.SWITCHES` and runs it by the field protocol (a Dask
batch: resumable). Every study writes the same rows (:func:`what_if_row`): the case's ``id``, ``test``,
``observed`` class and ``setup``; ``before`` (the batch's run) and ``after`` (the what-if's), each with the keys
of :data:`SIDE_KEYS` and a ``cost`` of :data:`COST_KEYS`; ``after_id``; and the switch's ``detail``. The result
names its switch once: ``{"name", "value", "before"}``.
"""

from __future__ import annotations

import tempfile
import time

from ..batch import run_cases
from ..cases import FieldCase
from ..protocol import FieldProtocol
from .drawn import aligned_records, batch_cases
from .switches import SWITCHES

__all__ = ["SCHEMA", "SIDE_KEYS", "COST_KEYS", "side", "what_if_row", "switch_record", "run_what_if"]

#: the schema's name, in every result that follows it
SCHEMA = "field what-if 1"
#: what each side of a row says of its run (None where it does not say)
SIDE_KEYS = ("status", "predicted", "runaway_cut", "slab_fracture_at", "static_class", "w_f", "w_f_source", "error")
#: what each side's run cost: particles, steps, wall time (s), simulated time (s), threads, workers
COST_KEYS = ("particles", "steps", "wall_s", "sim_time", "threads", "workers")


def side(record: dict) -> dict:
    """One side of a row from a run's record (a batch row, or a what-if's record): :data:`SIDE_KEYS` and ``cost``."""
    return {**{k: record.get(k) for k in SIDE_KEYS}, "cost": {k: record.get(k) for k in COST_KEYS}}


def what_if_row(case: dict, before: dict, after: dict, after_id: str | None, detail: dict) -> dict:
    """A row of the schema: ``case`` gives ``id``, ``test``, ``observed`` and ``setup``; ``before`` and ``after``
    are the runs' records (:func:`side` of each)."""
    return {"id": case["id"], "after_id": after_id, "test": case["test"], "observed": case["observed"],
            "setup": case.get("setup"), "before": side(before), "after": side(after), "detail": detail}


def switch_record(name: str, value, before=None) -> dict:
    """A result's ``switch``: its name, the what-if's value and the value of the runs it is compared with
    (``before``; default the batch's, the switch's baseline)."""
    return {"name": name, "value": value, "before": SWITCHES[name].baseline if before is None else before}


def run_what_if(name: str, value, rows: list[dict], data: str, runs: str | None = None, *,
                workers: int | None = None, threads: int = 1) -> dict | None:
    """Run the batch ``rows`` again with the switch ``name`` at ``value``.

    Parameters
    ----------
    name : str
        A switch of :data:`~.switches.SWITCHES`.
    value : object
        Its what-if value (checked by the switch).
    rows : list of dict
        Finished batch rows (their ids name the cases' pits and keys).
    data : str
        The pits' folder (the unpacked development set).
    runs : str, optional
        The runs' folder (kept: a rerun resumes); default a temporary one.
    workers, threads : int
        Dask workers (default one per core) and each case's CPU threads.

    Returns
    -------
    dict or None
        ``switch`` (:func:`switch_record`), ``schema``, ``protocol`` (the what-if's run key), ``threads``,
        ``workers``, ``setup_s`` (s) and ``cases`` (:func:`what_if_row`, in the order of ``rows``); None where a
        case is not set up as its batch set it up (said on stderr).
    """
    from ...errors import InvalidArgument

    sw = SWITCHES[name]
    why = sw.check(value)
    if why is not None:
        raise InvalidArgument(name, value, why)
    base = FieldProtocol(threads=threads).validate()
    proto = sw.protocol(base, value)
    t0 = time.perf_counter()
    cases = batch_cases(data, rows, base)
    if cases is None:
        return None
    changed = [sw.change(c, value, data) for c in cases]
    setup_s = time.perf_counter() - t0
    with tempfile.TemporaryDirectory(prefix=f"mpm_warp_{name}_") as tmp:
        batch = run_cases([c for c in changed if isinstance(c, FieldCase)], [], runs or tmp, workers=workers,
                          protocol=proto)
    records = aligned_records(changed, batch, proto)
    out = [what_if_row(row, row, rec, rec.get("id"),
                       sw.detail(c, n, value) if isinstance(n, FieldCase) else {})
           for row, rec, c, n in zip(rows, records, cases, changed, strict=True)]
    return {"schema": SCHEMA, "switch": switch_record(name, value), "protocol": proto.run_key(), "threads": threads,
            "workers": workers, "setup_s": setup_s, "cases": out}
