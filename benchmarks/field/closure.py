"""Do the field columns keep their outcome with the laminate closure at their layer interfaces?

Usage: ``python benchmarks/field/closure.py DIR --runs RUNDIR [--per-class 6]`` (the draw's options: ``--help``);
``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case. Writes
``benchmarks/field/results/field_closure.json`` in the what-if schema (``mpm_warp.field.studies.what_if``: the
batch's run before, the what-if's after).

At the field protocol's 4 cells across the weak layer the grid's bimaterial artefact is at its worst (the rows
next to the weak layer carry up to 85 % more or less than the overburden, docs/results/snow.md, "Stress at the weak
layer's interfaces"), and the slab-stress studies found the run's slab layers at the base 0.7 to 51 times the
static FE's stress (docs/results/field-slab.md, "A resolved slab"). The laminate closure (``scene.interface_closure``,
docs/model.md §5b) removes that artefact in the settled column: the what-if ``interface_closure``.
"""

if __name__ == "__main__":
    from mpm_warp.studies.field_what_if import what_if_main
    raise SystemExit(what_if_main(__doc__, __file__, ("interface_closure",), 6))
