"""Where the plastic step's constitutive update spends its time, on the trial states of a real step.

mpm_warp compiles the update into P2G, so its parts cannot be read from a stage
timer. These kernels run the engine's own ``wp.func``s on the very inputs of a
step (the trial ``H_tr = H + L + L H``, ``L = dt C``, of every particle of a
snapshot and its ``log_Jp``), each loading its inputs and storing its outputs:

``update``
    the whole update (``constitutive.constitutive_update_func``): what P2G
    does per particle before its scatter; a yielding trial in the series range
    takes the return without a decomposition;
``principal_path_update``
    the same update built with ``decomposition_free=False``: every yielding
    trial takes the eigen-decomposition (the engine before the
    decomposition-free return), with the largest differences of its new state
    from the engine's (``engine_vs_principal_path``: rounding);
``series_check``
    the small-strain prefix that every particle runs (``log_strain`` series,
    p, q, yield check);
``principal``
    the principal strains of the general path (``principal_strain_func``: the
    eigen-decomposition of ``F F^T - I``), now taken only by trials beyond the
    series range (``series_range_fraction`` of the particles are inside it);
``return``
    ``camclay_return_strain`` alone on those principal strains.

The loads and stores make every figure slightly larger than the same work
inside the fused P2G. On the CPU the figures are process CPU time (one thread).

``plastic_step.py`` calls the same measurement (``mpm_warp.studies.perf.update_cost``) for every size it
times; on its own::

    python benchmarks/perf/return_cost.py [--dim 3] [--n-grid 32] [--repeats 5] [--quick]

measures the struck block (``mpm_warp.studies.plastic_block``) after its warm-up and writes
``benchmarks/perf/results/return_cost_<device>.json``.
"""

import os
import sys

from mpm_warp.studies import plastic_block as pb
from mpm_warp.studies.blocks import block_simulation
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.perf.update_cost import update_cost
from mpm_warp.studies.protocol import out_dir, parser, result_name

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def main(argv=None) -> int:
    ap = parser(__doc__, "the 3D block at 24 cells")
    ap.add_argument("--dim", type=int, default=3, choices=(2, 3))
    ap.add_argument("--n-grid", type=int, default=32, help="cells per axis of the unit box")
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args(argv)
    if a.quick:
        a.dim, a.n_grid = 3, 24
    sim = block_simulation(a.dim, "plastic", a.n_grid, a.device, n_threads=1)
    sim.stepper.set_frame_end(1e9)
    sim.stepper.steps(pb.warmup_steps(a.n_grid))     # the state the timed steps of plastic_step see
    cost = update_cost(sim, a.repeats)
    print({k: v for k, v in cost.items() if k.endswith("_s")}, flush=True)
    name = result_name("return_cost", a)
    data = {"benchmark": "the Cam-Clay update and its parts on the trial states of the struck block, per launch",
            "dim": a.dim, "n_grid": a.n_grid, "n_particles": sim.model.n_particles, "repeats": a.repeats,
            "clock": "process CPU time" if not a.device.startswith("cuda") else "wall time", "cost": cost,
            "environment": environment(a.device)}
    print("wrote", write_json(name, data, out_dir(a, RESULTS, "return_cost")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
