"""The field studies' shared code: what ``benchmarks/field/`` scripts draw, set up again, change and compare.

- :mod:`.drawn`: cases drawn per observed class from committed batches, each set up again from its pit.
- :mod:`.switches`: the what-ifs, one named protocol switch each, in one registry.
- :mod:`.what_if`: the driver that runs any switch on a drawn set, and the one before/after schema it writes.
- :mod:`.convert`: the earlier studies' own schemas converted to that one, every number kept.
- :mod:`.slab_strength`, :mod:`.slab_fe`, :mod:`.slab_stress`: the slab's strength what-ifs, its static FE, and a
  run's slab stress frame by frame.
- :mod:`.at_call`: what a finished run's slab had done at its call (its drop, the share of the crack it came down
  over, the stress its body carried), from the run file and the final checkpoint.
"""
