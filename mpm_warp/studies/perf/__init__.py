"""The performance benchmarks' shared code: the block timed in both engines (``benchmarks/perf/``).

- :mod:`.warp_block`: the mpm_warp side of the block protocol (warm up, snapshot, time, return kinds);
- :mod:`.throughput`: sizes to grids, one configuration's rows, a run over many (throughput, device suite);
- :mod:`.update_cost`: the Cam-Clay update and its parts alone on a step's trial states;
- :mod:`.taichi_peer`, :mod:`.taichi_mpm`, :mod:`.taichi_camclay`: the Taichi side. Taichi is the optional
  ``bench`` extra, imported only inside :func:`.taichi_peer.run_taichi_block`, in a child interpreter.
"""
