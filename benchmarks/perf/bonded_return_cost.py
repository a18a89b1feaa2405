"""Cost of the bonded Cam-Clay return against camclay's, per point, for elastic and yielding trials.

Usage: ``python benchmarks/perf/bonded_return_cost.py [--device cpu|cuda] [--n 1000000] [--precision float32]
[--quick]``.
Writes ``benchmarks/perf/results/bonded_return_cost_<device>.json``. One kernel launch
returns ``n`` independent principal Hencky strains (no decomposition: the returns alone,
``bonded_camclay_return_strain`` and ``camclay_return_strain``), with
the weak layer of the PST (E 1 MPa, nu 0.3, M 1.2, beta 0.3, xi 0.0041, p_bond
3058 Pa, kappa_s 0.025: ``mpm_warp.scenes.weak_layer.calibration.weak_layer_material(tau_p=1000,
w_f=0.3, ...)``) and camclay with the same intact ellipse (p0 = 3067 Pa).
Trial sets: ``elastic`` (inside), ``yield_small`` (outside by an MPM step's
strain, 1e-4, in a random direction: the crack tip), ``yield_bond_gone``
(the same with the bond gone), ``yield_far`` (strains up to 1e-2: collapse).
Each figure is the median of three launches after a warm-up launch (compiled).
"""

import functools
import os
import statistics
import time

import numpy as np
import warp as wp

from mpm_warp.kernels.bonded_camclay import bonded_camclay_return_strain_func
from mpm_warp.kernels.camclay import camclay_return_strain_func, initial_log_jp
from mpm_warp.kernels.types import vec3
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")

E, NU, M, BETA, XI, P_BOND, KAPPA_S = 1e6, 0.3, 1.2, 0.3, 0.0041261, 3058.3, 0.025374
MU, LAM = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))
K = LAM + 2 * MU / 3
P0_FLOOR = 1e-5 * K
P0_INTACT = P0_FLOOR + P_BOND


@functools.cache
def _kernels(T):
    v3 = vec3(T)
    bonded, camclay = bonded_camclay_return_strain_func(T), camclay_return_strain_func(T)

    @wp.kernel(enable_backward=False)
    def run_bonded(eps: wp.array(dtype=v3), kap: wp.array(dtype=T), eps_out: wp.array(dtype=v3),
                   ljp_out: wp.array(dtype=T), kap_out: wp.array(dtype=T)):
        i = wp.tid()
        s, lj, k, y = bonded(eps[i], T(0.0), kap[i], T(MU), T(LAM), T(M), T(BETA), T(XI), T(P0_FLOOR), T(P_BOND),
                             T(KAPPA_S))
        eps_out[i] = s
        ljp_out[i] = lj
        kap_out[i] = k

    @wp.kernel(enable_backward=False)
    def run_camclay(eps: wp.array(dtype=v3), ljp: T, eps_out: wp.array(dtype=v3), ljp_out: wp.array(dtype=T)):
        i = wp.tid()
        s, lj, y = camclay(eps[i], ljp, T(MU), T(LAM), T(M), T(BETA), T(XI), T(P0_FLOOR))
        eps_out[i] = s
        ljp_out[i] = lj

    return run_bonded, run_camclay


def trial_sets(n: int, seed: int = 0) -> dict:
    """Principal trial Hencky strains (n, 3) and kappa (n,) for each set (module docstring)."""
    rng = np.random.default_rng(seed)
    # the settled state under the slab: uniaxial strain at sigma_n = 1226 Pa
    e_settled = np.array([0.0, -1226.0 / (LAM + 2 * MU), 0.0])
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    on_surface = e_settled * (2.8 * P0_INTACT / 1226.0 * 0.37)  # about the oedometric strength: near the surface
    sets = {
        "elastic": (e_settled + 1e-4 * direction, np.zeros(n)),
        "yield_small": (on_surface + 1e-4 * direction, np.full(n, 0.3 * KAPPA_S)),
        "yield_bond_gone": (on_surface + 1e-4 * direction, np.full(n, 2.0 * KAPPA_S)),
        "yield_far": (on_surface + 1e-2 * direction * rng.uniform(0, 1, (n, 1)), np.full(n, 0.3 * KAPPA_S)),
    }
    return {k: (-np.sort(-e, axis=1), kap) for k, (e, kap) in sets.items()}


def _time(kernel, n, inputs, device) -> list[float]:
    """Seconds of three launches of ``kernel`` over ``n`` points, after a warm-up launch."""
    out = []
    for rep in range(4):
        t0 = time.perf_counter()
        wp.launch(kernel, n, inputs=inputs, device=device)
        wp.synchronize_device(device)
        if rep:
            out.append(time.perf_counter() - t0)
    return out


def main(argv=None) -> int:
    ap = parser(__doc__, "1e4 points per set")
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--precision", default="float32", choices=["float32", "float64"])
    a = ap.parse_args(argv)
    if a.quick:
        a.n = 10_000
    T, nt = (wp.float32, np.float32) if a.precision == "float32" else (wp.float64, np.float64)
    dev = wp.get_device(a.device)
    run_bonded, run_camclay = _kernels(T)
    rows = []
    for name, (eps, kap) in trial_sets(a.n).items():
        # camclay with the same ellipse: the intact one, or p0 at its floor once the bond is gone
        ljp_cam = 0.0 if name == "yield_bond_gone" else initial_log_jp(P0_INTACT, K, XI)
        s = wp.array(eps.astype(nt), dtype=vec3(T), device=dev)
        k = wp.array(kap.astype(nt), dtype=T, device=dev)
        so = wp.zeros_like(s)
        lo, ko = wp.zeros(a.n, dtype=T, device=dev), wp.zeros(a.n, dtype=T, device=dev)
        tb = _time(run_bonded, a.n, [s, k, so, lo, ko], dev)
        yielded = float(np.mean(np.any(so.numpy() != s.numpy(), axis=1)))
        tc = _time(run_camclay, a.n, [s, T(ljp_cam), so, lo], dev)
        yielded_c = float(np.mean(np.any(so.numpy() != s.numpy(), axis=1)))
        row = {"set": name, "n": a.n, "yielded_fraction_bonded": yielded, "yielded_fraction_camclay": yielded_c,
               "bonded_ns_per_point":
               1e9 * statistics.median(tb) / a.n, "camclay_ns_per_point": 1e9 * statistics.median(tc) / a.n,
               "bonded_times_s": tb, "camclay_times_s": tc}
        row["ratio"] = row["bonded_ns_per_point"] / row["camclay_ns_per_point"]
        rows.append(row)
        print(f"{name:16s} yielded {yielded:5.2f} / {yielded_c:5.2f}: bonded {row['bonded_ns_per_point']:8.1f} ns, "
              f"camclay {row['camclay_ns_per_point']:8.1f} ns per point, ratio {row['ratio']:5.2f}", flush=True)
    path = write_json(f"bonded_return_cost_{dev.alias.split(':')[0]}" + ("_quick" if a.quick else ""),
                      {"environment": environment(a.device), "precision": a.precision, "rows": rows},
                      out_dir(a, RESULTS, "bonded_return_cost"))
    print("wrote", path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
