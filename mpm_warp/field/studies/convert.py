"""The earlier what-if studies' own result schemas converted to the one of :mod:`.what_if`, every value kept.

Each study once wrote its own pair of keys (``off``/``on``, ``without``/``with``, ``substratum``/``rigid``,
``coarse``/``fine``, ``scene``/``softer``, ``law``/``scaled``). :func:`convert` rewrites such a result as
``before``/``after`` rows with the switch named once, keeps every other top-level field (the environment with
the commit that produced it above all) and adds ``schema_converted``, a note that the schema was converted.
A run that wrote no ``status`` (the checkpoint reruns) finished: its side reads ``ok``. The per-key notes
``<key>_null`` (why a value is null) are left out; :func:`convert` refuses to lose any number or flag.

``python -m mpm_warp.field.studies.convert FILE [FILE ...]`` converts committed results in place.
"""

from __future__ import annotations

import json
import sys
from collections import Counter

from .what_if import SCHEMA, switch_record, what_if_row

__all__ = ["OLD", "convert", "values"]

#: per old result name: the keys of the two sides, the switch, its values from the result (the what-if's and the
#: runs' it is compared with: then the runs on the old snow, without a pre-cut), the row's keys that go to
#: ``detail``, the old key of the what-if's case id
OLD = {
    "field_closure": ("off", "on", "interface_closure", lambda d: (True, False), (), "closure_id"),
    "field_pre_cut": ("without", "with", "pre_cut_share", lambda d: (d["share"], 0.0),
                      ("static_cut", "pre_cut", "case_wall_s"), None),
    "field_rigid_base": ("substratum", "rigid", "rigid_base", lambda d: (True, False),
                         ("compliance_ratio", "substratum_m", "case_wall_s"), None),
    "field_resolution": ("coarse", "fine", "cells_across", lambda d: tuple(d["cells"][::-1]),
                         ("cells", "dx", "case_wall_s"), None),
    "field_weak_modulus": ("scene", "softer", "weak_modulus", lambda d: (d["modulus_mpa"], d["scene_modulus_mpa"]),
                           (), "softer_id"),
    "field_strength": ("law", "scaled", None, None, ("faceted_share",), "scaled_id"),
}


def values(obj) -> Counter:
    """Every number and flag in ``obj`` (nested), counted: what a conversion must keep."""
    out = Counter()
    if isinstance(obj, dict):
        for v in obj.values():
            out.update(values(v))
    elif isinstance(obj, list):
        for v in obj:
            out.update(values(v))
    elif isinstance(obj, (bool, int, float)) and not isinstance(obj, str):
        out[(type(obj).__name__, obj)] += 1
    return out


def _strength_switch(data: dict) -> tuple[str, tuple[float, float]]:
    """The strength study's switch: the faceted layers' factor where it was not 1, else every layer's."""
    f = data.get("faceted", 1.0)
    return ("slab_strength", (data["scale"], 1.0)) if f == 1.0 else ("faceted_strength", (f, 1.0))


def convert(data: dict) -> dict:
    """The result ``data`` of an earlier what-if study (its ``name`` a key of :data:`OLD`) in the what-if schema.

    Raises
    ------
    ValueError
        Where ``data`` is no such result, is converted already, or its conversion would lose a number or a flag.
    """
    if data.get("schema") == SCHEMA:
        raise ValueError(f"{data.get('name')}: converted already")
    if data.get("name") not in OLD:
        raise ValueError(f"{data.get('name')!r} is not an earlier what-if study's result ({', '.join(OLD)})")
    b_key, a_key, name, value_of, detail_keys, id_key = OLD[data["name"]]
    name, (value, was) = _strength_switch(data) if name is None else (name, value_of(data))
    rows = []
    for c in data["cases"]:
        before = {"status": "ok", "w_f": c.get("w_f"), "w_f_source": c.get("w_f_source"), **c[b_key]}
        after = {"status": "ok", **c[a_key]}
        rows.append(what_if_row(c, before, after, c.get(id_key) if id_key else None,
                                {k: c[k] for k in detail_keys if k in c}))
    head = {k: v for k, v in data.items() if k != "cases"}
    out = {"name": data["name"], "schema": SCHEMA, "switch": switch_record(name, value, was), **head,
           "schema_converted": f"converted from {data['name']}'s own keys ({b_key}, {a_key}) to the what-if schema "
                               "(mpm_warp.field.studies.convert); every value as the run wrote it, the environment "
                               "that of the run",
           "cases": rows}
    lost = values(data) - values(out)
    if lost:
        raise ValueError(f"{data['name']}: the conversion would lose {sorted(lost)[:3]}")
    return out


def main(argv=None) -> int:
    from ...finite_json import dump_finite

    for path in (sys.argv[1:] if argv is None else argv):
        with open(path) as fh:
            new = convert(json.load(fh))
        with open(path, "w") as fh:
            dump_finite(new, fh, indent=1, default=float)
            fh.write("\n")
        print(f"{path}: {len(new['cases'])} cases, switch {new['switch']['name']} = {new['switch']['value']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
