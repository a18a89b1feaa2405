"""What does a rigid base under the weak layer change in a field case? The same columns on their old snow.

The field protocol runs each column on a rigid base (``scene.rigid_base``), the column weac reads the
fracture energy back with; it once ran them on the profile's old snow (the substratum, docs/field.md). The what-if
``rigid_base`` runs the batch's columns again on their old snow, nothing else changed; its detail per case is the
substratum's compliance over the weak layer's (``sum d / M`` of its layers over ``D_wl / M_wl``, M the
constrained modulus), which is what a rigid base leaves out. The committed result ran the other way (earlier
batches on the old snow, again on the rigid base; its ``switch`` says so).

It draws ``--per-class`` finished cases of each observed class at random (``--seed``; blind to the predicted
class) from the committed development-set batches (``--batches``) among those whose batch run took at most
``--max-wall`` seconds, sets each up again from its pit as the batch did (its id's digest of the parameters and the
protocol must match), moves it onto its old snow, and runs it by the field protocol into ``--runs`` (a Dask
batch: resumable).
Per case, in the what-if schema (``mpm_warp.field.studies.what_if``): the batch's run (``before``) and the
what-if's (``after``): status, class, runaway cut, where the slab broke, weac's static rule, the fracture energy,
and the cost. Writes ``benchmarks/field/results/field_rigid_base.json``.

Usage: ``python benchmarks/field/rigid_base.py DIR --runs RUNDIR [--per-class 8] [--seed 0] [--max-wall 120]
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
SWITCHES = ("rigid_base",)


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_what_if_arguments(p, SWITCHES, 8, RESULTS)
    return what_if_study(p.parse_args(argv), SWITCHES, "field_rigid_base", RESULTS, environment("cpu"))


if __name__ == "__main__":
    sys.exit(main())
