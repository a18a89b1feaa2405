"""Would a softer weak layer tell the outcomes apart? The field columns set up again with a softer weak layer.

A pit records no stiffness: every field column's weak layer has the scene's Young's modulus, 1 MPa
(docs/profiles.md, "What the profile does not give"), the top of the 0.05-1 MPa that field weak layers span
(docs/model.md §6, "Field ranges"); weac's own default is 0.25 MPa. The weak layer's modulus sets how far the slab's
bending reaches beyond the cut, so the slab's stress at the crack tip, and, through weac's energy release rate at
the recorded cut, the fracture energy the run takes. This what-if study draws the columns of the strength study
(``closure.py``'s draw: ``--per-class`` of each observed class, ``--seed``, among the committed batches' cases
whose run took at most ``--max-wall`` s), sets each up again from its pit as the batch did (its id's digest must
match) and then again with the weak layer's modulus at ``--modulus``, as the batch would set it up with that
modulus: the fracture energy read back again from the recorded cut and the weak layer calibrated again. It runs
those by the field protocol into ``--runs`` (a Dask batch: resumable). Per case, at the scene's modulus (the
batch's run) and at ``--modulus``: the class, weac's static rule, the fracture energy, the runaway cut and where
the slab broke. A column the softer layer leaves the model unable to take is said in one line. No default changes.
Writes ``field_weak_modulus.json`` under ``benchmarks/field/results/`` or ``--out``.

Usage: ``python benchmarks/field/weak_modulus.py DIR --runs RUNDIR [--modulus 0.25] [--per-class 16] [--seed 0]
[--max-wall 120] [--workers N]``; ``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import warnings

from closure import KEYS, add_draw_arguments, draw_and_run

from mpm_warp.field.cases import FieldCase, field_base, field_case
from mpm_warp.field.protocol import FieldProtocol
from mpm_warp.scenes.profile import read_profile
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import parser

#: weac's default weak-layer modulus (MPa), the study's default
WEAC_MODULUS_MPA = 0.25


def softer(case: FieldCase, data: str, modulus: float):
    """``case`` set up again from its pit in ``data`` with the weak layer's Young's modulus ``modulus`` (Pa), as the
    batch sets a column up (the fracture energy read back, the layer calibrated): a FieldCase, or the FieldRefusal
    that says why the model cannot take it. Nothing but the weak layer may change (checked)."""
    base = field_base()
    base = dataclasses.replace(base, weak_layer=dataclasses.replace(base.weak_layer, E=modulus))
    new = field_case(read_profile(os.path.join(data, case.pit)), case.record, base=base)
    if isinstance(new, FieldCase) and dataclasses.replace(new.params, weak_layer=case.params.weak_layer) != case.params:
        raise AssertionError(f"{case.test}: more than the weak layer changed with its modulus")
    return new


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_draw_arguments(p, "with the softer weak layer", per_class=16)
    p.add_argument("--modulus", type=float, default=WEAC_MODULUS_MPA,
                   help=f"the weak layer's Young's modulus (MPa, default {WEAC_MODULUS_MPA:g}: weac's)")
    args = p.parse_args(argv)
    if not 0.05 <= args.modulus < 1.0:
        print(f"error: --modulus = {args.modulus:g} is invalid: expected 0.05-1 MPa (below the scene's 1 MPa)",
              file=sys.stderr)
        return 2
    warnings.filterwarnings("ignore")
    proto = FieldProtocol(threads=args.threads).validate()
    drawn = draw_and_run(args, "field_weak_modulus", environment("cpu"), proto, proto,
                         adjust=lambda c: softer(c, args.data, args.modulus * 1e6))
    if drawn is None:
        return 2
    chosen, records, meta = drawn
    rows = []
    for b, rec in zip(chosen, records, strict=True):
        rows.append({"id": b["id"], "softer_id": rec["id"], "test": b["test"], "observed": b["observed"],
                     "setup": b["setup"], "scene": {k: b.get(k) for k in KEYS + ("static_class", "w_f", "w_f_source")},
                     "softer": {k: rec.get(k) for k in KEYS + ("static_class", "w_f", "w_f_source", "error")}})
        print(f"{b['test']} ({b['observed']}): {b['predicted']} -> {rec.get('predicted') or rec['status']}, w_f "
              f"{b['w_f']} -> {rec.get('w_f')}, static {b.get('static_class')} -> {rec.get('static_class')}",
              flush=True)
    dest = meta.pop("dest")
    meta.pop("cases")
    data = {"name": "field_weak_modulus", "modulus_mpa": args.modulus,
            "scene_modulus_mpa": field_base().weak_layer.E / 1e6, **meta, "cases": rows}
    path = write_json("field_weak_modulus", data, dest)
    print(f"{path}: {len(rows)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
