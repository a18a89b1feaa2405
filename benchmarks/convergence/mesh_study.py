"""Mesh study of the weak-layer collapse (Gaume et al. 2018, Supplementary Note 3).

A weak layer (``D_wl`` = 3.125 cm, Cam-Clay, E 0.2 MPa, nu 0.3, rho 150,
M 1, beta 0.3, p0_ini 0) under an elastic slab in a laterally confined column,
gravity ramped (:func:`mpm_warp.validation.weak_layer_column`: set-up,
closed form and measurements; tests in ``tests/test_weak_layer.py``). For
every grid spacing ``dx``, hardening factor ``xi`` and slab density (which
sets the load and so ``p0``, as the paper did) the settled
column gives the mean collapse ``1 - J_P`` of the layer and the collapse height
``h_c = (1 - J_P) D_wl``; they are compared with the closed form of the
hardening rule under uniaxial strain,

    1 - J_P = 1 - exp(-asinh(p0 / K) / xi),  p0 = J_E J_P W / lambda_oed,

``W`` the slab weight per area (Cauchy), ``lambda_oed`` = 1.0848 for M 1, beta 0.3.

Outputs ``benchmarks/convergence/results/mesh_study.json`` (every run, the spread of
``1 - J_P`` across ``dx`` per case, device, versions) and
``benchmarks/convergence/results/mesh_study.png`` (collapse against the load with the
theoretical curves; error against the number of cells across the layer).

Precision: float64 by default, because in float32 a settled layer creeps by
round-off at a rate per step (``test_settled_layer_does_not_creep``), which
would show up as a spurious dependence on ``dx`` (finer grids take more
steps); ``--float32-case`` repeats one case in float32 at every ``dx``.
Explicit hardening converges at first order in the number of plastic
increments; the coarsest run takes ~1e3 steps while loading (error ~1e-3),
the finer ones more.

Result (CPU, one core, float64; 45 runs + 5 float32 in 310 s): the whole-layer
1 - J_P depends on dx through the cell the layer shares with the slab (it
under-compacts there): error against the closed form -18..-27 % at 2 cells
across the layer, -5..-13 % at 4, -1.3..-5.7 % at 8, -0.3..-2.1 % at 16,
-0.05..-0.5 % at 32 (observed order 1.1-2.5); the spread of 1 - J_P across
dx is up to 29 % over 2-32 cells, 5.8 % over 8-32 and 2.1 % over 16-32. The
layer interior converges to the closed form (|error| <= 0.2 % at 32 cells).
float32 at 32 cells: +0.9 % (round-off creep, 3e4 steps) against -0.2 %.

Run: ``python benchmarks/convergence/mesh_study.py`` (~5 min on one CPU core);
``--quick`` for a two-resolution smoke run (to a temporary folder); ``--plot-only``
recomputes the summary and redraws from the JSON.
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np

import mpm_warp as mw
from mpm_warp.camclay_forms import oedometric_ratio
from mpm_warp.finite_json import dump_finite, load_json
from mpm_warp.materials import hardening_collapse
from mpm_warp.studies.convergence import observed_order
from mpm_warp.studies.environment import check_provenance, environment
from mpm_warp.studies.figures import pyplot, save_figure
from mpm_warp.studies.protocol import out_dir, parser
from mpm_warp.validation import G, oedometric_collapse, run_column, weak_layer_column

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
DEFAULT_CELLS = (2, 4, 8, 16, 32)  # cells across the weak layer: dx = D_wl / cells
DEFAULT_XI = (0.02, 0.04, 0.08)
DEFAULT_RHO_SLAB = (600.0, 1200.0, 2400.0)  # slab 6.25 cm thick: W = 368, 736, 1472 Pa
D_WL = 1.0 / 32.0


def run_case(cells: int, xi: float, rho_slab: float, precision: str, device: str = "cpu") -> dict:
    """One settled column; returns the JSON record (no per-particle arrays)."""
    dx = D_WL / cells
    t0 = time.perf_counter()
    m, sim, info = run_column(dx=dx, xi=xi, rho_slab=rho_slab, precision=precision, D_wl=D_WL, device=device)
    total = time.perf_counter() - t0
    m.pop("per_particle")
    rec = {"cells": cells, "dx": dx, "xi": xi, "rho_slab": rho_slab, "precision": precision, **m,
           "error": m["collapse"] / m["collapse_theory"] - 1.0,
           "error_interior": (m["collapse_interior"] / m["collapse_theory_interior"] - 1.0
                              if math.isfinite(m["collapse_interior"]) else float("nan")),
           "h_c_theory": m["collapse_theory"] * D_WL,
           "steps": info["steps"], "n_particles": info["n_particles"], "t_end": info["t_settled"],
           "wall_time_stepping": info["wall_time"], "wall_time_total": total,
           "damping": info["damping"], "omega_end": info["omega_end"]}
    return rec


def summarise(runs: list[dict]) -> list[dict]:
    """Per (xi, rho_slab, precision): spread of 1 - J_P across dx, all dx and dx with >= 8 cells."""
    out = []
    keys = sorted({(r["xi"], r["rho_slab"], r["precision"]) for r in runs})
    for xi, rho, prec in keys:
        rs = sorted((r for r in runs if (r["xi"], r["rho_slab"], r["precision"]) == (xi, rho, prec)),
                    key=lambda r: r["cells"])
        c = np.array([r["collapse"] for r in rs])

        def spread(min_cells, rs=rs):
            v = np.array([r["collapse"] for r in rs if r["cells"] >= min_cells])
            return float((v.max() - v.min()) / v.mean()) if len(v) > 1 else None

        fit = [(r["dx"], abs(r["error"])) for r in rs if r["cells"] >= 4 and r["error"] != 0.0]
        order = observed_order(*zip(*fit, strict=True)) if len(fit) > 1 else None
        out.append({
            "xi": xi, "rho_slab": rho, "precision": prec, "W_mean": rs[0]["W_mean"],
            "collapse_theory": rs[0]["collapse_theory"],
            "cells": [r["cells"] for r in rs], "collapse": c.tolist(), "error": [r["error"] for r in rs],
            "spread_all": float((c.max() - c.min()) / c.mean()),
            "spread_8_cells_up": spread(8),
            "spread_16_cells_up": spread(16),
            "observed_order_4_cells_up": order,
        })
    return out


def plot(data: dict, path: str) -> None:
    """Collapse against the load with the closed form; error against cells across the layer."""
    plt = pyplot()

    runs = [r for r in data["runs"] if r["precision"] == data["precision"]]
    xis = sorted({r["xi"] for r in runs})
    cells = sorted({r["cells"] for r in runs})
    colors = dict(zip(xis, plt.cm.viridis(np.linspace(0.0, 0.8, len(xis))), strict=True))
    markers = dict(zip(cells, "v^osDP*X"[:len(cells)], strict=True))
    mat = data["weak_layer"]
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5))
    Wmax = max(r["W_mean"] for r in runs) * 1.15
    W = np.linspace(1.0, Wmax, 300)
    for xi in xis:
        m = mw.CamClaySnow(mat["E"], mat["nu"], mat["density"], M=mat["M"], beta=mat["beta"], xi=xi,
                           p0_ini=mat["p0_ini"])
        ax.plot(W, oedometric_collapse(W, m), color=colors[xi], lw=1.5,
                label=f"model, xi = {xi:g}" if xi == xis[0] else f"xi = {xi:g}")
        ax.plot(W, hardening_collapse(W, m.bulk, xi, m.p0_ini), color=colors[xi], lw=0.8, ls=":")
        for r in (r for r in runs if r["xi"] == xi):
            ax.plot(r["W_mean"], r["collapse"], ls="none", marker=markers[r["cells"]], color=colors[xi], ms=6,
                    mfc="none")
    for c in cells:
        ax.plot([], [], ls="none", marker=markers[c], color="k", mfc="none", label=f"dx = D_wl/{c}")
    ax.plot([], [], color="k", lw=0.8, ls=":", label="isotropic formula with p = W (not this loading)")
    ax.set_xlabel("slab load W = rho_s g h + weak-layer weight above (Pa)")
    ax.set_ylabel("1 - J_P (mean over the weak layer)")
    D_mm = 1e3 * data["set_up"]["D_wl"]
    axh = ax.secondary_yaxis("right", functions=(lambda c: c * D_mm, lambda h: h / D_mm))
    axh.set_ylabel(f"h_c = (1 - J_P) D_wl (mm), D_wl = {D_mm:g} mm")
    ax.set_title("collapse vs load: uniaxial-strain closed form (solid)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    for s in data["summary"]:
        if s["precision"] != data["precision"]:
            continue
        rs = sorted((r for r in runs if r["xi"] == s["xi"] and r["rho_slab"] == s["rho_slab"]),
                    key=lambda r: r["cells"])
        cc = [r["cells"] for r in rs]
        ax2.plot(cc, [100 * r["error"] for r in rs], color=colors[s["xi"]], marker="o", ms=4, lw=1,
                 alpha=0.5 + 0.5 * s["rho_slab"] / 2400.0)
        ci = [(r["cells"], 100 * r["error_interior"]) for r in rs if math.isfinite(r["error_interior"])]
        if ci:
            ax2.plot(*zip(*ci, strict=True), color=colors[s["xi"]], ls="--", lw=0.8)
    f32 = [r for r in data["runs"] if r["precision"] != data["precision"]]
    if f32:
        f32.sort(key=lambda r: r["cells"])
        ax2.plot([r["cells"] for r in f32], [100 * r["error"] for r in f32], color="r", marker="x", lw=1,
                 label=f"float32, xi {f32[0]['xi']:g}, rho_s {f32[0]['rho_slab']:g}")
    ax2.plot([], [], color="k", marker="o", ms=4, lw=1, label=f"whole layer ({data['precision']})")
    ax2.plot([], [], color="k", ls="--", lw=0.8, label="interior (> 1 cell from floor and slab)")
    summ = [s for s in data["summary"] if s["precision"] == data["precision"]]
    txt = ("max spread of 1 - J_P across dx, (max - min)/mean:\n"
           f"  all dx {100 * max(s['spread_all'] for s in summ):.0f} %, "
           f">= 8 cells {100 * max(s['spread_8_cells_up'] or 0 for s in summ):.1f} %, "
           f">= 16 cells {100 * max(s['spread_16_cells_up'] or 0 for s in summ):.1f} %")
    ax2.text(0.98, 0.04, txt, transform=ax2.transAxes, ha="right", va="bottom", fontsize=7,
             bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "0.7"})
    ax2.axhline(0.0, color="k", lw=0.5)
    ax2.set_xscale("log", base=2)
    ax2.set_xticks(cells, [str(c) for c in cells])
    ax2.set_xlabel("cells across the weak layer (D_wl / dx)")
    ax2.set_ylabel("1 - J_P error against the closed form (%)")
    ax2.set_title("dx dependence")
    ax2.legend(fontsize=7)
    ax2.grid(alpha=0.3)
    fig.suptitle("Weak-layer collapse under a slab (SI Note 3): mesh, xi and p0 (slab density)", fontsize=11)
    save_figure(fig, path)


def main(argv=None) -> int:
    ap = parser(__doc__, "4 and 8 cells, one xi, one slab density")
    ap.add_argument("--cells", type=int, nargs="+", default=list(DEFAULT_CELLS))
    ap.add_argument("--xi", type=float, nargs="+", default=list(DEFAULT_XI))
    ap.add_argument("--rho-slab", type=float, nargs="+", default=list(DEFAULT_RHO_SLAB))
    ap.add_argument("--precision", default="float64", choices=("float32", "float64"))
    ap.add_argument("--float32-case", type=float, nargs=2, default=(0.04, 1200.0), metavar=("XI", "RHO_SLAB"),
                    help="repeat this case in float32 at every dx (xi, slab density); 0 0 to skip")
    ap.add_argument("--plot-only", action="store_true",
                    help="recompute the summary and redraw the figure from the JSON in --out (or the results)")
    a = ap.parse_args(argv)
    name = "mesh_study" + ("_quick" if a.quick else "")
    folder = (a.out or RESULTS) if a.plot_only else out_dir(a, RESULTS, "mesh_study")
    path, png = os.path.join(folder, name + ".json"), os.path.join(folder, name + ".png")
    if a.plot_only:
        with open(path) as fh:
            data = load_json(fh)
        data["summary"] = summarise(data["runs"])
        _write(path, data)
        plot(data, png)
        report(data)
        return 0
    if a.quick:
        a.cells, a.xi, a.rho_slab = [4, 8], [0.04], [1200.0]
    sc, wl, info = weak_layer_column(dx=D_WL / 8, xi=a.xi[0], rho_slab=a.rho_slab[0], D_wl=D_WL)
    data = {
        "benchmark": "mesh_study", "source": "Gaume et al. 2018 SI Note 3; mpm_warp.validation.weak_layer_column",
        "device": a.device, "precision": a.precision, "environment": environment(a.device),
        "threads": 1,
        "set_up": {"D_wl": D_WL, "h_slab": info["h_slab"], "rho_wl": info["rho_wl"],
                   "slab": {**sc.materials["slab"].to_dict(), "density": "per run (rho_slab)"}, "gravity": G,
                   "ramp": info["ramp"],
                   "floor": "sticky", "side_walls": "slip, one cell apart (uniaxial strain)",
                   "particles_per_cell": 2, "cfl": sc.time.cfl},
        "weak_layer": {k: v for k, v in wl.to_dict().items() if k not in ("xi", "model")},
        "lambda_oed": oedometric_ratio(wl.M, wl.beta),
        "closed_form": "1 - J_P = 1 - exp(-(asinh(p0/K) - asinh(p0_ini/K))/xi), p0 = J_E J_P W / lambda_oed",
        "runs": [],
    }
    jobs = [(c, xi, rho, a.precision) for xi in a.xi for rho in a.rho_slab for c in a.cells]
    if a.float32_case[0] > 0 and a.precision != "float32" and not a.quick:
        jobs += [(c, a.float32_case[0], a.float32_case[1], "float32") for c in a.cells]
    t_all = time.perf_counter()
    for k, (c, xi, rho, prec) in enumerate(jobs):
        rec = run_case(c, xi, rho, prec, a.device)
        data["runs"].append(rec)
        data["summary"] = summarise(data["runs"])
        data["wall_time_study"] = time.perf_counter() - t_all
        _write(path, data)
        print(f"[{k + 1}/{len(jobs)}] cells {c:3d} xi {xi:g} rho_s {rho:g} {prec}: 1-J_P {rec['collapse']:.5f} "
              f"theory {rec['collapse_theory']:.5f} err {100 * rec['error']:+.2f} % (interior "
              f"{100 * rec['error_interior']:+.2f} %), h_c {1e3 * rec['h_c']:.3f} mm, {rec['steps']} steps, "
              f"{rec['wall_time_total']:.1f} s", flush=True)
    plot(data, png)
    report(data)
    print("wrote", path, flush=True)
    return 0


def _write(path: str, data: dict) -> None:
    """The JSON through a temporary file (a kill leaves the previous one); a dirty result is refused in results."""
    check_provenance(os.path.dirname(path) or ".", data)
    with open(path + ".tmp", "w") as fh:
        dump_finite(data, fh, indent=1)
    os.replace(path + ".tmp", path)


def report(data: dict) -> None:
    """Print the per-case spread of 1 - J_P across dx and the observed order of the error."""
    print("spread of 1 - J_P across dx, (max - min)/mean; observed order of |error| (>= 4 cells):")
    for s in data["summary"]:
        print(f"  xi {s['xi']:g} rho_s {s['rho_slab']:g} {s['precision']}: all {100 * s['spread_all']:.1f} %, "
              f">= 8 cells {100 * (s['spread_8_cells_up'] or 0):.2f} %, >= 16 cells "
              f"{100 * (s['spread_16_cells_up'] or 0):.2f} %, order {s['observed_order_4_cells_up'] or 0:.2f}")


if __name__ == "__main__":
    sys.exit(main())
