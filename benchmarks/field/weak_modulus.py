"""Would a softer weak layer tell the outcomes apart? The field columns set up again with a softer weak layer.

A pit records no stiffness: every field column's weak layer has the scene's Young's modulus, 1 MPa
(docs/profiles.md, "What the profile does not give"), the top of the 0.05-1 MPa that field weak layers span
(docs/model.md §6, "Field ranges"); weac's own default is 0.25 MPa. The weak layer's modulus sets how far the slab's
bending reaches beyond the cut, so the slab's stress at the crack tip, and, through weac's energy release rate at
the recorded cut, the fracture energy the run takes. The what-if ``weak_modulus`` sets each column up again with
the weak layer's modulus at ``--modulus`` (MPa), as the batch would set it up with that modulus: the fracture
energy read back again from the recorded cut and the weak layer calibrated again; a column the softer layer leaves
the model unable to take is said in one line. No default changes.

It draws ``--per-class`` finished cases of each observed class at random (``--seed``; blind to the predicted
class) from the committed development-set batches (``--batches``) among those whose batch run took at most
``--max-wall`` seconds, sets each up again from its pit as the batch did (its id's digest of the parameters and the
protocol must match), sets it up again with the softer weak layer, and runs it by the field protocol into
``--runs`` (a Dask batch: resumable).
Per case, in the what-if schema (``mpm_warp.field.studies.what_if``): the batch's run (``before``) and the
what-if's (``after``): status, class, runaway cut, where the slab broke, weac's static rule, the fracture energy,
and the cost. Writes ``field_weak_modulus.json`` under ``benchmarks/field/results/`` or ``--out``.

Usage: ``python benchmarks/field/weak_modulus.py DIR --runs RUNDIR [--modulus 0.25] [--per-class 16] [--seed 0]
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
SWITCHES = ("weak_modulus",)


def main(argv=None) -> int:
    p = parser(__doc__, "one case of at most 20 s")
    add_what_if_arguments(p, SWITCHES, 16, RESULTS)
    return what_if_study(p.parse_args(argv), SWITCHES, "field_weak_modulus", RESULTS, environment("cpu"))


if __name__ == "__main__":
    sys.exit(main())
