"""Does a pre-cut change a field case's outcome? The same columns, sawn from the end or pre-cut another share.

Usage: ``python benchmarks/field/pre_cut.py DIR --runs RUNDIR [--share 0] [--per-class 8]`` (the draw's options:
``--help``); ``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case. Writes
``benchmarks/field/results/field_pre_cut.json`` in the what-if schema (``mpm_warp.field.studies.what_if``: the
batch's run before, the what-if's after).

The saw's way to the runaway is most of a field case's simulated time, so the field protocol starts each
column sawn half of weac's critical cut at its fracture energy (``pre_cut_share``, at most half the column). The
what-if ``pre_cut_share`` runs the batch's columns again with another share (``--share``; 0, the default: sawn
from the end); its detail per case is weac's critical cut and the pre-cut. The committed result ran the other way
(earlier batches without a pre-cut, again with one of 0.5; its ``switch`` says so).
"""

if __name__ == "__main__":
    from mpm_warp.studies.field_what_if import what_if_main
    raise SystemExit(what_if_main(__doc__, __file__, ("pre_cut_share",), 8))
