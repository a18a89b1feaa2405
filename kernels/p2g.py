"""Particle-to-grid transfer (MLS-MPM, Hu et al. 2018) with the constitutive update.

One launch per particle group (a block of one material). Per particle, in
physical order:

1. trial elastic state ``H_tr = H + L + L H``, ``L = dt C`` (``F_tr = (I + dt C) F_E``,
   docs/model.md §4) and the material's constitutive update, which returns the new
   elastic state and the Kirchhoff stress ``tau`` (``kernels/constitutive.py``);
   In plane strain a plastic particle also updates its out-of-plane elastic stretch ``hzz``
   (indexed as ``log_jp``); an elastic one has ``F_E,zz = 1`` and stores none;
2. scatter of mass and of the MLS-MPM momentum
   ``m v + (m C - dt V0 D^-1 tau) (x_i - x_p)``, ``D^-1 = 4 / dx^2``, to the
   ``3^dim`` nodes of the quadratic B-spline stencil.

The grid is stored flat (one 1D array per grid copy, C order: node ``(i, j[, k])``
at ``i s_0 + j s_1 [+ k]``, ``strides = (s_0, s_1[, 1])``): every array of the
kernel is then one-dimensional and contiguous, which Warp's CPU code generator
specialises (element strides known at compile time), and a stencil node is its
base index plus a constant offset.

In plane strain (``dim = 2``) positions are 2-vectors, the grid is 2D and the
particle volume ``V0`` and mass are per unit depth (m^3/m, kg/m).

Counters (``counts``, int32, per grid copy): ``[1]`` particles skipped with a
stencil outside the grid (only a non-finite position), ``[2]`` singular-value
floor events, ``[3]`` inversions (``det F_tr <= 0``).
"""

import functools

import warp as wp

from .constitutive import (
    FLOORED,
    INVERTED,
    PLASTIC_MODELS,
    YIELDED,
    constitutive_update_func,
    material_struct,
    trial_func,
)
from .p2g_rows import scatter_rows_func
from .shape import NONNEG, in_grid_func, stencil_func
from .types import mat, vec


@functools.cache
def p2g_kernel(dim, T, model, track_yield):
    """Build the P2G kernel.

    Parameters
    ----------
    dim : {2, 3}
        Spatial dimension (2: plane strain).
    T : warp scalar type
        ``wp.float32`` or ``wp.float64``.
    model : str
        Material model of the group (see ``kernels.constitutive.MODELS``); plastic
        models read and write ``log_jp``, the bonded weak layer and tensile cracking ``kappa``.
    track_yield : bool
        Also set ``yielded[i] = 1`` where the return was active (output field).
    """
    V = vec(dim, T)
    M = mat(dim, T)
    Vi = wp.types.vector(dim, wp.int32)
    P = material_struct(T)
    stencil = stencil_func(T, dim)
    in_grid = in_grid_func(dim)
    scatter_rows = scatter_rows_func(T) if dim == 2 else None
    trial = trial_func(T, dim)
    update = constitutive_update_func(dim, T, model)
    plastic = model in PLASTIC_MODELS
    bonded = model == "bonded_camclay"
    cracking = model == "tensile_cracking"

    @wp.kernel(enable_backward=False, module="unique")
    def p2g(
        x: wp.array(dtype=V),
        v: wp.array(dtype=V),
        C: wp.array(dtype=M),
        H: wp.array(dtype=M),
        hzz: wp.array(dtype=T),
        log_jp: wp.array(dtype=T),
        kappa: wp.array(dtype=T),
        yielded: wp.array(dtype=wp.uint8),
        mass: T,
        vol0: T,
        m: P,
        dt_arr: wp.array(dtype=T),
        origin: V,
        inv_dx: T,
        dx: T,
        shape: Vi,
        strides: Vi,
        grid_m: wp.array(dtype=T),
        grid_p: wp.array(dtype=V),
        counts: wp.array(dtype=wp.int32),
    ):
        i = wp.tid()
        dt = dt_arr[0]
        if dt <= T(0.0):
            return
        Cp = C[i]
        H_tr = trial(H[i], dt * Cp)
        lj = T(0.0)
        kap = T(0.0)
        if wp.static(plastic):
            lj = log_jp[i]
        if wp.static(bonded or cracking):
            kap = kappa[i]
        if wp.static(dim == 2 and plastic):
            H_new, hzz_new, tau, lj_new, kap_new, flags = update(H_tr, hzz[i], lj, kap, m)
            hzz[i] = hzz_new
        elif wp.static(dim == 2):  # elastic: F_E,zz is the total, 1 (not stored); the update keeps it
            H_new, hzz_new, tau, lj_new, kap_new, flags = update(H_tr, T(0.0), lj, kap, m)
        else:
            H_new, tau, lj_new, kap_new, flags = update(H_tr, lj, kap, m)
        H[i] = H_new
        if flags != 0:
            if wp.static(plastic):
                if (flags & YIELDED) != 0:
                    log_jp[i] = lj_new
                    if wp.static(bonded):
                        kappa[i] = kap_new
                    if wp.static(track_yield):
                        yielded[i] = wp.uint8(1)
            if wp.static(cracking):
                if (flags & YIELDED) != 0:
                    kappa[i] = kap_new
            if (flags & FLOORED) != 0:
                wp.atomic_add(counts, 2, 1)
            if (flags & INVERTED) != 0:
                wp.atomic_add(counts, 3, 1)
        A = (-dt * vol0 * T(4.0) * inv_dx * inv_dx) * tau + mass * Cp
        mv = mass * v[i]
        b, fx, W = stencil(x[i], origin, inv_dx)
        if not in_grid(b, shape):
            wp.atomic_add(counts, 1, 1)
            return
        if wp.static(dim == 2):
            # (masking the sign bit, a no-op on the in-grid indices, tells the compiler they are not negative: no
            # negative-index wrap per access)
            s0 = strides[0] & NONNEG
            n0 = (b[0] * s0 + b[1] * strides[1]) & NONNEG
            # A dpos = A[:, 0] dpos_x + A[:, 1] dpos_y (Warp's order), its column terms formed once per stencil
            # row and column: the same sums in the same order as the per-node product; the scatter as
            # vector operations with fused multiply-adds on the CPU (kernels/p2g_rows.py)
            scatter_rows(grid_m, grid_p, n0, s0, W, fx, dx, mass, mv, A)
        else:
            n0 = b[0] * strides[0] + b[1] * strides[1] + b[2]
            for a in range(3):
                for c in range(3):
                    for d in range(3):
                        n = n0 + a * strides[0] + c * strides[1] + d
                        w = W[a, 0] * W[c, 1] * W[d, 2]
                        dpos = (V(T(float(a)), T(float(c)), T(float(d))) - fx) * dx
                        grid_m[n] += w * mass
                        grid_p[n] += w * (mv + A * dpos)

    return p2g
