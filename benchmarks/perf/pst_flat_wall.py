"""How long does ``pst_flat`` take here, from its own command? With this machine's speed on the day beside it.

Runs the command the scenario file gives, ``mpm-warp run pst_flat --out <tmp>/pst_flat.h5 --json``, in a
subprocess after a short run of the same scene has compiled its kernels, and records its wall time, the
run summary (particles, steps, the stepping's own wall time and rate) and, before and after it, the rate of
the 2D elastic block of :mod:`pst_scaling` (82,944 particles, two threads, 200 steps): the speed of this
shared 2-core machine on the day, which moves between sessions by up to 2x, so that a later run
can be scaled to it. Writes ``benchmarks/perf/results/pst_flat_wall_cpu.json``.

Usage::

    python benchmarks/perf/pst_flat_wall.py [--quick]     # --quick: a 1 m column over 0.15 s
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import mpm_warp as mw
from mpm_warp.studies.blocks import block_simulation
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser, result_name
from mpm_warp.studies.timing import time_steps

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def block_rate(threads: int = 2, n_grid: int = 288) -> float:
    """Median particle-steps per wall second of the 2D elastic block (3 batches of 200 steps)."""
    sim = block_simulation(2, "elastic", n_grid, n_threads=threads)
    ts = sorted(time_steps(sim, 200, repeats=3))
    return sim.model.n_particles / ts[1]


def main(argv=None) -> int:
    ap = parser(__doc__, "a 1 m column over 0.15 s")
    a = ap.parse_args(argv)
    sets = ["--set", "scene.length=1.0", "--set", "time.end=0.15"] if a.quick else []
    exe = shutil.which("mpm-warp") or os.path.join(os.path.dirname(sys.executable), "mpm-warp")
    work = tempfile.mkdtemp(prefix="mpm_warp_pst_flat_")
    env = environment("cpu")
    try:
        mw.run("pst_flat", device="cpu", overrides=["time.end=0.001", "time.frame_interval=0.001"])  # compiles
        before = block_rate()
        cmd = [exe, "run", "pst_flat", "--out", os.path.join(work, "pst_flat.h5"), "--json", "--quiet", *sets]
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        after = block_rate()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if proc.returncode != 0:
        print(proc.stdout[-2000:], proc.stderr[-4000:], file=sys.stderr)
        return proc.returncode
    summary = json.loads([ln for ln in proc.stdout.splitlines() if ln.startswith("{")][-1])
    data = {"command": " ".join(["mpm-warp", *cmd[1:3], "--out", "pst_flat.h5", *cmd[5:]]), "wall_s": wall,
            "summary": summary, "block_rate_before": before, "block_rate_after": after,
            "threads": int(os.environ.get("MPM_WARP_THREADS") or os.cpu_count() or 1), "environment": env}
    name = result_name("pst_flat_wall", a)
    print(f"pst_flat: {wall / 60:.1f} min ({summary.get('n_particles')} particles, {summary.get('steps')} steps); "
          f"block {before / 1e6:.2f} / {after / 1e6:.2f} M particle-steps/s before / after")
    print("wrote", write_json(name, data, out_dir(a, RESULTS, "pst_flat_wall")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
