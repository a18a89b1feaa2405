"""Post-processing: everything here only reads run files (:func:`mpm_warp.read_run`), never a simulation.

- :mod:`.fields`: derived particle fields, each defined once with its reference state (collapse, displacement,
  stresses, speed);
- :mod:`.fronts`: the crack front of a run file as x per frame and its speed fit (the scene's window);
- :mod:`.plots`: time-series figures with their data (``mpm-warp plot``);
- :mod:`.render`: off-screen particle images and films (``mpm-warp render``).
"""
