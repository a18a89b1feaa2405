"""Would a weaker slab tell SF from END? The field columns run again with their slab's tensile strength scaled.

The model calls 35 of the development set's 45 SF records END: their slab never cracked through
(docs/results/field.md, "Field outcomes against the observers"). The static FE's slab stress ranks an SF record
above an END record in 85 % of the pairs (docs/results/field-slab.md, "A resolved slab"), so the SF slabs are the
more loaded ones, but at a fraction of their strength (Sigrist 2006 from the density, docs/model.md §9). This
sensitivity study asks whether the strength law is the lever: if a slab weaker by a factor ``--scale`` broke mostly
in the SF records and seldom in the END ones, an independently measured field-scale strength would be worth taking;
if it broke in both alike, the strength law cannot separate them. The factor is a what-if, never a calibration: no
default changes.

It draws the cases as ``closure.py`` does (``--per-class`` of each observed class at random, ``--seed``, among the
committed batches' cases whose run took at most ``--max-wall`` s), sets each up again from its pit (its id's
digest must match the batch's), sets every slab layer's tensile strength to ``--scale`` times its density law's,
nothing else changed (the fracture energy stays the density law's), and runs it by the field protocol into
``--runs`` (a Dask batch: resumable). Per case: the class, the runaway cut and where the slab broke, at the
density law's strength (the batch's run) and scaled. Writes ``field_strength.json`` under
``benchmarks/field/results/`` or ``--out``.

Usage: ``python benchmarks/field/strength.py DIR --runs RUNDIR [--scale 0.5] [--faceted 1] [--per-class 8]
[--seed 0] [--max-wall 120] [--workers N]``; ``--quick``: one case of at most 20 s, to a temporary folder.
Minutes a case.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import warnings

from closure import KEYS, add_draw_arguments, draw_and_run

from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.field.static_rule import weac_static_class
from mpm_warp.scenes.density_laws import sigrist_tensile_strength
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")


#: primary grain forms of faceted snow (IACS classes FC and DH, every subclass)
FACETED = ("FC", "DH")


def faceted(layer) -> bool:
    """Whether a field column's slab layer is of faceted snow: its name starts with its grains, primary first
    (``"FCxr/RG 4F, 180 kg/m3 (estimated)"``, docs/profiles.md)."""
    return (layer.name or "").startswith(FACETED)


def faceted_share(params) -> float:
    """The share of a column's slab thickness that is faceted snow (-)."""
    layers = params.slab_stack()
    return sum(ly.thickness for ly in layers if faceted(ly)) / sum(ly.thickness for ly in layers)


def weaker(case, scale: float, facets: float = 1.0):
    """``case`` with every slab layer's tensile strength ``scale`` times its density law's (Pa), ``facets`` times
    more for a layer of faceted snow, and nothing else changed; a layer given its own strength keeps it scaled the
    same way."""
    def scaled(layer):
        base = layer.tensile_strength or sigrist_tensile_strength(layer.density)
        return dataclasses.replace(layer, tensile_strength=scale * base * (facets if faceted(layer) else 1.0))

    p = case.params
    if p.slab_layers:
        p = dataclasses.replace(p, slab_layers=tuple(scaled(ly) for ly in p.slab_layers))
    else:
        p = dataclasses.replace(p, slab=scaled(p.slab))
    return dataclasses.replace(case, params=p.validate("scene"))


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_draw_arguments(p, "with the scaled strength", per_class=8)
    p.add_argument("--scale", type=float, default=0.5, help="the slab's tensile strength over its law's (default 0.5)")
    p.add_argument("--faceted", type=float, default=1.0,
                   help="a faceted layer's (FC, DH) strength over the scaled law's (default 1; in situ about 0.5)")
    args = p.parse_args(argv)
    for name, v in (("--scale", args.scale), ("--faceted", args.faceted)):
        if not 0.0 < v <= 1.0:
            print(f"error: {name} = {v:g} is invalid: expected a factor in (0, 1]", file=sys.stderr)
            return 2
    warnings.filterwarnings("ignore")
    proto = FieldProtocol(threads=args.threads).validate()
    drawn = draw_and_run(args, "field_strength", environment("cpu"), proto, proto,
                         adjust=lambda c: weaker(c, args.scale, args.faceted))
    if drawn is None:
        return 2
    chosen, records, meta = drawn
    rows = []
    for b, rec, case in zip(chosen, records, meta.pop("cases"), strict=True):
        rows.append({"id": b["id"], "scaled_id": rec["id"], "test": b["test"], "observed": b["observed"],
                     "w_f": b["w_f"], "w_f_source": b["w_f_source"], "setup": b["setup"],
                     "faceted_share": faceted_share(case.params),
                     "law": {k: b.get(k) for k in KEYS + ("static_class",)},
                     "scaled": {k: rec.get(k) for k in KEYS + ("error",)} | {"static_class": weac_static_class(
                         case.params)}})
        print(f"{b['test']} ({b['observed']}): {b['predicted']} -> {rec.get('predicted')}, slab broke at "
              f"{b.get('slab_fracture_at')} -> {rec.get('slab_fracture_at')}", flush=True)
    dest = meta.pop("dest")
    data = {"name": "field_strength", "scale": args.scale, "faceted": args.faceted, "faceted_grains": list(FACETED),
            **meta, "cases": rows}
    path = write_json("field_strength", data, dest)
    print(f"{path}: {len(rows)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
