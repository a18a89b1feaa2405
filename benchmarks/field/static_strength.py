"""Does the grain form of the slab's snow tell SF from END? weac's static rule on every scored column, with faceted
layers at their in-situ strength.

In situ, faceted snow was about half as strong in tension as rounded or partly settled snow of the same density
(Jamieson and Johnston 1990; docs/field.md); the density law the model and its static baseline take (Sigrist 2006,
docs/model.md §9) has no grain form. If faceted slabs were where the observers saw SF, weakening them would send
weac's static rule (SF where the slab's tensile stress at the recorded cut reaches its strength, docs/field.md)
to SF in the SF records more than in the END ones. This study runs no MPM: every case the committed
development-set batches scored (``--batches``) is set up again from its pit (its id's digest must match), and
weac's static class is taken at the density law's strength and with every slab layer of faceted snow (primary
grain FC or DH) at ``--faceted`` times it, nothing else changed. Per case: the slab's faceted share (of its
thickness) and both static classes. Writes ``benchmarks/field/results/field_static_strength.json``.

Usage: ``python benchmarks/field/static_strength.py DIR [--faceted 0.5] [--batches JSON ...]``; ``--quick``:
the first 3 cases, to a temporary folder. About a second a case.
"""

from __future__ import annotations

import os
import sys
import time
import warnings

from mpm_warp.field.static_rule import weac_static_class
from mpm_warp.field.studies.drawn import add_data_arguments, scored_cases
from mpm_warp.field.studies.slab_strength import FACETED, faceted_share, weaker
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")


def main(argv=None) -> int:
    p = parser(__doc__, "the first 3 cases")
    add_data_arguments(p, RESULTS)
    p.add_argument("--faceted", type=float, default=0.5,
                   help="a faceted layer's (FC, DH) strength over the density law's (default 0.5, in situ)")
    args = p.parse_args(argv)
    if not 0.0 < args.faceted <= 1.0:
        print(f"error: --faceted = {args.faceted:g} is invalid: expected a factor in (0, 1]", file=sys.stderr)
        return 2
    warnings.filterwarnings("ignore")
    env = environment("cpu")
    t0 = time.perf_counter()
    scored = scored_cases(args.batches, args.data, 3 if args.quick else None)
    if scored is None:
        return 2
    chosen, cases = scored
    out = []
    for b, case in zip(chosen, cases, strict=True):
        law = weac_static_class(case.params)
        grain = weac_static_class(weaker(case, 1.0, args.faceted).params)
        out.append({"id": b["id"], "test": b["test"], "observed": b["observed"], "predicted": b["predicted"],
                    "faceted_share": faceted_share(case.params), "static_batch": b.get("static_class"),
                    "static_law": law, "static_grain": grain})
    wall = time.perf_counter() - t0
    data = {"name": "field_static_strength", "faceted": args.faceted, "faceted_grains": list(FACETED),
            "batches": [os.path.relpath(b, HERE) for b in args.batches], "wall_s": wall, "environment": env,
            "cases": out}
    path = write_json("field_static_strength", data, out_dir(args, RESULTS, "field_static_strength"))
    print(f"{path}: {len(out)} cases in {wall:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
