"""Would a weaker slab tell SF from END? The field columns run again with their slab's tensile strength scaled.

The model calls most of the development set's SF records END: their slab never cracked through
(docs/results/field.md, "Field outcomes against the observers"). The static FE's slab stress ranks an SF record
above an END record in most pairs (docs/results/field-slab.md, "A resolved slab"), so the SF slabs are the more
loaded ones, but at a fraction of their strength (Sigrist 2006 from the density, docs/model.md §9). If a slab
weaker by a factor broke mostly in the SF records and seldom in the END ones, an independently measured
field-scale strength would be worth taking; if it broke in both alike, the strength law cannot separate them. Two
what-ifs, one a run: ``slab_strength`` (every slab layer at ``--scale`` times its law's strength, the default) and
``faceted_strength`` (only faceted layers, FC and DH, at ``--faceted`` times it: in situ about 0.5, Jamieson and
Johnston 1990). The fracture energy stays the density law's; never a calibration: no default changes.

It draws ``--per-class`` finished cases of each observed class at random (``--seed``; blind to the predicted
class) from the committed development-set batches (``--batches``) among those whose batch run took at most
``--max-wall`` seconds, sets each up again from its pit as the batch did (its id's digest of the parameters and the
protocol must match), weakens its slab, and runs it by the field protocol into ``--runs`` (a Dask batch:
resumable).
Per case, in the what-if schema (``mpm_warp.field.studies.what_if``): the batch's run (``before``) and the
what-if's (``after``): status, class, runaway cut, where the slab broke, weac's static rule, the fracture energy,
and the cost. Writes ``field_strength.json`` under ``benchmarks/field/results/`` or ``--out``.

Usage: ``python benchmarks/field/strength.py DIR --runs RUNDIR [--scale 0.5 | --faceted 0.5] [--per-class 8] [--seed 0]
[--max-wall 120] [--workers N] [--threads T]``; ``--quick``: one case of at most 20 s, to a temporary folder.
Minutes a case.
"""

from __future__ import annotations

import os
import sys

from mpm_warp.studies.environment import environment
from mpm_warp.studies.field_what_if import add_what_if_arguments, what_if_study
from mpm_warp.studies.protocol import parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
#: the what-ifs this script runs (the first without an option)
SWITCHES = ("slab_strength", "faceted_strength")


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_what_if_arguments(p, SWITCHES, 8, RESULTS)
    return what_if_study(p.parse_args(argv), SWITCHES, "field_strength", RESULTS, environment("cpu"))


if __name__ == "__main__":
    sys.exit(main())
