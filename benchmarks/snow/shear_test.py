"""The unconfined shear test of SI Note 2 at 4 and 8 cells across the weak layer.

Runs ``shear_test`` (the SI's case: the PST's weak layer with the SI's 2 mm softening slip, pushed
at 0.01 m/s for 0.8 s) at ``D_wl / dx`` = 4 and 8 and writes ``benchmarks/snow/results/snow_shear_test.json``
(peak, residual, softening slip on the layer's own slip and on the plate's displacement, collapse
beside the oedometric and the critical-state laws, the calibrated targets, and the 4-to-8 changes)
and ``snow_shear_test.png`` (shear stress and the layer's compaction against its slip, the bond).

Usage::

    .venv/bin/python benchmarks/snow/shear_test.py [--cells 4 8] [--quick]
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

import mpm_warp as mw
from mpm_warp.scenes.shear_test import shear_curves
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
SI_SLIP = 0.002       # m, critical sliding displacement of SI Note 2
SI_COLLAPSE = 0.20    # -, "almost 20 %" of SI Note 2


def run(cells: int, device: str) -> dict:
    sc = mw.load_scenario("shear_test")
    dx = sc.scene.weak_layer_thickness / cells
    t0 = time.perf_counter()
    rr = mw.run("shear_test", device=device, overrides=[f"scene.dx={dx!r}"])
    mon = rr.monitor
    c = shear_curves(mon.params, mon.times, {k: np.asarray(v) for k, v in mon.series.items()})
    return {"cells": cells, "dx": dx, "wall_s": time.perf_counter() - t0, "steps": rr.steps,
            "particles": rr.n_particles, "result": rr.scene_result,
            "curves": {k: np.asarray(c[k])[::5].tolist() for k in ("t", "u", "slip", "tau", "axial", "bond")}}


def figure(runs: list, path: str) -> None:
    plt = pyplot()

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    r0 = runs[0]["result"]
    for k, r in enumerate(runs):
        c = r["curves"]
        slip = 1e3 * np.asarray(c["slip"])
        lab = f"{r['cells']} cells (dx {1e3 * r['dx']:.3g} mm)"
        ax[0].plot(slip, c["tau"], "-", color=f"C{k}", label=lab)
        ax[1].plot(slip, c["axial"], "-", color=f"C{k}", label=lab)
        ax[2].plot(slip, c["bond"], "-", color=f"C{k}", label=lab)
    tau_p = r0["tau_p_calibrated"]
    ax[0].axhline(tau_p, color="k", ls="--", lw=1, label=f"given tau_p {tau_p:.0f} Pa")
    ax[0].set(xlabel="layer slip [mm] (top row against bottom row)", ylabel="push / area [Pa]",
              title="shear stress")
    ax[1].axhline(r0["collapse_fraction_law"], color="k", ls="--", lw=1, label="oedometric law (h_c / D_wl)")
    ax[1].axhline(SI_COLLAPSE, color="0.5", ls=":", lw=1, label="SI Note 2: ~20 %")
    ax[1].set(xlabel="layer slip [mm]", ylabel="compaction of the layer [-]", title="collapse")
    ax[2].axvline(1e3 * SI_SLIP, color="0.5", ls=":", lw=1, label="SI: ~2 mm")
    ax[2].set(xlabel="layer slip [mm]", ylabel="mean bond [-]", title="bond")
    for a in ax:
        a.legend(fontsize=7)
    fig.suptitle("unconfined shear test (SI Note 2): the weak layer under the slab's load, pushed at 0.01 m/s",
                 fontsize=9)
    save_figure(fig, path)


def main(argv=None) -> int:
    ap = parser(__doc__, "3 cells across the layer only")
    ap.add_argument("--cells", type=int, nargs="+", default=[4, 8], help="cells across the weak layer")
    a = ap.parse_args(argv)
    if a.quick:
        a.cells = [3]
    runs = [run(n, a.device) for n in a.cells]
    data = {"runs": runs, "si_softening_slip": SI_SLIP, "si_collapse": SI_COLLAPSE,
            "environment": environment(a.device)}
    if len(runs) > 1:
        lo, hi = runs[0]["result"], runs[-1]["result"]
        key = f"change_{a.cells[0]}_to_{a.cells[-1]}_cells"
        data[key] = {k: hi[k] / lo[k] - 1.0 for k in ("peak_shear_stress", "softening_displacement")}
    name = "snow_shear_test" + ("_quick" if a.quick else "")
    folder = out_dir(a, RESULTS, "shear_test")
    print("wrote", write_json(name, data, folder))
    figure(runs, os.path.join(folder, name + ".png"))
    for r in runs:
        x = r["result"]
        print(f"{r['cells']} cells: peak {x['peak_shear_stress']:.4g} Pa (given {x['tau_p_calibrated']:.4g}), "
              f"residual {x['residual_shear_stress']:.4g} Pa, softening {1e3 * x['softening_displacement']:.3g} mm "
              f"(plate {1e3 * x['plate_softening_displacement']:.3g} mm), collapse {x['collapse_fraction']:.3f} "
              f"(oedometric {x['collapse_fraction_law']:.3f}, critical state "
              f"{x['collapse_fraction_critical_state']:.3f}), {r['wall_s']:.0f} s")
    for key in (k for k in data if k.startswith("change_")):
        print(key, {k: f"{v:+.2%}" for k, v in data[key].items()})
    return 0


if __name__ == "__main__":
    sys.exit(main())
