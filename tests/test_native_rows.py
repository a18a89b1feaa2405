"""The native 2D transfer snippets (kernels/p2g_rows.py, kernels/g2p_rows.py): their CPU vector code against
their plain code (CUDA's, built for the CPU with ``portable``) and against the Warp form they replace; both CPU
snippets fuse multiply-adds, so they agree to rounding."""

import numpy as np
import pytest
import warp as wp

from mpm_warp.kernels.g2p_rows import gather_rows_func
from mpm_warp.kernels.p2g_rows import scatter_rows_func
from mpm_warp.kernels.shape import stencil_func
from mpm_warp.kernels.types import mat, vec

SHAPE = (7, 9)  # nodes; flat index i * 9 + j


@pytest.fixture(params=[wp.float32, wp.float64], ids=["float32", "float64"])
def T(request):
    return request.param


def _particles(T, n=64, seed=3):
    rng = np.random.default_rng(seed)
    npT = np.float32 if T == wp.float32 else np.float64
    x = rng.uniform(0.6, 4.9, (n, 2)).astype(npT)  # inside the 7 x 9 grid's safe interior at dx = 1
    v = rng.normal(size=(n, 2)).astype(npT)
    A = rng.normal(size=(n, 2, 2)).astype(npT)
    g = rng.normal(size=(SHAPE[0] * SHAPE[1], 2)).astype(npT)
    return x, v, A, g


def _scatter_kernel(T, mode):
    """``mode``: "vector" (the CPU snippet), "portable" (CUDA's code on the CPU) or "warp" (the Warp form)."""
    V, M = vec(2, T), mat(2, T)
    stencil = stencil_func(T, 2)
    rows = scatter_rows_func(T, portable=(mode == "portable")) if mode != "warp" else None

    @wp.kernel(enable_backward=False, module="unique")
    def k(x: wp.array(dtype=V), v: wp.array(dtype=V), A: wp.array(dtype=M), gm: wp.array(dtype=T),
          gp: wp.array(dtype=V)):
        i = wp.tid()
        mass = T(0.75)
        dx = T(1.0)
        mv = mass * v[i]
        Ai = A[i]
        b, fx, W = stencil(x[i], V(), T(1.0))
        n0 = b[0] * 9 + b[1]
        if wp.static(mode == "warp"):
            for a in range(3):
                cx = V(Ai[0, 0], Ai[1, 0]) * ((T(float(a)) - fx[0]) * dx)
                for c in range(3):
                    w = W[a, 0] * W[c, 1]
                    gm[n0 + a * 9 + c] += w * mass
                    gp[n0 + a * 9 + c] += w * (mv + (cx + V(Ai[0, 1], Ai[1, 1]) * ((T(float(c)) - fx[1]) * dx)))
        else:
            rows(gm, gp, n0, 9, W, fx, dx, mass, mv, Ai)

    return k


def _gather_kernel(T, mode):
    V, R = vec(2, T), wp.types.matrix((3, 2), T)
    stencil = stencil_func(T, 2)
    rows = gather_rows_func(T, portable=(mode == "portable")) if mode != "warp" else None

    @wp.kernel(enable_backward=False, module="unique")
    def k(x: wp.array(dtype=V), g: wp.array(dtype=V), out: wp.array(dtype=R)):
        i = wp.tid()
        b, fx, W = stencil(x[i], V(), T(1.0))
        n0 = b[0] * 9 + b[1]
        if wp.static(mode == "warp"):
            r = R()
            for a in range(3):
                for c in range(3):
                    w = W[a, 0] * W[c, 1]
                    gv = g[n0 + a * 9 + c]
                    for l in range(2):
                        r[0, l] += w * gv[l]
                        r[1, l] += w * (T(float(a)) - fx[0]) * gv[l]
                        r[2, l] += w * (T(float(c)) - fx[1]) * gv[l]
            out[i] = r
        else:
            out[i] = rows(g, n0, 9, W, fx)

    return k


def _scatter(T, mode):
    x, v, A, _ = _particles(T)
    V, M = vec(2, T), mat(2, T)
    gm = wp.zeros(SHAPE[0] * SHAPE[1], dtype=T, device="cpu")
    gp = wp.zeros(SHAPE[0] * SHAPE[1], dtype=V, device="cpu")
    wp.launch(_scatter_kernel(T, mode), len(x), device="cpu",
              inputs=[wp.array(x, dtype=V, device="cpu"), wp.array(v, dtype=V, device="cpu"),
                      wp.array(A, dtype=M, device="cpu"), gm, gp])
    return gm.numpy(), gp.numpy()


def _gather(T, mode):
    x, _, _, g = _particles(T)
    V, R = vec(2, T), wp.types.matrix((3, 2), T)
    out = wp.zeros(len(x), dtype=R, device="cpu")
    wp.launch(_gather_kernel(T, mode), len(x), device="cpu",
              inputs=[wp.array(x, dtype=V, device="cpu"), wp.array(g, dtype=V, device="cpu"), out])
    return out.numpy()


def test_scatter_vector_code_is_the_plain_code_to_the_rounding_of_its_fused_multiply_adds(T):
    """CUDA's plain code and the Warp form give the same grid bit for bit; the CPU snippet fuses each product and
    the sum it feeds (one rounding instead of two), so it agrees with them to a few rounding units of the grid's
    values (a missed node or a wrong weight is off by a tenth of them)."""
    vec_m, vec_p = _scatter(T, "vector")
    plain_m, plain_p = _scatter(T, "portable")
    warp_m, warp_p = _scatter(T, "warp")
    assert np.array_equal(plain_m, warp_m) and np.array_equal(plain_p, warp_p)
    u = float(np.finfo(vec_m.dtype).eps)
    assert np.abs(vec_m - plain_m).max() <= 8 * u * np.abs(plain_m).max()
    assert np.abs(vec_p - plain_p).max() <= 8 * u * np.abs(plain_p).max()
    assert vec_m.sum() == pytest.approx(0.75 * 64, rel=1e-6)  # the weights of each particle sum to one


def test_gather_vector_code_matches_the_plain_code_and_the_stencil_sums(T):
    got = _gather(T, "vector")
    eps = 1e-6 if T == wp.float32 else 1e-14
    for mode in ("portable", "warp"):
        assert np.allclose(got, _gather(T, mode), rtol=0.0, atol=eps * 8), mode
