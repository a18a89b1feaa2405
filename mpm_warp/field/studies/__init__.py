"""The field studies' shared code: what ``benchmarks/field/`` scripts draw, set up again and compare.

- :mod:`.drawn`: cases drawn per observed class from committed batches, each set up again from its pit.
- :mod:`.slab_strength`, :mod:`.slab_fe`, :mod:`.slab_stress`: the slab's strength what-ifs, its static FE, and a
  run's slab stress frame by frame.
"""
