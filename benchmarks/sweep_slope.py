"""Slope sweep on Dask: crack speed (or, until a PST scene ships, a proxy) against slope angle.

With ``scenarios/pst_demo.toml`` present (or ``--scenario`` naming a PST scene) the sweep varies
``scene.slope_angle`` and plots the PST crack speed (``RunResult.scene_result``: ``crack_speed`` if the
scene reports it, else ``speed``, m/s) through :func:`mpm_warp.run`.

Proxy (used while no PST scene exists, or with ``--proxy``): the elastic_block scene (E 1 MPa,
rho 250 kg/m^3, dx 2 cm, 2000 particles) set on the floor of a slope of angle theta, i.e. gravity
``g (sin theta, -cos theta, 0)``, with Coulomb friction mu = 0.3 on the floor (friction angle
16.7 deg). Below the friction angle the slab stays put; above it the released slab slides with
``a = g (sin theta - mu cos theta)``. The proxy result is the slab's downslope release speed
``slide_speed`` = mean particle ``v_x`` at t_end (m/s), beside the closed form ``a t_end`` and the
fitted acceleration (mean ``v_x`` against time over the frames after ``t_end / 4``): it tests
the sweep machinery and the frictional-wall contact together, not anticracks.

Writes ``benchmarks/results/sweep_slope.csv`` (the sweep summary), ``sweep_slope.png`` (result
against slope, with the closed form for the proxy) and ``sweep_slope.json`` (device, versions,
sweep time). Run files go to ``--runs`` (default: a folder in the temporary directory); running
again skips the finished runs.

    python benchmarks/sweep_slope.py [--slopes 0,5,...,40] [--workers N] [--scheduler ADDR]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import tempfile
import time

import numpy as np

import mpm_warp as mw
from mpm_warp.sweep import run_sweep, split_values

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
G = 9.81
MU = 0.3           # floor friction of elastic_block
T_END = 0.4        # s
PROXY_SET = ["time.end=0.4", "time.frame_interval=0.02", "blocks.0.lo=[0.05, 0.0, 0.0]",
             "blocks.0.hi=[0.25, 0.1, 0.1]", "output.fields=[\"x\", \"v\"]"]


def slope_gravity(theta_deg: float) -> list[float]:
    """Gravity (m/s^2) on a slope of ``theta_deg``: downslope is +x, the bed normal +y."""
    t = math.radians(theta_deg)
    return [round(G * math.sin(t), 12), round(-G * math.cos(t), 12), 0.0]


def proxy_runner(scenario, output, device):
    """Run the block and add its release speed and acceleration (m/s, m/s^2) to ``scene_result``."""
    res = mw.run(scenario, output, device, overwrite=True)      # a dead worker may have left its .part.h5
    data = mw.read_run(output)
    vx = np.array([data.frame(i)["v"][:, 0].mean() for i in range(data.n_frames)], dtype=float)
    late = data.times >= data.times[-1] / 4
    theta = math.degrees(math.atan2(scenario.time.gravity[0], -scenario.time.gravity[1]))
    a_exact = max(0.0, G * (math.sin(math.radians(theta)) - MU * math.cos(math.radians(theta))))
    res.scene_result.update(slide_speed=float(vx[-1]), slide_speed_exact=a_exact * float(data.times[-1]),
                     acceleration=float(np.polyfit(data.times[late], vx[late], 1)[0]), acceleration_exact=a_exact)
    return res


def figure(rows, x, y, exact, path, title):
    from matplotlib.figure import Figure

    ok = sorted((float(r[x]), float(r[y]), r) for r in rows if r["status"] == "ok" and r.get(y) is not None)
    fig = Figure(figsize=(6.4, 4.2), layout="constrained")
    ax = fig.add_subplot()
    ax.plot([p[0] for p in ok], [p[1] for p in ok], "o-", label=f"MPM ({y})")
    if exact:
        th = np.linspace(min(p[0] for p in ok), max(p[0] for p in ok), 200)
        ax.plot(th, G * np.clip(np.sin(np.radians(th)) - MU * np.cos(np.radians(th)), 0, None) * T_END, "k--",
                lw=1, label=r"$g(\sin\theta - \mu\cos\theta)^+\,t_{end}$")
        ax.axvline(math.degrees(math.atan(MU)), color="0.6", lw=0.8, ls=":", label=r"friction angle $\arctan\mu$")
    ax.set(xlabel="slope angle (deg)", ylabel=f"{y} (m/s)", title=title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    fig.savefig(path, dpi=120)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default="pst_demo", help="PST scene (used when it exists)")
    ap.add_argument("--proxy", action="store_true", help="the elastic-block proxy even if a PST scene exists")
    ap.add_argument("--slopes", default=None, help="slope angles (deg), comma-separated")
    ap.add_argument("--runs", default=os.path.join(tempfile.gettempdir(), "mpm_warp_sweep_slope"))
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--scheduler", default=None)
    ap.add_argument("--device", default=None)
    ap.add_argument("--set", action="append", default=[], help="extra override for every case")
    a = ap.parse_args(argv)
    pst = not a.proxy and os.path.exists(os.path.join(mw.scenarios_dir(), a.scenario + ".toml"))
    slopes = [float(s) for s in split_values(a.slopes or ("0,10,20,30,35" if pst else "0,5,10,15,20,25,30,35,40"))]
    if pst:
        scenario, cases, fixed, x, runner = a.scenario, [{"scene.slope_angle": s} for s in slopes], a.set, \
            "scene.slope_angle", None
    else:
        scenario, x, runner, fixed = "elastic_block", "scene.slope_deg", proxy_runner, PROXY_SET + a.set
        cases = [{"scene.slope_deg": s, "time.gravity": slope_gravity(s)} for s in slopes]
    os.makedirs(RESULTS, exist_ok=True)
    t0 = time.perf_counter()
    res = run_sweep(scenario, cases=cases, out_dir=os.path.join(a.runs, "pst" if pst else "proxy"),
                    overrides=fixed, scheduler=a.scheduler, n_workers=a.workers, device=a.device, runner=runner,
                    plot_x=x, summary_path=os.path.join(RESULTS, "sweep_slope.csv"),
                    figure_path=os.path.join(a.runs, "sweep_slope_generic.png"))
    wall = time.perf_counter() - t0
    y = ("crack_speed" if any("crack_speed" in r for r in res.rows) else "speed") if pst else "slide_speed"
    title = (f"PST crack speed against slope ({scenario})" if pst else
             "Proxy: release speed of an elastic slab on a frictional slope (mu = 0.3)")
    figure(res.rows, x, y, not pst, os.path.join(RESULTS, "sweep_slope.png"), title)
    meta = {"scenario": scenario, "mode": "pst" if pst else "proxy", "x": x, "y": y, "overrides": fixed,
            "slopes_deg": slopes, "runs": len(res.rows), "failed": len(res.failed), "skipped": res.skipped,
            "sweep_wall_s": wall, "devices": sorted({str(r.get("device")) for r in res.rows}),
            "workers": a.workers, "scheduler": a.scheduler or "LocalCluster", "versions": mw.result.versions()}
    with open(os.path.join(RESULTS, "sweep_slope.json"), "w") as fh:
        json.dump(meta, fh, indent=1)
    print(f"{'slope (deg)':>11} {y:>12}" + ("  exact (m/s)   a (m/s^2)  a exact" if not pst else "") + "  status")
    for r in res.rows:
        line = f"{r[x]:>11g} {r.get(y) if r.get(y) is not None else float('nan'):>12.4f}"
        if not pst and r["status"] == "ok":
            line += f"  {r['slide_speed_exact']:>11.4f}  {r['acceleration']:>10.4f}  {r['acceleration_exact']:>7.4f}"
        print(line + f"  {r['status']} {r.get('error') or ''}")
    print(f"summary {res.path}; figure {os.path.join(RESULTS, 'sweep_slope.png')}; {wall:.1f} s")
    return 1 if res.failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
