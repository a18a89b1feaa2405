"""Hencky strain without a decomposition, for the common small-strain case.

The elastic state is stored as the displacement gradient ``H = F_E - I`` (see
``kernels/constitutive.py``). The spatial Hencky strain is ``eps = 1/2 log(b)``
with ``b = F F^T = I + X``, ``X = H + H^T + H H^T`` (formed from ``H`` directly,
so a strain of 1e-6 keeps its float32 digits instead of drowning in the 1 of
``F``). The Kirchhoff stress of the Hencky St Venant-Kirchhoff model is then
``tau = 2 mu eps + lam tr(eps) I`` (MODEL.md 1, written without the SVD:
``U diag(f(s)) U^T = f(U diag(s) U^T)`` for any isotropic ``f``).

For ``X`` small the matrix logarithm is its series

    log(I + X) = X - X^2/2 + X^3/3 - X^4/4 + X^5/5 - X^6/6 + O(|X|^7),

evaluated by Horner's rule (five products instead of an SVD, about 20 times
cheaper on the CPU in 3D). With ``|X|_F <= 0.1`` the truncation error is below
``0.1^7 / 7 = 1.4e-8``, under float32 round-off. Larger strains, and any
``det F <= 0`` (a reflection has ``b = I`` too), fall back to the SVD path,
which the caller runs when ``ok == 0``.

In plane strain (``dim = 2``) ``F_E`` is block diagonal: the in-plane 2x2 block
``I + H`` and the out-of-plane stretch ``1 + h_zz``; ``eps_zz = log1p(h_zz)``
exactly (:func:`log1p_func`).
"""

import functools

import warp as wp

from .types import mat


@functools.cache
def log_strain_func(T, dim=3):
    """Return ``log_strain(H) -> (eps: mat, ok: int)`` for ``H = F - I`` (``dim x dim``).

    ``eps`` is the spatial Hencky strain ``1/2 log(F F^T)`` (-) when ``ok == 1``;
    ``ok == 0`` means the series does not apply (``|F F^T - I|_F > 0.1`` or
    ``det F <= 0``) and ``eps`` is undefined.
    """
    M = mat(dim, T)

    @wp.func
    def log_strain(H: M):
        I = wp.identity(dim, dtype=T)
        X = H + wp.transpose(H) + H * wp.transpose(H)
        ok = 0
        eps = M()
        if wp.ddot(X, X) <= T(0.01) and wp.determinant(I + H) > T(0.0):
            L = (T(1.0) / T(5.0)) * I - (T(1.0) / T(6.0)) * X
            L = T(-1.0 / 4.0) * I + X * L
            L = (T(1.0) / T(3.0)) * I + X * L
            L = T(-1.0 / 2.0) * I + X * L
            L = I + X * L
            eps = T(0.5) * (X * L)
            ok = 1
        return eps, ok

    return log_strain


@functools.cache
def log1p_func(T):
    """Return ``log1p(h) = ln(1 + h)`` accurate for small ``h`` (Goldberg 1991, Theorem 4); ``h > -1``."""

    @wp.func
    def log1p(h: T):
        u = T(1.0) + h
        r = h
        if u != T(1.0):
            r = wp.log(u) * (h / (u - T(1.0)))
        return r

    return log1p


@functools.cache
def expm1_func(T):
    """Return ``expm1(x) = exp(x) - 1`` accurate for small ``x`` (Kahan's trick: ``(u - 1) x / ln u``, ``u = e^x``)."""

    @wp.func
    def expm1(x: T):
        u = wp.exp(x)
        r = x
        if u != T(1.0):
            lu = wp.log(u)
            if lu != T(0.0):
                r = (u - T(1.0)) * (x / lu)
            else:
                r = u - T(1.0)
        return r

    return expm1
