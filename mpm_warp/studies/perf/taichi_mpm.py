"""MLS-MPM block in Taichi, 2D (plane strain) or 3D, elastic or Cam-Clay: the peer of the block benchmarks.

Written the way an experienced Taichi user would write it (mpm88/mpm128 style):
one fused ``ti.kernel`` per step whose top-level loops are parallel,
``ti.static`` stencil loops, ``ti.svd`` for the polar/singular values, dense
fields, scene constants folded in as Python floats. Taichi is imported by the
caller (:mod:`.taichi_peer`) and passed in; this module never imports it.

Constitutive update per particle (docs/model.md §1 and 4)
---------------------------------------------------
``F_tr = (I + dt C) F_E``; ``F_tr = U diag(s) V^T`` (``ti.svd``). Elastic:
``F_E = F_tr``. Cam-Clay: the return below maps ``s`` to ``s_new`` and
``log_Jp``; ``F_E = U diag(s_new) V^T``. Kirchhoff stress ``tau = U diag(2 mu
eps + lam tr eps) U^T``, ``eps = ln s``. Plane strain (2D) keeps a 2x2 ``F_E``
and its out-of-plane elastic stretch ``F_zz`` (a scalar field, 1 for elastic
particles since the total ``F_zz`` is 1): the return sees the three principal
stretches ``(s_0, s_1, F_zz)`` and the in-plane stress uses ``tr eps`` over all
three.

The Cam-Clay return (:mod:`.taichi_camclay`) is the same algorithm as mpm_warp's (docs/model.md §4).
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from .. import plastic_block as pb
from ..blocks import ELASTIC_E, ELASTIC_NU, ELASTIC_RHO, GRAVITY_Y, elastic_time_step
from .taichi_camclay import S_FLOOR, camclay_return_func

#: Width (in cells) of the slip boundary layer, Taichi style.
BOUND = 3
#: Absolute grid-mass threshold (kg) below which a node is treated as empty.
MASS_EPS = 1.0e-12

MODES = ("elastic", "plastic", "plastic_track", "no_return")


def build(ti: Any, n_grid: int, dim: int, material: str) -> SimpleNamespace:
    """Allocate the fields and define the step kernels of one scene (after ``ti.init``).

    Parameters
    ----------
    ti : module
        The initialised ``taichi`` module.
    n_grid : int
        Grid nodes per axis; ``n_particles = n_grid**dim``.
    dim : {2, 3}
    material : {"elastic", "plastic"}

    Returns
    -------
    SimpleNamespace
        ``fields`` (x, v, C, F and, for Cam-Clay, log_jp, yielded, F_zz in 2D),
        ``n_particles``, ``dt``, ``reset(x0, v0, C0)``, ``snapshot() -> dict``,
        ``restore(dict)`` and ``substep(scatter, mode)`` returning the step
        kernel for a P2G scatter (``"atomic"``: mpm88-style fused parallel
        scatter; ``"serial"``: parallel stress then a serialized scatter whose
        atomics Taichi demotes to plain adds, faster on few CPU cores) and a
        constitutive mode (``"elastic"``; for Cam-Clay ``"plastic"``,
        ``"plastic_track"`` which also sets ``yielded``, and ``"no_return"``:
        the same step with the return compiled out, SVD kept).
    """
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")
    if material not in ("elastic", "plastic"):
        raise ValueError(f"material must be 'elastic' or 'plastic', got {material!r}")
    f32 = ti.f32
    plastic = material == "plastic"
    n_particles = n_grid**dim
    dx = 1.0 / n_grid
    inv_dx = float(n_grid)
    if plastic:
        pb.check_n_grid(n_grid)
        E, nu, rho, dt = pb.YOUNG_E, pb.POISSON_NU, pb.DENSITY, pb.time_step(n_grid)
    else:
        E, nu, rho, dt = ELASTIC_E, ELASTIC_NU, ELASTIC_RHO, elastic_time_step(n_grid)
    p_vol = (0.5 * dx) ** dim  # 2D: per metre of thickness
    p_mass = rho * p_vol
    mu = E / (2.0 * (1.0 + nu))
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    K = lam + 2.0 * mu / 3.0
    stress_scale = -dt * p_vol * 4.0 * inv_dx * inv_dx
    gravity = [0.0] * dim
    gravity[1] = GRAVITY_Y
    bound = BOUND
    mass_eps = MASS_EPS
    s_floor = S_FLOOR

    x = ti.Vector.field(dim, dtype=f32, shape=n_particles)
    v = ti.Vector.field(dim, dtype=f32, shape=n_particles)
    C = ti.Matrix.field(dim, dim, dtype=f32, shape=n_particles)
    F = ti.Matrix.field(dim, dim, dtype=f32, shape=n_particles)
    affine_f = ti.Matrix.field(dim, dim, dtype=f32, shape=n_particles)
    grid_v = ti.Vector.field(dim, dtype=f32, shape=(n_grid,) * dim)
    grid_m = ti.field(dtype=f32, shape=(n_grid,) * dim)
    log_jp = ti.field(dtype=f32, shape=n_particles) if plastic else None
    yielded = ti.field(dtype=ti.u8, shape=n_particles) if plastic else None
    F_zz = ti.field(dtype=f32, shape=n_particles) if plastic and dim == 2 else None

    camclay_return = camclay_return_func(ti, mu, K)

    def make_affine(do_return: bool, track: bool):
        @ti.func
        def affine(p):
            """Update F_E (and log_Jp) of particle p; return its MLS-MPM affine momentum matrix."""
            F_tr = (ti.Matrix.identity(f32, dim) + dt * C[p]) @ F[p]
            U, sig, V = ti.svd(F_tr)
            s = ti.Vector([sig[0, 0], sig[1, 1], 1.0])
            if ti.static(dim == 3):
                s[2] = sig[2, 2]
            elif ti.static(plastic):
                s[2] = F_zz[p]
            if ti.static(do_return):
                s_new, ljp_new, hit = camclay_return(s, log_jp[p])
                log_jp[p] = ljp_new
                if ti.static(track):
                    yielded[p] = ti.cast(hit, ti.u8)
                s = s_new
                U_s = ti.Matrix([[U[i, d] * s[d] for d in ti.static(range(dim))] for i in ti.static(range(dim))])
                F[p] = U_s @ V.transpose()  # U diag(s_new) V^T
                if ti.static(dim == 2):
                    F_zz[p] = s[2]
            else:
                F[p] = F_tr
            e = ti.Vector([ti.log(ti.max(s[0], s_floor)), ti.log(ti.max(s[1], s_floor)),
                           ti.log(ti.max(s[2], s_floor))])
            tr = e[0] + e[1] + e[2]
            # Kirchhoff tau = U diag(t) U^T, with the P2G factor -dt V0 4/dx^2 folded into the columns of U
            U_t = ti.Matrix([[U[i, d] * ((2.0 * mu * e[d] + lam * tr) * stress_scale) for d in ti.static(range(dim))]
                             for i in ti.static(range(dim))])
            return U_t @ U.transpose() + p_mass * C[p]

        return affine

    @ti.func
    def stencil(xp):
        """Base node, fractional offset and quadratic B-spline weights of a particle."""
        Xp = xp * inv_dx
        base = ti.cast(Xp - 0.5, ti.i32)
        fx = Xp - ti.cast(base, f32)
        w = ti.Matrix.rows([0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1.0) ** 2, 0.5 * (fx - 0.5) ** 2])
        return base, fx, w

    @ti.func
    def scatter(p, aff):
        """P2G scatter of particle p; ``+=`` is atomic in parallel loops, plain when serialized."""
        base, fx, w = stencil(x[p])
        mv = p_mass * v[p]
        for offset in ti.static(ti.grouped(ti.ndrange(*((3,) * dim)))):
            dpos = (ti.cast(offset, f32) - fx) * dx
            weight = 1.0
            for d in ti.static(range(dim)):
                weight *= w[offset[d], d]
            grid_v[base + offset] += weight * (mv + aff @ dpos)
            grid_m[base + offset] += weight * p_mass

    @ti.func
    def clear_grid():
        for I in ti.grouped(grid_m):
            grid_v[I] = ti.Vector.zero(f32, dim)
            grid_m[I] = 0.0

    @ti.func
    def grid_update():
        """Momentum -> velocity, gravity, slip walls on the outer ``bound`` nodes."""
        for I in ti.grouped(grid_m):
            m = grid_m[I]
            if m > mass_eps:
                vel = grid_v[I] / m + dt * ti.Vector(gravity)
                for d in ti.static(range(dim)):
                    if I[d] < bound and vel[d] < 0.0:
                        vel[d] = 0.0
                    if I[d] > n_grid - bound and vel[d] > 0.0:
                        vel[d] = 0.0
                grid_v[I] = vel

    @ti.func
    def g2p():
        """APIC gather of velocity and affine matrix, then advection."""
        for p in x:
            base, fx, w = stencil(x[p])
            new_v = ti.Vector.zero(f32, dim)
            new_C = ti.Matrix.zero(f32, dim, dim)
            for offset in ti.static(ti.grouped(ti.ndrange(*((3,) * dim)))):
                dpos = ti.cast(offset, f32) - fx  # grid units: (x_i - x_p) / dx
                weight = 1.0
                for d in ti.static(range(dim)):
                    weight *= w[offset[d], d]
                g_v = grid_v[base + offset]
                new_v += weight * g_v
                new_C += (4.0 * inv_dx * weight) * g_v.outer_product(dpos)
            v[p] = new_v
            C[p] = new_C
            x[p] += dt * new_v

    kernels: dict = {}

    def substep(scatter_kind: str, mode: str):
        if scatter_kind not in ("atomic", "serial"):
            raise ValueError(f"scatter must be 'atomic' or 'serial', got {scatter_kind!r}")
        allowed = ("plastic", "plastic_track", "no_return") if plastic else ("elastic",)
        if mode not in allowed:
            raise ValueError(f"mode must be one of {allowed} for a {material} block, got {mode!r}")
        key = (scatter_kind, mode)
        if key in kernels:
            return kernels[key]
        affine = make_affine(mode in ("plastic", "plastic_track"), mode == "plastic_track")

        if scatter_kind == "atomic":
            @ti.kernel
            def step():
                clear_grid()
                for p in x:  # fused stress + scatter, parallel with atomic adds (mpm88 style)
                    scatter(p, affine(p))
                grid_update()
                g2p()
        else:
            @ti.kernel
            def step():
                clear_grid()
                for p in x:  # stress (SVD, return) in parallel
                    affine_f[p] = affine(p)
                ti.loop_config(serialize=True)
                for p in range(n_particles):  # serialized scatter: atomics demoted to plain adds
                    scatter(p, affine_f[p])
                grid_update()
                g2p()

        kernels[key] = step
        return step

    state_fields = {"x": x, "v": v, "C": C, "F": F}
    if plastic:
        state_fields["log_jp"] = log_jp
        if dim == 2:
            state_fields["F_zz"] = F_zz

    def reset(x0: np.ndarray, v0: np.ndarray, C0: np.ndarray) -> None:
        """Initial state: positions, velocities, affine matrices (float32 arrays), F_E = I, log_Jp(0)."""
        x.from_numpy(np.ascontiguousarray(x0, dtype=np.float32))
        v.from_numpy(np.ascontiguousarray(v0, dtype=np.float32))
        C.from_numpy(np.ascontiguousarray(C0, dtype=np.float32))
        F.from_numpy(np.tile(np.eye(dim, dtype=np.float32), (n_particles, 1, 1)))
        if plastic:
            log_jp.fill(pb.initial_log_jp())
            yielded.fill(0)
            if dim == 2:
                F_zz.fill(1.0)

    def snapshot() -> dict:
        return {k: f.to_numpy() for k, f in state_fields.items()}

    def restore(snap: dict) -> None:
        for k, f in state_fields.items():
            f.from_numpy(snap[k])

    fields = SimpleNamespace(x=x, v=v, C=C, F=F, grid_v=grid_v, grid_m=grid_m, log_jp=log_jp, yielded=yielded,
                             F_zz=F_zz)
    return SimpleNamespace(fields=fields, n_particles=n_particles, dt=dt, reset=reset, snapshot=snapshot,
                           restore=restore, substep=substep, plastic=plastic, dim=dim)

