"""Does a field case's outcome hold on a finer grid? The same columns at 6 cells across the weak layer instead of 4.

Usage: ``python benchmarks/field/resolution.py DIR --runs RUNDIR [--cells 6] [--per-class 4]`` (the draw's options:
``--help``); ``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case. Writes
``benchmarks/field/results/field_resolution.json`` in the what-if schema (``mpm_warp.field.studies.what_if``: the
batch's run before, the what-if's after).

The field protocol resolves each weak layer with 4 grid cells (``FieldProtocol.cells_across``), where the snow
ladder's PST is still far from converged (its error at 4 cells: ``error_vs_runtime_snow.py --field-level``). What
the batch scores is the class, so the what-if ``cells_across`` asks whether the class, and where the crack ran
away, change when the same columns run finer (``--cells``; the finer run costs about (6/4)^3 = 3.4 times as much;
the slab's crack band follows the grid: one particle spacing, docs/model.md §9).
"""

if __name__ == "__main__":
    from mpm_warp.studies.field_what_if import what_if_main
    raise SystemExit(what_if_main(__doc__, __file__, ("cells_across",), 4))
