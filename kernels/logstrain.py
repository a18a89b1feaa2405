"""Hencky strain without a decomposition, for the common small-strain case.

The elastic state is stored as the displacement gradient ``H = F_E - I`` (see
``kernels/constitutive.py``). The spatial Hencky strain is ``eps = 1/2 log(b)``
with ``b = F F^T = I + X``, ``X = H + H^T + H H^T`` (formed from ``H`` directly,
so a strain of 1e-6 keeps its float32 digits instead of drowning in the 1 of
``F``). The Kirchhoff stress of the Hencky St Venant-Kirchhoff model is then
``tau = 2 mu eps + lam tr(eps) I`` (docs/model.md §1, written without the SVD:
``U diag(f(s)) U^T = f(U diag(s) U^T)`` for any isotropic ``f``).

For ``X`` small the matrix logarithm is its series

    log(I + X) = X - X^2/2 + X^3/3 - ... (-1)^(n+1) X^n/n + O(|X|^(n+1)),

summed by scalar recurrences (Cayley-Hamilton; see :func:`log_strain_func`),
far cheaper than an SVD or an eigen-decomposition. With ``|X|_F <= 0.1`` and
``n = 6`` (float32) the truncation error is below ``0.1^7 / 7 = 1.4e-8``, under
float32 round-off; float64 sums 15 terms (``0.1^16 / 16 = 6e-18``), so its
verification runs are not limited by the series. Tiny strains (below 2e-4 in
float32, 1e-8 in float64) take one or two terms: the rest lies below the
rounding of the result and would otherwise underflow into subnormal numbers,
which a CPU computes a hundred times slower. Larger strains, and any
``det F <= 0`` (a reflection has ``b = I`` too), fall back to the SVD path,
which the caller runs when ``ok == 0``.

In plane strain (``dim = 2``) ``F_E`` is block diagonal: the in-plane 2x2 block
``I + H`` and the out-of-plane stretch ``1 + h_zz``; ``eps_zz = log1p(h_zz)``
exactly (:func:`log1p_func`).
"""

import functools
import math

import warp as wp

from .types import mat


@functools.cache
def log_strain_func(T, dim=3):
    """Return ``log_strain(H) -> (eps: mat, ok: int)`` for ``H = F - I`` (``dim x dim``).

    ``eps`` is the spatial Hencky strain ``1/2 log(F F^T)`` (-) when ``ok == 1``;
    ``ok == 0`` means the series does not apply (``|F F^T - I|_F > 0.1`` or
    ``det F <= 0``) and ``eps`` is undefined.

    The series is summed with scalar recurrences instead of matrix products
    (Cayley-Hamilton): every power of ``X`` is ``a I + b X`` in 2D
    (``X^2 = t X - d I``, ``t = tr X``, ``d = det X``) and ``a I + b X + c X^2`` in
    3D (``X^3 = I1 X^2 - I2 X + I3 I``), so ``log(I + X) = alpha I + beta X
    [+ gamma X^2]`` costs one matrix product in 3D and none in 2D.

    Tiny strains take the first terms only, where the rest lies below a quarter
    rounding unit ``u/4`` of the result (``u = 2^-24`` float32, ``2^-53`` float64)
    and would otherwise be computed in subnormal numbers (a hundred times slower
    on a CPU): ``eps = (H + H^T)/2`` when ``max |H_ij| <= u/16`` (then ``|H H^T|
    <= dim u/16 |H|``), ``eps = (X - X^2/2)/2`` when ``|X|^2/3 <= u/4``.
    """
    M = mat(dim, T)
    order = 6 if T == wp.float32 else 15  # truncation |X|^(n+1)/(n+1) < 1.4e-8 (float32) / 6e-18 (float64) of |X|
    u = 2.0**-24 if T == wp.float32 else 2.0**-53
    h_first = u / 16.0  # max |H_ij| up to which eps = (H + H^T) / 2
    x2_second = 3.0 * u / 4.0  # |X|_F^2 up to which two terms suffice: |X|^2 / 3 <= u / 4

    @wp.func
    def log_strain(H: M):
        I = wp.identity(dim, dtype=T)
        h_max = T(0.0)  # a balanced max tree: short dependency chains
        if wp.static(dim == 2):
            h_max = wp.max(wp.max(wp.abs(H[0, 0]), wp.abs(H[0, 1])), wp.max(wp.abs(H[1, 0]), wp.abs(H[1, 1])))
        else:
            r0 = wp.max(wp.max(wp.abs(H[0, 0]), wp.abs(H[0, 1])), wp.abs(H[0, 2]))
            r1 = wp.max(wp.max(wp.abs(H[1, 0]), wp.abs(H[1, 1])), wp.abs(H[1, 2]))
            r2 = wp.max(wp.max(wp.abs(H[2, 0]), wp.abs(H[2, 1])), wp.abs(H[2, 2]))
            h_max = wp.max(wp.max(r0, r1), r2)
        if h_max <= T(h_first):
            return T(0.5) * (H + wp.transpose(H)), 1  # det F > 0: |H| < 1/dim
        X = H + wp.transpose(H) + H * wp.transpose(H)
        ok = 0
        eps = M()
        s2 = wp.ddot(X, X)
        if s2 <= T(0.01) and wp.determinant(I + H) > T(0.0):
            ok = 1
            if wp.static(dim == 2):
                t = X[0, 0] + X[1, 1]
                d = X[0, 0] * X[1, 1] - X[0, 1] * X[1, 0]
                if s2 <= T(x2_second):
                    # X - X^2/2 = d/2 I + (1 - t/2) X
                    eps = T(0.5) * ((T(0.5) * d) * I + (T(1.0) - T(0.5) * t) * X)
                else:
                    # X^k = p I + q X; X^(k+1) = -d q I + (p + t q) X
                    p = T(0.0)
                    q = T(1.0)
                    alpha = T(0.0)
                    beta = T(1.0)
                    sign = T(1.0)
                    for k in range(2, wp.static(order + 1)):  # unrolled: constant bounds
                        p_next = -d * q
                        q = p + t * q
                        p = p_next
                        sign = -sign
                        ck = sign / T(float(k))
                        alpha += ck * p
                        beta += ck * q
                    eps = T(0.5) * (alpha * I + beta * X)
            else:
                X2 = X * X
                if s2 <= T(x2_second):
                    eps = T(0.5) * (X - T(0.5) * X2)
                else:
                    i1 = wp.trace(X)
                    i2 = T(0.5) * (i1 * i1 - wp.trace(X2))
                    i3 = wp.determinant(X)
                    # X^k = a I + b X + c X^2; X^(k+1) = c i3 I + (a - c i2) X + (b + c i1) X^2
                    a = T(0.0)
                    b = T(0.0)
                    c = T(1.0)
                    alpha = T(0.0)
                    beta = T(1.0)
                    gamma = T(-0.5)
                    sign = T(-1.0)
                    for k in range(3, wp.static(order + 1)):  # unrolled: constant bounds
                        a_next = c * i3
                        b_next = a - c * i2
                        c = b + c * i1
                        a = a_next
                        b = b_next
                        sign = -sign
                        ck = sign / T(float(k))
                        alpha += ck * a
                        beta += ck * b
                        gamma += ck * c
                    eps = T(0.5) * (alpha * I + beta * X + gamma * X2)
        return eps, ok

    return log_strain


@functools.cache
def log1p_func(T):
    """Return ``log1p(h) = ln(1 + h)`` accurate for small ``h``; ``h > -1``.

    For ``|h| <= 1/16`` (every elastic strain of snow) by its series ``h - h^2/2 + h^3/3 - ...`` to ``h^n``
    by :func:`poly_func`, ``n = 7`` (float32) or 13 (float64): the first omitted term is below
    ``|h| 16^-n / (n + 1)`` (4.7e-10 and 1.6e-17 of ``|h|``, under the rounding unit), with no library
    ``log`` and no division. Beyond, Goldberg's ``ln(u) h / (u - 1)``, ``u = 1 + h`` (1991, Theorem 4).
    """
    order = 7 if T == wp.float32 else 13
    series = poly_func(T, tuple((-1.0) ** (k + 1) / k for k in range(2, order + 1)))  # (-1)^(k+1)/k, k = 2..n

    @wp.func
    def log1p(h: T):
        r = h
        if wp.abs(h) <= T(0.0625):
            r = h + (h * h) * series(h)
        else:
            u = T(1.0) + h
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


@functools.cache
def expm1_sym_func(T, dim=3, order=None):
    """Return ``expm1_sym(D) -> exp(D) - I`` for a small symmetric ``dim x dim`` matrix ``D`` (``|D|_F <= 1/4``).

    The series ``sum_k D^k / k!`` from ``k = 1`` (no cancellation against ``I``, so a
    strain increment of 1e-9 keeps its digits), summed with the scalar recurrences of
    :func:`log_strain_func` (Cayley-Hamilton). With ``|D|_F <= 1/4`` the first omitted term is
    below ``|D| 4^-n / (n + 1)!``: ``n = 8`` (float32, 4e-11 of ``|D|``) and ``n = 13``
    (float64, 2e-19). The constitutive update applies it to the plastic correction
    ``D = eps_new - eps`` of a return that kept the eigenvectors of the trial. ``order`` overrides ``n`` for a
    caller that knows ``|D|`` smaller (:func:`expm1_order`).
    """
    M = mat(dim, T)
    order = order or expm1_order(T)

    @wp.func
    def expm1_sym(D: M):
        I = wp.identity(dim, dtype=T)
        if wp.static(dim == 2):
            t = D[0, 0] + D[1, 1]
            d = D[0, 0] * D[1, 1] - D[0, 1] * D[1, 0]
            # D^k = p I + q D; D^(k+1) = -d q I + (p + t q) D
            p = T(0.0)
            q = T(1.0)
            alpha = T(0.0)
            beta = T(1.0)
            ck = T(1.0)
            for k in range(2, wp.static(order + 1)):  # unrolled: constant bounds
                p_next = -d * q
                q = p + t * q
                p = p_next
                ck = ck / T(float(k))
                alpha += ck * p
                beta += ck * q
            return alpha * I + beta * D
        else:
            D2 = D * D
            i1 = wp.trace(D)
            i2 = T(0.5) * (i1 * i1 - wp.trace(D2))
            i3 = wp.determinant(D)
            # D^k = a I + b D + c D^2; D^(k+1) = c i3 I + (a - c i2) D + (b + c i1) D^2
            a = T(0.0)
            b = T(0.0)
            c = T(1.0)
            alpha = T(0.0)
            beta = T(1.0)
            gamma = T(0.5)
            ck = T(0.5)
            for k in range(3, wp.static(order + 1)):  # unrolled: constant bounds
                a_next = c * i3
                b_next = a - c * i2
                c = b + c * i1
                a = a_next
                b = b_next
                ck = ck / T(float(k))
                alpha += ck * a
                beta += ck * b
                gamma += ck * c
            return alpha * I + beta * D + gamma * D2

    return expm1_sym


def expm1_order(T, d_max=0.25):
    """The order ``n`` of the exponential series for ``|D| <= d_max`` (``d_max = 1/4`` or ``1/256``): the first
    omitted term is below ``|D| d_max^n / (n + 1)!``, under a fifth of the rounding unit: ``n = 8`` (float32,
    4e-11) and 13 (float64, 2e-19) for 1/4; ``n = 3`` (float32, 2.5e-9) and 6 (float64, 7e-19) for 1/256, the
    plastic correction of one step of any but a violent flow (the struck block's are below 1/800).
    """
    if d_max == 0.25:
        return 8 if T == wp.float32 else 13
    if d_max == 1.0 / 256.0:
        return 3 if T == wp.float32 else 6
    raise ValueError(f"d_max = {d_max!r}: expected 0.25 or 1/256")


@functools.cache
def expm1_small_func(T, order=None):
    """Return ``expm1_small(x) -> exp(x) - 1`` for ``|x| <= 1/4`` by the series of :func:`expm1_sym_func`.

    The scalar companion of ``expm1_sym`` (the out-of-plane entry of the same correction in
    plane strain), a tenth of the cost of ``exp`` and ``log`` in :func:`expm1_func`: ``x p(x)``,
    ``p(x) = sum_{k < n} x^k / (k + 1)!`` by :func:`poly_func`; ``order`` as in :func:`expm1_sym_func`.
    """
    order = order or expm1_order(T)
    p = poly_func(T, tuple(1.0 / math.factorial(k + 1) for k in range(order)))

    @wp.func
    def expm1_small(x: T):
        return x * p(x)

    return expm1_small


@functools.cache
def poly_func(T, coeffs):
    """Return ``poly(x) -> sum_k coeffs[k] x^k`` (``coeffs``: a tuple of Python floats, rounded once to ``T``).

    Horner's rule in ``x^2`` on the even and the odd coefficients, two independent chains of half the
    length (``E(x^2) + x O(x^2)``): the series of this module are latency-bound in the constitutive
    update, and this halves their dependency chain for the same operation count.
    """
    even = list(coeffs[0::2])[::-1]  # highest power first
    odd = list(coeffs[1::2])[::-1] or [0.0]

    @wp.func
    def poly(x: T):
        x2 = x * x
        e = T(wp.static(even[0]))
        for j in range(1, wp.static(len(even))):  # unrolled: constant bounds
            e = T(wp.static(even[j])) + x2 * e
        o = T(wp.static(odd[0]))
        for j in range(1, wp.static(len(odd))):  # unrolled: constant bounds
            o = T(wp.static(odd[j])) + x2 * o
        return e + x * o

    return poly
