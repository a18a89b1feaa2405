"""Is plane strain the slab's load in a 30 cm wide column? The static FE of every scored column in both plane limits.

The run and weac both take a PST column as infinitely wide across the slope (plane strain); a field column is 30 cm
wide, with free side walls, and its slab 10-100 cm deep, so it lies between plane strain and plane stress (a
column infinitely thin). If that mattered to the slab's stress, it could be physics the model lacks where the
observer saw the slab break. This study runs no MPM: every case the committed development-set batches scored
(``--batches``) is set up again from its pit (its id's digest must match) and solved statically at its recorded
cut, the cut the observer saw the crack start at, by the 9-node FE of ``slab_fe.py``
(``mpm_warp.validation.column_fe``, elements ``--dx`` wide, every layer resolved), once in plane strain and once
in plane stress. Per case: the slab's largest principal stress over its layer's tensile strength (Sigrist 2006,
or as given), away from the singular corners (``slab_fe.CORNER_M``), in each limit, and where it sits. Writes
``benchmarks/field/results/field_plane_stress.json``.

Usage: ``python benchmarks/field/plane_stress.py DIR [--dx 0.01] [--batches JSON ...]``; ``--quick``: the first 3
cases, to a temporary folder. Seconds a case.
"""

from __future__ import annotations

import os
import sys

from mpm_warp.field.studies.drawn import add_data_arguments
from mpm_warp.field.studies.slab_fe import fe_ratios
from mpm_warp.scenes.pst.static import static_column
from mpm_warp.studies.environment import environment
from mpm_warp.studies.field_static import static_study
from mpm_warp.studies.protocol import parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
PLANES = ("strain", "stress")


def main(argv=None) -> int:
    p = parser(__doc__, "the first 3 cases")
    add_data_arguments(p, RESULTS)
    p.add_argument("--dx", type=float, default=0.01, help="element width (m, default 0.01)")
    args = p.parse_args(argv)
    if not 0.002 <= args.dx <= 0.05:
        print(f"error: --dx = {args.dx:g} is invalid: expected 0.002-0.05 m", file=sys.stderr)
        return 2
    return static_study(args, "field_plane_stress", RESULTS, lambda b, case: _row(b, case, args.dx),
                        {"dx": args.dx, "planes": list(PLANES)}, environment("cpu"))


def _row(b: dict, case, dx: float) -> dict:
    """The FE of one scored case at its recorded cut in both plane limits."""
    col = static_column(case.params)
    strengths = [ly.strength for ly in case.params.slab_stack()]
    cut = float(case.params.saw.cut_length)
    fe = {plane: fe_ratios(col, strengths, cut, dx, plane) for plane in PLANES}
    print(f"{b['test']} ({b['observed']}): peak {fe['strain']['peak']:.3f} (strain), "
          f"{fe['stress']['peak']:.3f} (stress)", flush=True)
    return {"id": b["id"], "test": b["test"], "observed": b["observed"], "predicted": b["predicted"],
            "static_class": b.get("static_class"), "cut": cut, "length": col.length,
            "slab_depth": sum(ly[0] for ly in col.slab), "fe": fe}


if __name__ == "__main__":
    sys.exit(main())
