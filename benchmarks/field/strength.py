"""Would a weaker slab tell SF from END? The field columns run again with their slab's tensile strength scaled.

Usage: ``python benchmarks/field/strength.py DIR --runs RUNDIR [--scale 0.5 | --faceted 0.5] [--per-class 8]`` (the
draw's options: ``--help``); ``--quick``: one case of at most 20 s, to a temporary folder. Minutes a case. Writes
``field_strength.json`` under ``benchmarks/field/results/`` or ``--out`` in the what-if schema
(``mpm_warp.field.studies.what_if``: the batch's run before, the what-if's after).

The model calls most of the development set's SF records END: their slab never cracked through
(docs/results/field.md, "Field outcomes against the observers"). The static FE's slab stress ranks an SF record
above an END record in most pairs (docs/results/field-slab.md, "A resolved slab"), so the SF slabs are the more
loaded ones, but at a fraction of their strength (Sigrist 2006 from the density, docs/model.md §9). If a slab
weaker by a factor broke mostly in the SF records and seldom in the END ones, an independently measured
field-scale strength would be worth taking; if it broke in both alike, the strength law cannot separate them. Two
what-ifs, one a run: ``slab_strength`` (every slab layer at ``--scale`` times its law's strength, the default) and
``faceted_strength`` (only faceted layers, FC and DH, at ``--faceted`` times it: in situ about 0.5, Jamieson and
Johnston 1990). The fracture energy stays the density law's; never a calibration: no default changes.
"""

if __name__ == "__main__":
    from mpm_warp.studies.field_what_if import what_if_main
    raise SystemExit(what_if_main(__doc__, __file__, ("slab_strength", "faceted_strength"), 8))
