"""What the benchmark scripts share: the pieces of a study, above the scenes and below the CLI.

``benchmarks/`` holds the scripts (one question each, ``benchmarks/README.md``); their shared logic
lives here so that it is tested and importable:

- :mod:`.environment`: the environment record of a result (device, versions, date, load, CPU) and
  writing a result's JSON;
- :mod:`.protocol`: the command line every script has (``--device``, ``--quick``, ``--out``);
- :mod:`.timing`: timers of kernels and steps (CPU time on the shared CPU, wall time on CUDA);
- :mod:`.blocks`: the elastic and struck Cam-Clay blocks of the throughput benchmarks;
- :mod:`.plastic_block`: the struck Cam-Clay block's physics and observables;
- :mod:`.perf`: the blocks timed in mpm_warp and in the Taichi peer, the update's cost;
- :mod:`.convergence`: observed orders, Richardson extrapolation, the run time to an error;
- :mod:`.snow`: the snow studies' ladder PST, its bisection grid, the merging of a level's parts,
  the field observations;
- :mod:`.fanout`: cases as Dask tasks (:func:`.fanout.dask_map`).
"""
