"""Hencky strain without a decomposition, for the common small-strain case.

The spatial Hencky strain is ``eps = 1/2 log(b)`` with ``b = F F^T``; the
Kirchhoff stress of the Hencky St Venant-Kirchhoff model is then
``tau = 2 mu eps + lam tr(eps) I`` (MODEL.md 1, written without the SVD:
``U diag(f(s)) U^T = f(U diag(s) U^T)`` for any isotropic ``f``).

For ``X = b - I`` small the matrix logarithm is its series

    log(I + X) = X - X^2/2 + X^3/3 - X^4/4 + X^5/5 - X^6/6 + O(|X|^7),

evaluated by Horner's rule (five 3x3 products instead of a 3x3 SVD, about
20 times cheaper on the CPU). With ``|X|_F <= 0.1`` the truncation error is
below ``0.1^7 / 7 = 1.4e-8``, under float32 round-off of ``F`` itself. Larger
strains, and any ``det F <= 0`` (a reflection has ``b = I`` too), fall back to
the SVD path, which the caller runs when ``ok == 0``.
"""

import functools

import warp as wp

from .types import mat33


@functools.cache
def log_strain_func(T):
    """Return ``log_strain(F) -> (eps: mat33, ok: int)``.

    ``eps`` is the spatial Hencky strain ``1/2 log(F F^T)`` (-) when ``ok == 1``;
    ``ok == 0`` means the series does not apply (``|F F^T - I|_F > 0.1`` or
    ``det F <= 0``) and ``eps`` is undefined.
    """
    M = mat33(T)

    @wp.func
    def log_strain(F: M):
        I = wp.identity(3, dtype=T)
        X = F * wp.transpose(F) - I
        ok = 0
        eps = M()
        if wp.ddot(X, X) <= T(0.01) and wp.determinant(F) > T(0.0):
            L = T(1.0 / 5.0) * I - T(1.0 / 6.0) * X
            L = T(-1.0 / 4.0) * I + X * L
            L = T(1.0 / 3.0) * I + X * L
            L = T(-1.0 / 2.0) * I + X * L
            L = I + X * L
            eps = T(0.5) * (X * L)
            ok = 1
        return eps, ok

    return log_strain
