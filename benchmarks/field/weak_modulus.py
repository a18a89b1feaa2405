"""Would a softer weak layer tell the outcomes apart? The field columns set up again with a softer weak layer.

Usage: ``python benchmarks/field/weak_modulus.py DIR --runs RUNDIR [--modulus 0.25] [--per-class 16]`` (the draw's
options: ``--help``); ``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case. Writes
``field_weak_modulus.json`` under ``benchmarks/field/results/`` or ``--out`` in the what-if schema
(``mpm_warp.field.studies.what_if``: the batch's run before, the what-if's after).

A pit records no stiffness: every field column's weak layer has the scene's Young's modulus, 1 MPa
(docs/profiles.md, "What the profile does not give"), the top of the 0.05-1 MPa that field weak layers span
(docs/model.md §6, "Field ranges"); weac's own default is 0.25 MPa. The weak layer's modulus sets how far the slab's
bending reaches beyond the cut, so the slab's stress at the crack tip, and, through weac's energy release rate at
the recorded cut, the fracture energy the run takes. The what-if ``weak_modulus`` sets each column up again with
the weak layer's modulus at ``--modulus`` (MPa), as the batch would set it up with that modulus: the fracture
energy read back again from the recorded cut and the weak layer calibrated again; a column the softer layer leaves
the model unable to take is said in one line. No default changes.
"""

if __name__ == "__main__":
    from mpm_warp.studies.field_what_if import what_if_main
    raise SystemExit(what_if_main(__doc__, __file__, ("weak_modulus",), 16))
