"""Why is the shear test's peak below tau_p? Its free ends, measured against the sample's length.

The shear test (``shear_test``: a 3 cm weak layer under the slab's load, pushed at 0.01 m/s) at 4 and 8
cells across the layer, on samples of 0.3, 0.6 and 1.2 m, closure off (the
default) and, at 4 cells on the 0.3 m sample, on. Each run records (:mod:`mpm_warp.studies.shear_rows`)
the structural peak (push force over the sample's area at its maximum, what a test reads), the interior's
own peak (the mean ``sigma_xy`` of the layer at least one layer thickness from both ends, at its maximum
over time), and at the structural peak the shear stress per particle row and along the sample. The peaks
against the length are fitted with ``a - b / L``: the ends' deficit is a fixed length of unloaded sample,
so ``a`` is the peak of an endless sample. Writes ``benchmarks/snow/results/shear_free_ends_<dev>.json``
and ``.png`` (the peak against 1/L with the fit; the stress along the sample at the peak).

Usage::

    python benchmarks/snow/shear_free_ends.py [--quick]
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser, result_name
from mpm_warp.studies.shear_rows import length_fit, shear_rows

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
LENGTHS = {4: (0.3, 0.6, 1.2), 8: (0.3, 0.6, 1.2)}
ON = "scene.interface_closure=true"


def figure(data: dict, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
    for cells, runs in data["runs"].items():
        L = np.array([r["sample_length"] for r in runs])
        ax.plot(1 / L, [r["peak_over_tau_p"] for r in runs], "o", label=f"{cells} cells: structural peak")
        ax.plot(1 / L, [r["interior_peak_over_tau_p"] for r in runs], "s", mfc="none",
                label=f"{cells} cells: interior's own peak")
        f = data["fit"][cells]
        xs = np.linspace(0, 1 / L.min(), 20)
        ax.plot(xs, f["a"] - f["b"] * xs, "--", lw=1, color=ax.lines[-2].get_color())
        for r in runs:
            if r["sample_length"] == max(L):
                xa = [p["x"] / r["sample_length"] for p in r["along"]]
                bx.plot(xa, [p["tau_over_tau_p"] for p in r["along"]], ".-",
                        label=f"{cells} cells, L = {r['sample_length']:g} m")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.axhspan(0.97, 1.03, color="0.9", zorder=0, label="within 3 % of tau_p")
    ax.set_xlim(left=0)
    ax.set_xlabel("1 / sample length (1/m)")
    ax.set_ylabel("peak shear stress / tau_p")
    ax.set_title("peak against sample length (fit a - b/L, dashed)", fontsize=10)
    ax.legend(fontsize=8, loc="lower left")
    bx.axhline(1.0, color="k", lw=0.8)
    bx.set_xlabel("position along the sample / its length")
    bx.set_ylabel("layer's mean sigma_xy / tau_p at the structural peak")
    bx.set_title("shear stress along the sample at the peak", fontsize=10)
    bx.legend(fontsize=8, loc="lower center")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = parser(__doc__, "4 cells on 0.15 and 0.3 m samples")
    a = ap.parse_args(argv)
    lengths = {4: (0.15, 0.3)} if a.quick else LENGTHS
    data = {"scenario": "shear_test", "runs": {}, "fit": {}, "environment": environment(a.device)}
    t0 = time.perf_counter()
    for cells, Ls in lengths.items():
        data["runs"][str(cells)] = [shear_rows(cells, L, device=a.device) for L in Ls]
        for r in data["runs"][str(cells)]:
            print(f"{cells} cells, L = {r['sample_length']:g} m: structural peak / tau_p {r['peak_over_tau_p']:.4f}, "
                  f"interior's {r['interior_peak_over_tau_p']:.4f} ({r['wall_s']:.0f} s)", flush=True)
    for cells, runs in data["runs"].items():
        data["fit"][cells] = length_fit([r["sample_length"] for r in runs], [r["peak_over_tau_p"] for r in runs])
        print(f"{cells} cells: endless sample's peak / tau_p = {data['fit'][cells]['a']:.4f}")
    if not a.quick:
        data["closure_on"] = shear_rows(4, 0.3, overrides=[ON], device=a.device)
    data["seconds"] = time.perf_counter() - t0
    folder = out_dir(a, RESULTS, "shear_free_ends")
    name = result_name("shear_free_ends", a)
    print("wrote", write_json(name, data, folder))
    figure(data, os.path.join(folder, name + ".png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
