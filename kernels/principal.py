"""Principal decompositions of the elastic state ``F_E = I + H``: the 2x2 SVD, symmetric eigen-decompositions
and the principal Hencky strains used by the constitutive update and the diagnostics.

Every function comes from a cached factory of the scalar type ``T`` and the dimension
(2: plane strain, where ``F_E = diag(F_2, 1 + h_zz)``; 3).
"""

import functools

import warp as wp

from .logstrain import log1p_func
from .types import mat, vec

#: Jacobi sweeps at most (4 at most were used on 4e4 random and clustered matrices; the stopping rule ends the loop)
_MAX_SWEEPS = 8

__all__ = ["svd2_func", "jacobi_eig3_func", "sym_eig_func", "principal_func", "principal_strain_func"]


@functools.cache
def svd2_func(T):
    """Return ``svd2(F) -> (U, s, V)`` of a 2x2 matrix, ``F = U diag(s) V^T``.

    ``U`` and ``V`` are rotations and ``s[1]`` carries the sign of ``det F``, the
    convention of ``wp.svd3`` (``wp.svd2`` returns a reflection in ``U`` for
    ``det F < 0`` and fails on symmetric reflections such as ``[[0, 1], [1, 0]]``).
    Closed form: the polar rotation ``R`` of ``F = R S`` (angle ``atan2(F10 - F01,
    F00 + F11)``), then the eigenvectors ``Q`` of the symmetric ``S``:
    ``U = R Q``, ``V = Q``, ``s`` the eigenvalues of ``S``, descending.
    """
    M2 = mat(2, T)
    V2 = vec(2, T)

    @wp.func
    def svd2(F: M2):
        x = F[0, 0] + F[1, 1]
        y = F[1, 0] - F[0, 1]
        h = wp.sqrt(x * x + y * y)
        c = T(1.0)
        sn = T(0.0)
        if h > T(0.0):
            c = x / h
            sn = y / h
        R = M2(c, -sn, sn, c)
        S = wp.transpose(R) * F
        s12 = T(0.5) * (S[0, 1] + S[1, 0])
        d = T(0.5) * (S[0, 0] - S[1, 1])
        m = T(0.5) * (S[0, 0] + S[1, 1])
        r = wp.sqrt(d * d + s12 * s12)
        t = T(0.5) * wp.atan2(s12, d)
        cq = wp.cos(t)
        sq = wp.sin(t)
        Q = M2(cq, -sq, sq, cq)
        return R * Q, V2(m + r, m - r), Q

    return svd2


@functools.cache
def jacobi_eig3_func(T):
    """Return ``jacobi_eig3(X) -> (Q, lam)``: eigen-decomposition of a symmetric 3x3 matrix, converged.

    Cyclic Jacobi with exact rotations (Golub and Van Loan 2013, section 8.5), swept over
    the pairs (0, 1), (0, 2), (1, 2) until every off-diagonal entry is at most a rounding
    unit of the largest diagonal one, ``u max |a_ii|`` (``u = 2^-24`` float32, ``2^-53``
    float64): ``Q^T X Q`` is then diagonal to the rounding of ``X`` itself. Convergence is
    quadratic, also for repeated eigenvalues; 3 to 5 sweeps in practice, at most
    :data:`_MAX_SWEEPS`. ``Q`` is accumulated by the same rotations, so it stays orthogonal
    to a few rounding units. Eigenvalues are in the order of the diagonal, unsorted.
    Why not ``wp.eig3``: its four float32 sweeps of approximate rotations stop short
    (docs/model.md §4, "Principal strains").
    """
    M3 = mat(3, T)
    V3 = vec(3, T)
    u = 2.0**-24 if T == wp.float32 else 2.0**-53
    max_sweeps = _MAX_SWEEPS

    @wp.func
    def rotation(app: T, aqq: T, apq: T):
        """``(t, c, s)`` of the rotation that zeroes ``apq``: ``t = tan``, the smaller of the two angles."""
        h = aqq - app
        t = T(0.0)
        if wp.abs(h) + T(100.0) * wp.abs(apq) == wp.abs(h):
            t = apq / h  # |apq| below a rounding unit of |h| / 100: t = 1/(2 theta) to rounding (theta^2 overflows)
        else:
            theta = T(0.5) * h / apq
            t = T(1.0) / (wp.abs(theta) + wp.sqrt(T(1.0) + theta * theta))
            if theta < T(0.0):
                t = -t
        c = T(1.0) / wp.sqrt(T(1.0) + t * t)
        return t, c, t * c

    @wp.func
    def jacobi_eig3(X: M3):
        a00 = X[0, 0]
        a11 = X[1, 1]
        a22 = X[2, 2]
        a01 = T(0.5) * (X[0, 1] + X[1, 0])
        a02 = T(0.5) * (X[0, 2] + X[2, 0])
        a12 = T(0.5) * (X[1, 2] + X[2, 1])
        v0 = V3(T(1.0), T(0.0), T(0.0))
        v1 = V3(T(0.0), T(1.0), T(0.0))
        v2 = V3(T(0.0), T(0.0), T(1.0))
        sweep = int(0)
        while sweep < max_sweeps:
            sweep += 1
            tol = T(u) * wp.max(wp.max(wp.abs(a00), wp.abs(a11)), wp.abs(a22))
            rotated = int(0)
            if wp.abs(a01) > tol:  # pair (0, 1); the other index 2
                t, c, s = rotation(a00, a11, a01)
                a00 = a00 - t * a01
                a11 = a11 + t * a01
                a01 = T(0.0)
                r_p = a02
                a02 = c * r_p - s * a12
                a12 = s * r_p + c * a12
                w = v0
                v0 = c * w - s * v1
                v1 = s * w + c * v1
                rotated = 1
            if wp.abs(a02) > tol:  # pair (0, 2); the other index 1
                t, c, s = rotation(a00, a22, a02)
                a00 = a00 - t * a02
                a22 = a22 + t * a02
                a02 = T(0.0)
                r_p = a01
                a01 = c * r_p - s * a12
                a12 = s * r_p + c * a12
                w = v0
                v0 = c * w - s * v2
                v2 = s * w + c * v2
                rotated = 1
            if wp.abs(a12) > tol:  # pair (1, 2); the other index 0
                t, c, s = rotation(a11, a22, a12)
                a11 = a11 - t * a12
                a22 = a22 + t * a12
                a12 = T(0.0)
                r_p = a01
                a01 = c * r_p - s * a02
                a02 = s * r_p + c * a02
                w = v1
                v1 = c * w - s * v2
                v2 = s * w + c * v2
                rotated = 1
            if rotated == 0:
                break
        return wp.matrix_from_cols(v0, v1, v2), V3(a00, a11, a22)

    return jacobi_eig3


@functools.cache
def sym_eig_func(T, dim=3):
    """Return ``sym_eig(X) -> (Q, lam)``: eigenvectors (columns of ``Q``) and eigenvalues of a symmetric matrix.

    3D: :func:`jacobi_eig3_func` (off-diagonal of ``Q^T X Q`` below a rounding unit of
    ``|X|``). 2D: closed form, ``lam = m +- r`` with ``m = tr/2``,
    ``r = sqrt(((X00 - X11)/2)^2 + X01^2)``, ``Q`` the rotation by ``1/2 atan2(2 X01, X00 - X11)``.
    """
    M = mat(dim, T)
    V = vec(dim, T)
    jacobi_eig3 = jacobi_eig3_func(T)

    @wp.func
    def sym_eig(X: M):
        if wp.static(dim == 2):
            d = T(0.5) * (X[0, 0] - X[1, 1])
            o = T(0.5) * (X[0, 1] + X[1, 0])
            m = T(0.5) * (X[0, 0] + X[1, 1])
            r = wp.sqrt(d * d + o * o)
            t = T(0.5) * wp.atan2(o, d)
            c = wp.cos(t)
            sn = wp.sin(t)
            return M(c, -sn, sn, c), V(m + r, m - r)
        else:
            return jacobi_eig3(X)

    return sym_eig


@functools.cache
def principal_func(T, dim=3):
    """Return ``principal(H, h_zz) -> (U, s: vec3, V)``: SVD of ``F_E = I + H`` (``dim x dim`` ``U``, ``V``).

    In 3D ``h_zz`` is ignored; in plane strain ``s[2] = 1 + h_zz``. The last
    in-plane singular value carries the sign of ``det`` (rotations ``U``, ``V``).
    """
    M = mat(dim, T)
    V3 = vec(3, T)
    svd2 = svd2_func(T)

    @wp.func
    def principal(H: M, hzz: T):
        F = wp.identity(dim, dtype=T) + H
        if wp.static(dim == 2):
            U, s2, Vm = svd2(F)
            return U, V3(s2[0], s2[1], T(1.0) + hzz), Vm
        else:
            U = M()
            s = V3()
            Vm = M()
            wp.svd3(F, U, s, Vm)
            return U, s, Vm

    return principal


@functools.cache
def principal_strain_func(T, dim=3):
    """Return ``principal_strain(H, h_zz, s_floor) -> (U, eps: vec3, Vm, s: vec3, svd: int)``.

    Principal Hencky strains ``eps`` and left singular vectors ``U`` of
    ``F_E = I + H`` (plane strain: ``eps[2] = log1p(h_zz)``). Normally from the
    eigen-decomposition of ``X = F F^T - I = H + H^T + H H^T``:
    ``eps_i = 1/2 log1p(lambda_i)``, which keeps the relative precision of a
    strain of 1e-6 in float32 (the SVD of ``I + H`` resolves strains only to a
    rounding unit of 1); then ``svd = 0`` and ``Vm``, ``s`` are not computed. A
    stretch below 1e-2 or ``det F <= 0`` takes the SVD (``svd = 1``): ``s`` the
    signed singular values, ``eps = ln max(s, s_floor)``.
    """
    M = mat(dim, T)
    V3 = vec(3, T)
    sym_eig = sym_eig_func(T, dim)
    principal = principal_func(T, dim)
    log1p = log1p_func(T)

    @wp.func
    def principal_strain(H: M, hzz: T, s_floor: T):
        det = wp.determinant(wp.identity(dim, dtype=T) + H)
        if wp.static(dim == 2):
            det = det * (T(1.0) + hzz)
        if det > T(0.0):
            Q, lam = sym_eig(H + wp.transpose(H) + H * wp.transpose(H))
            lam_min = lam[0]
            for a in range(dim):
                lam_min = wp.min(lam_min, lam[a])
            if lam_min > T(-0.9999):
                eps = V3()
                for a in range(dim):
                    eps[a] = T(0.5) * log1p(lam[a])
                if wp.static(dim == 2):
                    eps[2] = log1p(hzz)
                return Q, eps, M(), V3(), int(0)
        U, s, Vm = principal(H, hzz)
        eps = V3(wp.log(wp.max(s[0], s_floor)), wp.log(wp.max(s[1], s_floor)), wp.log(wp.max(s[2], s_floor)))
        return U, eps, Vm, s, int(1)

    return principal_strain
