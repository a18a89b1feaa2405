"""Cost and accuracy of the 3D principal decomposition: the converged Jacobi of ``kernels/principal.py``
against ``wp.eig3`` (four float32 / eight float64 sweeps of approximate rotations), per matrix.

Usage: ``python benchmarks/perf/eig3_cost.py [--device cpu|cuda] [--n 200000] [--quick]``. Writes
``benchmarks/perf/results/eig3_cost_<device>.json``. The matrices are ``X = F F^T - I`` of the general path:
random rotations of principal values in [-0.9, 2], a quarter with two clustered eigenvalues (relative gaps
1e-8 to 0.1) and a quarter scaled by 1e-8 to 1. One launch decomposes all of them; the two kernels are
timed alternately, five times each after a compiling launch, and the medians compared (process CPU time on
the CPU, wall time on CUDA). Accuracy: the largest off-diagonal of ``Q^T X Q`` over ``|X|_F`` and the
largest entry of ``Q^T Q - I``, in rounding units of the precision, against float64 NumPy products.
"""

import functools
import os
import statistics
import time

import numpy as np
import warp as wp

from mpm_warp.kernels.principal import jacobi_eig3_func
from mpm_warp.kernels.types import mat, vec
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")

TYPES = {"float32": (wp.float32, np.float32, 2.0**-24), "float64": (wp.float64, np.float64, 2.0**-53)}


@functools.cache
def _kernels(T):
    M3, V3 = mat(3, T), vec(3, T)
    jacobi = jacobi_eig3_func(T)

    @wp.kernel(enable_backward=False, module="unique")
    def with_jacobi(X: wp.array(dtype=M3), Q: wp.array(dtype=M3), lam: wp.array(dtype=V3)):
        i = wp.tid()
        q, e = jacobi(X[i])
        Q[i] = q
        lam[i] = e

    @wp.kernel(enable_backward=False, module="unique")
    def with_eig3(X: wp.array(dtype=M3), Q: wp.array(dtype=M3), lam: wp.array(dtype=V3)):
        i = wp.tid()
        q = M3()
        e = V3()
        wp.eig3(X[i], q, e)
        Q[i] = q
        lam[i] = e

    return {"jacobi": with_jacobi, "eig3": with_eig3}


def matrices(n: int, seed: int = 0) -> np.ndarray:
    """The test matrices (module docstring), float64, shape (n, 3, 3)."""
    rng = np.random.default_rng(seed)
    lam = rng.uniform(-0.9, 2.0, (n, 3))
    k = np.arange(n) % 4
    lam[k == 1, 1] = lam[k == 1, 0] * (1 + 10.0 ** rng.uniform(-8, -1, (k == 1).sum()))
    lam[k == 2] *= 10.0 ** rng.uniform(-8, 0, ((k == 2).sum(), 1))
    q, r = np.linalg.qr(rng.normal(size=(n, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    return np.einsum("nij,nj,nkj->nik", q, lam, q)


def main(argv=None) -> int:
    ap = parser(__doc__, "2e4 matrices")
    ap.add_argument("--n", type=int, default=200_000)
    a = ap.parse_args(argv)
    if a.quick:
        a.n = 20_000
    dev = wp.get_device(a.device)
    clock = time.perf_counter if dev.is_cuda else time.process_time
    X = matrices(a.n)
    rows = []
    for precision, (T, nt, u) in TYPES.items():
        Xa = wp.array(X.astype(nt), dtype=mat(3, T), device=dev)
        Xn = X.astype(nt).astype(np.float64)
        nrm = np.linalg.norm(Xn, axis=(1, 2))
        row = {"precision": precision, "n": a.n}
        times = {name: [] for name in _kernels(T)}
        outs = {name: (wp.zeros(a.n, dtype=mat(3, T), device=dev), wp.zeros(a.n, dtype=vec(3, T), device=dev))
                for name in times}
        for rep in range(6):
            for name, kernel in _kernels(T).items():
                wp.synchronize_device(dev)
                t0 = clock()
                wp.launch(kernel, a.n, inputs=[Xa, *outs[name]], device=dev)
                wp.synchronize_device(dev)
                if rep:  # the first launch compiles
                    times[name].append(clock() - t0)
        for name, (Q, _) in outs.items():
            Qn = Q.numpy().astype(np.float64)
            A = np.einsum("nji,njk,nkl->nil", Qn, Xn, Qn)
            off = np.sqrt(2 * (A[:, 0, 1] ** 2 + A[:, 0, 2] ** 2 + A[:, 1, 2] ** 2)) / np.where(nrm > 0, nrm, 1.0)
            orth = np.abs(np.einsum("nji,njk->nik", Qn, Qn) - np.eye(3)).max(axis=(1, 2))
            row[name] = {"ns_per_matrix": 1e9 * statistics.median(times[name]) / a.n, "times_s": times[name],
                         "max_offdiag_u": float(off.max() / u), "p99_offdiag_u": float(np.percentile(off, 99) / u),
                         "max_nonorthogonality_u": float(orth.max() / u)}
        row["jacobi_over_eig3_time"] = row["jacobi"]["ns_per_matrix"] / row["eig3"]["ns_per_matrix"]
        rows.append(row)
        print(f"{precision}: jacobi {row['jacobi']['ns_per_matrix']:.1f} ns, eig3 {row['eig3']['ns_per_matrix']:.1f} ns"
              f" per matrix (ratio {row['jacobi_over_eig3_time']:.2f}); off-diagonal max "
              f"{row['jacobi']['max_offdiag_u']:.3g} / {row['eig3']['max_offdiag_u']:.3g} u, non-orthogonality "
              f"{row['jacobi']['max_nonorthogonality_u']:.3g} / {row['eig3']['max_nonorthogonality_u']:.3g} u",
              flush=True)
    path = write_json(f"eig3_cost_{dev.alias.split(':')[0]}" + ("_quick" if a.quick else ""),
                      {"environment": environment(a.device), "rows": rows}, out_dir(a, RESULTS, "eig3_cost"))
    print("wrote", path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
