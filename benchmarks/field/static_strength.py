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

from mpm_warp.field.static_rule import weac_static_class
from mpm_warp.field.studies.drawn import add_data_arguments
from mpm_warp.field.studies.slab_strength import FACETED, faceted_share, weaker
from mpm_warp.studies.environment import environment
from mpm_warp.studies.field_static import static_study
from mpm_warp.studies.protocol import parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def main(argv=None) -> int:
    p = parser(__doc__, "the first 3 cases")
    add_data_arguments(p, RESULTS)
    p.add_argument("--faceted", type=float, default=0.5,
                   help="a faceted layer's (FC, DH) strength over the density law's (default 0.5, in situ)")
    args = p.parse_args(argv)
    if not 0.0 < args.faceted <= 1.0:
        print(f"error: --faceted = {args.faceted:g} is invalid: expected a factor in (0, 1]", file=sys.stderr)
        return 2
    return static_study(args, "field_static_strength", RESULTS, lambda b, case: _row(b, case, args.faceted),
                        {"faceted": args.faceted, "faceted_grains": list(FACETED)}, environment("cpu"))


def _row(b: dict, case, facets: float) -> dict:
    """weac's static class of one scored case at the law's strength and with its faceted layers at ``facets``."""
    return {"id": b["id"], "test": b["test"], "observed": b["observed"], "predicted": b["predicted"],
            "faceted_share": faceted_share(case.params), "static_batch": b.get("static_class"),
            "static_law": weac_static_class(case.params),
            "static_grain": weac_static_class(weaker(case, 1.0, facets).params)}


if __name__ == "__main__":
    sys.exit(main())
