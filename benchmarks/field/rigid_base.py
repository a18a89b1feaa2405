"""What does a rigid base under the weak layer change in a field case? The same columns on their old snow.

Usage: ``python benchmarks/field/rigid_base.py DIR --runs RUNDIR [--per-class 8]`` (the draw's options: ``--help``);
``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case. Writes
``benchmarks/field/results/field_rigid_base.json`` in the what-if schema (``mpm_warp.field.studies.what_if``: the
batch's run before, the what-if's after).

The field protocol runs each column on a rigid base (``scene.rigid_base``), the column weac reads the
fracture energy back with; it once ran them on the profile's old snow (the substratum, docs/field.md). The what-if
``rigid_base`` runs the batch's columns again on their old snow, nothing else changed; its detail per case is the
substratum's compliance over the weak layer's (``sum d / M`` of its layers over ``D_wl / M_wl``, M the
constrained modulus), which is what a rigid base leaves out. The committed result ran the other way (earlier
batches on the old snow, again on the rigid base; its ``switch`` says so).
"""

if __name__ == "__main__":
    from mpm_warp.studies.field_what_if import what_if_main
    raise SystemExit(what_if_main(__doc__, __file__, ("rigid_base",), 8))
