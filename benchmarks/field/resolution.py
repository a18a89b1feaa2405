"""Does a field case's outcome hold on a finer grid? The same columns at 6 cells across the weak layer instead of 4.

The field protocol resolves each weak layer with 4 grid cells (``FieldProtocol.cells_across``), where the snow
ladder's PST is still far from converged (its error at 4 cells: ``error_vs_runtime_snow.py --field-level``). What
the batch scores is the class, so the what-if ``cells_across`` asks whether the class, and where the crack ran
away, change when the same columns run finer (``--cells``; the finer run costs about (6/4)^3 = 3.4 times as much;
the slab's crack band follows the grid: one particle spacing, docs/model.md §9).

It draws ``--per-class`` finished cases of each observed class at random (``--seed``; blind to the predicted
class) from the committed development-set batches (``--batches``) among those whose batch run took at most
``--max-wall`` seconds, sets each up again from its pit as the batch did (its id's digest of the parameters and the
protocol must match), sets its grid to ``--cells`` cells across its weak layer, and runs it by the field
protocol into ``--runs`` (a Dask batch: resumable).
Per case, in the what-if schema (``mpm_warp.field.studies.what_if``): the batch's run (``before``) and the
what-if's (``after``): status, class, runaway cut, where the slab broke, weac's static rule, the fracture energy,
and the cost. Writes ``benchmarks/field/results/field_resolution.json``.

Usage: ``python benchmarks/field/resolution.py DIR --runs RUNDIR [--cells 6] [--per-class 4] [--seed 0] [--max-wall 120]
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
SWITCHES = ("cells_across",)


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_what_if_arguments(p, SWITCHES, 4, RESULTS)
    return what_if_study(p.parse_args(argv), SWITCHES, "field_resolution", RESULTS, environment("cpu"))


if __name__ == "__main__":
    sys.exit(main())
