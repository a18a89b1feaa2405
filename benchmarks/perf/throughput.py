"""Throughput of the MLS-MPM step beside Taichi, by dimension, material, size and thread count.

Usage::

    python benchmarks/perf/throughput.py [--device cpu|cuda:0] [--dims 3 2] [--materials elastic plastic]
                                    [--particles 13824 32768 110592 262144] [--steps 50] [--threads 1 2]
    python benchmarks/perf/throughput.py --quick     # ~4k particles, 5 steps, one thread: a minute on a CPU

``--particles`` are approximate counts: each becomes the even ``n_grid`` with
``n_grid**dim`` closest to it (2 particles per cell and axis in a unit box).
The elastic block is ``mpm_warp.studies.blocks.block_scenario`` (E = 1e5 Pa, rho = 1000, dt =
1e-4 s, or dx / c_p on grids finer than 1.16 mm; free fall); the plastic block is the struck Cam-Clay snow of
``mpm_warp.studies.plastic_block``. Both engines follow the protocol of ``mpm_warp.studies.perf.warp_block`` /
``taichi_peer`` (compiled, warmed up, median of three repeats from one
snapshot; Taichi in its own process per configuration). On the CPU each row
also has ``cpu_utilisation`` and ``particle_steps_per_cpu_s`` (per second of
process CPU time): on a machine whose cores are shared with other work the
wall-clock rates move with that load, the CPU-time rates much less. 2D is plane strain
(``[domain] dimension = 2`` in mpm_warp). Writes ``benchmarks/perf/results/<name>.json`` (default
``throughput_<device>``) after every configuration, so a run stopped early
keeps what it measured, and ``<name>.png`` (particle-steps per second against particles).
"""

from __future__ import annotations

import os
import sys

from mpm_warp.finite_json import load_json
from mpm_warp.studies.environment import environment
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.perf.throughput import run
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
DEFAULT_PARTICLES = [13824, 32768, 110592, 262144]


def figure(out: dict, path: str) -> None:
    """Particle-steps per second against particles: one panel per dimension, a line per material and engine."""
    import matplotlib.ticker

    plt = pyplot()

    rows = [r for r in out["rows"] if "particle_steps_per_s" in r]
    dims = sorted({r["dim"] for r in rows}, reverse=True)
    if not dims:
        return
    fig, axes = plt.subplots(1, len(dims), figsize=(5.5 * len(dims), 5.2), squeeze=False)
    for ax, dim in zip(axes[0], dims, strict=True):
        keys = sorted({(r["material"], r["engine"], r["threads"]) for r in rows if r["dim"] == dim},
                      key=lambda k: (k[0], k[2] or 0, k[1] != "mpm_warp"))
        colours = {}                  # one colour per material and thread count: solid mpm_warp, dashed Taichi
        for material, engine, threads in keys:
            c = colours.setdefault((material, threads), f"C{len(colours)}")
            pts = sorted((r["n_particles"], r["particle_steps_per_s"]) for r in rows
                         if (r["dim"], r["material"], r["engine"], r["threads"]) == (dim, material, engine, threads))
            ax.loglog(*zip(*pts, strict=True), "o-" if engine == "mpm_warp" else "s--", color=c,
                      label=f"{engine} {material}" + (f", {threads} thread(s)" if threads else ""))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set(xlabel="particles", ylabel="particle-steps per second (wall clock, median)",
               title=f"{dim}D{' (plane strain)' if dim == 2 else ''}, {out['environment']['device']}")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.15))  # below: no point hidden
    save_figure(fig, path)


def main(argv=None) -> int:
    ap = parser(__doc__, "3D and 2D, elastic and plastic, ~4k particles, 5 steps, one repeat, one thread")
    ap.add_argument("--dims", type=int, nargs="+", default=[3, 2], choices=(2, 3))
    ap.add_argument("--materials", nargs="+", default=["elastic", "plastic"], choices=("elastic", "plastic"))
    ap.add_argument("--particles", type=float, nargs="+", default=DEFAULT_PARTICLES)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, nargs="+", default=None,
                    help="CPU thread counts (default 1 and all cores; CUDA: one launch stream)")
    ap.add_argument("--no-taichi", action="store_true")
    ap.add_argument("--name", default=None, help="result file name (default throughput_<cpu|cuda>)")
    ap.add_argument("--figure-only", action="store_true", help="redraw <name>.png from the JSON in --out (or results)")
    a = ap.parse_args(argv)
    if a.figure_only:
        folder = a.out or RESULTS
        name = a.name or f"throughput_{'cuda' if a.device.startswith('cuda') else 'cpu'}"
        with open(os.path.join(folder, name + ".json")) as fh:
            figure(load_json(fh), os.path.join(folder, name + ".png"))
        return 0
    if a.quick:
        a.particles, a.steps, a.repeats, a.threads = [4096.0], 5, 1, [1]
    cuda = a.device.startswith("cuda")
    threads = [1] if cuda else (a.threads or sorted({1, os.cpu_count() or 1}))
    name = a.name or f"throughput_{'cuda' if cuda else 'cpu'}" + ("_quick" if a.quick else "")
    folder = out_dir(a, RESULTS, "throughput")
    out = run(a.dims, a.materials, a.particles, a.steps, a.device, threads, not a.no_taichi, name, a.repeats,
              results_dir=folder, env=environment(a.device))
    figure(out, os.path.join(folder, name + ".png"))
    print("wrote", os.path.join(folder, name + ".json"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
