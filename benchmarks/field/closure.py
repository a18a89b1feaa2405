"""Do the field columns keep their outcome with the laminate closure at their layer interfaces?

At the field protocol's 4 cells across the weak layer the grid's bimaterial artefact is at its worst (the rows
next to the weak layer carry up to 85 % more or less than the overburden, docs/results/snow.md, "Stress at the weak
layer's interfaces"), and the slab-stress studies found the run's slab layers at the base 0.7 to 51 times the
static FE's stress (docs/results/field-slab.md, "A resolved slab"). The laminate closure (``scene.interface_closure``,
docs/model.md §5b) removes that artefact in the settled column: the what-if ``interface_closure``.

It draws ``--per-class`` finished cases of each observed class at random (``--seed``; blind to the predicted
class) from the committed development-set batches (``--batches``) among those whose batch run took at most
``--max-wall`` seconds, sets each up again from its pit as the batch did (its id's digest of the parameters and the
protocol must match), switches the closure on, nothing else changed, and runs it by the field protocol into
``--runs`` (a Dask batch: resumable).
Per case, in the what-if schema (``mpm_warp.field.studies.what_if``): the batch's run (``before``) and the
what-if's (``after``): status, class, runaway cut, where the slab broke, weac's static rule, the fracture energy,
and the cost. Writes ``benchmarks/field/results/field_closure.json``.

Usage: ``python benchmarks/field/closure.py DIR --runs RUNDIR [--per-class 6] [--seed 0] [--max-wall 120]
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
SWITCHES = ("interface_closure",)


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_what_if_arguments(p, SWITCHES, 6, RESULTS)
    return what_if_study(p.parse_args(argv), SWITCHES, "field_closure", RESULTS, environment("cpu"))


if __name__ == "__main__":
    sys.exit(main())
