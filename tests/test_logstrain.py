"""The small-strain Hencky strain ``1/2 log(F F^T)`` by its series (kernels/logstrain.py).

Against an independent float64 reference (``numpy.linalg.eigh`` of ``X = H + H^T
+ H H^T`` and ``log1p`` of its eigenvalues), over 2000 random displacement
gradients with norms from 1e-7 to 0.03 (``|X|`` up to the series' limit 0.1):
measured worst relative error 2.3e-7 in float32 (a few rounding units) and
2.8e-15 in float64 (15 terms: no truncation left). Also: the series declines
outside its range (``|X| > 0.1``, ``det F <= 0``), and ``log1p``/``expm1`` are
accurate for tiny arguments, where ``log(1 + h)`` would lose every digit.
Tiny strains (down to 1e-30, where the full series would compute in subnormal
numbers) keep the same relative accuracy. ``expm1_sym`` (``exp(D) - I`` of a
symmetric ``D``, ``|D| <= 1/4``, and with the shorter series of ``|D| <= 1/256``) and
``expm1_small`` against ``eigh`` and ``numpy.expm1`` in float64: within 32 rounding units of
``|D|`` (measured worst 20 u, float64 3D, where the recurrences and the reference's
eigenvectors each lose a few).
"""


import numpy as np
import pytest
import warp as wp
from helpers_validation import DEVICE

from mpm_warp.kernels.logstrain import (
    expm1_func,
    expm1_order,
    expm1_small_func,
    expm1_sym_func,
    log1p_func,
    log_strain_func,
)
from mpm_warp.kernels.types import mat

TOL = {"float32": 1e-6, "float64": 1e-14}
TYPES = {"float32": (wp.float32, np.float32), "float64": (wp.float64, np.float64)}


def _kernel(dim, T):
    M = mat(dim, T)
    ls = log_strain_func(T, dim)

    @wp.kernel(enable_backward=False, module="unique")
    def k(H: wp.array(dtype=M), out: wp.array(dtype=M), ok: wp.array(dtype=wp.int32)):
        i = wp.tid()
        e, o = ls(H[i])
        out[i] = e
        ok[i] = o

    return k


def _run(dim, precision, Hs):
    T, nt = TYPES[precision]
    M = mat(dim, T)
    n = len(Hs)
    out = wp.zeros(n, dtype=M, device=DEVICE)
    ok = wp.zeros(n, dtype=wp.int32, device=DEVICE)
    wp.launch(_kernel(dim, T), n, inputs=[wp.array(Hs.astype(nt), dtype=M, device=DEVICE), out, ok], device=DEVICE)
    return out.numpy().astype(np.float64), ok.numpy()


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_series_matches_reference(dim, precision):
    rng = np.random.default_rng(1)
    n = 2000
    Hs = (rng.normal(size=(n, dim, dim)) * np.geomspace(1e-7, 0.02, n)[:, None, None]).astype(TYPES[precision][1])
    got, ok = _run(dim, precision, Hs)
    H = Hs.astype(np.float64)
    X = H + np.transpose(H, (0, 2, 1)) + H @ np.transpose(H, (0, 2, 1))
    lam, Q = np.linalg.eigh(X)
    ref = 0.5 * np.einsum("nij,nj,nkj->nik", Q, np.log1p(lam), Q)
    inside = np.sqrt((X * X).sum(axis=(1, 2))) <= 0.1 * (1 - 1e-6)
    assert np.array_equal(ok[inside], np.ones(inside.sum(), dtype=ok.dtype))
    rel = np.abs(got - ref).max(axis=(1, 2))[ok == 1] / np.abs(ref).max(axis=(1, 2))[ok == 1]
    print(f"{dim}D {precision}: worst relative error {rel.max():.2e} over {int((ok == 1).sum())} points")
    assert rel.max() < TOL[precision]


@pytest.mark.parametrize("dim", [2, 3])
def test_series_declines_outside_its_range(dim):
    big = 0.2 * np.eye(dim)                           # |X| > 0.1
    flip = np.diag([-2.0] + [0.0] * (dim - 1))        # F = diag(-1, 1, ...): det F < 0, F F^T = I
    _, ok = _run(dim, "float64", np.stack([big, flip, np.zeros((dim, dim))]))
    assert ok.tolist() == [0, 0, 1]


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_log1p_and_expm1_keep_tiny_arguments(precision):
    T, nt = TYPES[precision]
    lp, em = log1p_func(T), expm1_func(T)

    @wp.kernel(enable_backward=False, module="unique")
    def k(x: wp.array(dtype=T), a: wp.array(dtype=T), b: wp.array(dtype=T)):
        i = wp.tid()
        a[i] = lp(x[i])
        b[i] = em(x[i])

    x = np.array([1e-12, -3e-9, 2e-6, -5e-4, 0.04, -0.0625, 0.0625, -0.0626, 0.1, -0.5, 2.0], dtype=nt)  # series edge
    a = wp.zeros(len(x), dtype=T, device=DEVICE)
    b = wp.zeros(len(x), dtype=T, device=DEVICE)
    wp.launch(k, len(x), inputs=[wp.array(x, dtype=T, device=DEVICE), a, b], device=DEVICE)
    u = 2.0**-24 if precision == "float32" else 2.0**-53
    x64 = x.astype(np.float64)
    np.testing.assert_allclose(a.numpy(), np.log1p(x64), rtol=4 * u)
    np.testing.assert_allclose(b.numpy(), np.expm1(x64), rtol=4 * u)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_series_keeps_tiny_strains(dim, precision):
    rng = np.random.default_rng(2)
    n = 400
    Hs = (rng.normal(size=(n, dim, dim)) * np.geomspace(1e-30, 1e-3, n)[:, None, None]).astype(TYPES[precision][1])
    got, ok = _run(dim, precision, Hs)
    assert ok.all()
    H = Hs.astype(np.float64)
    X = H + np.transpose(H, (0, 2, 1)) + H @ np.transpose(H, (0, 2, 1))
    lam, Q = np.linalg.eigh(X)
    ref = 0.5 * np.einsum("nij,nj,nkj->nik", Q, np.log1p(lam), Q)
    rel = np.abs(got - ref).max(axis=(1, 2)) / np.abs(ref).max(axis=(1, 2))
    assert rel.max() < TOL[precision]


@pytest.mark.parametrize("d_max", [0.25, 1.0 / 256.0])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_expm1_of_a_small_symmetric_matrix(dim, precision, d_max):
    T, nt = TYPES[precision]
    M = mat(dim, T)
    order = expm1_order(T, d_max)
    em_sym, em_small = expm1_sym_func(T, dim, order), expm1_small_func(T, order)

    @wp.kernel(enable_backward=False, module="unique")
    def k(D: wp.array(dtype=M), x: wp.array(dtype=T), out: wp.array(dtype=M), xo: wp.array(dtype=T)):
        i = wp.tid()
        out[i] = em_sym(D[i])
        xo[i] = em_small(x[i])

    rng = np.random.default_rng(4)
    n = 1000
    A = rng.normal(size=(n, dim, dim))
    S = A + np.transpose(A, (0, 2, 1))
    S *= (np.geomspace(1e-9, d_max, n) / np.sqrt((S * S).sum(axis=(1, 2))))[:, None, None]   # |D|_F up to d_max
    D = S.astype(nt)
    x = (rng.choice([-1.0, 1.0], n) * np.geomspace(1e-12, d_max, n)).astype(nt)
    out = wp.zeros(n, dtype=M, device=DEVICE)
    xo = wp.zeros(n, dtype=T, device=DEVICE)
    wp.launch(k, n, inputs=[wp.array(D, dtype=M, device=DEVICE), wp.array(x, dtype=T, device=DEVICE), out, xo],
              device=DEVICE)
    w, Q = np.linalg.eigh(D.astype(np.float64))
    ref = np.einsum("nij,nj,nkj->nik", Q, np.expm1(w), Q)
    u = 2.0**-24 if precision == "float32" else 2.0**-53
    err = np.abs(out.numpy() - ref).max(axis=(1, 2)) / np.abs(D.astype(np.float64)).max(axis=(1, 2))
    print(f"{dim}D {precision} order {order}: expm1_sym worst error {err.max() / u:.1f} u of |D|")
    assert err.max() < 32 * u
    np.testing.assert_allclose(xo.numpy(), np.expm1(x.astype(np.float64)), rtol=4 * u)
