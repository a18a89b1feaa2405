"""Does a pre-cut change a field case's outcome? The same columns, sawn from the end or pre-cut another share.

The saw's way to the runaway is most of a field case's simulated time, so the field protocol starts each
column sawn half of weac's critical cut at its fracture energy (``pre_cut_share``, at most half the column). The
what-if ``pre_cut_share`` runs the batch's columns again with another share (``--share``; 0, the default: sawn
from the end); its detail per case is weac's critical cut and the pre-cut. The committed result ran the other way
(earlier batches without a pre-cut, again with one of 0.5; its ``switch`` says so).

It draws ``--per-class`` finished cases of each observed class at random (``--seed``; blind to the predicted
class) from the committed development-set batches (``--batches``) among those whose batch run took at most
``--max-wall`` seconds, sets each up again from its pit as the batch did (its id's digest of the parameters and the
protocol must match), sets its pre-cut to ``--share`` of weac's critical cut, and runs it by the field protocol
into ``--runs`` (a Dask batch: resumable).
Per case, in the what-if schema (``mpm_warp.field.studies.what_if``): the batch's run (``before``) and the
what-if's (``after``): status, class, runaway cut, where the slab broke, weac's static rule, the fracture energy,
and the cost. Writes ``benchmarks/field/results/field_pre_cut.json``.

Usage: ``python benchmarks/field/pre_cut.py DIR --runs RUNDIR [--share 0] [--per-class 8] [--seed 0] [--max-wall 120]
[--workers N] [--threads T]``; ``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case.
"""

from __future__ import annotations

import os
import sys

from mpm_warp.studies.environment import environment
from mpm_warp.studies.field_what_if import add_what_if_arguments, what_if_study
from mpm_warp.studies.protocol import parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
#: the what-ifs this script runs (the first without an option)
SWITCHES = ("pre_cut_share",)


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_what_if_arguments(p, SWITCHES, 8, RESULTS)
    return what_if_study(p.parse_args(argv), SWITCHES, "field_pre_cut", RESULTS, environment("cpu"))


if __name__ == "__main__":
    sys.exit(main())
