"""The Cam-Clay update and its parts, each alone on the trial states of a step (``benchmarks/perf/return_cost.py``).

The engine compiles the update into P2G, so its parts cannot be read from a stage timer: these kernels run the
engine's own ``wp.func``s on a snapshot's trial states ``H_tr = H + L + L H`` (``L = dt C``), each loading its
inputs and storing its outputs (slightly more than the same work inside the fused P2G).
"""

# no ``from __future__ import annotations``: the kernels' annotations name closure types
import functools
import math

import numpy as np
import warp as wp

from ...kernels.camclay import camclay_p0_func, camclay_return_strain_func, camclay_yield_func
from ...kernels.constitutive import constitutive_update_func, material_struct, trial_func
from ...kernels.logstrain import log1p_func, log_strain_func
from ...kernels.principal import principal_strain_func
from ...kernels.types import mat, vec
from ...model import material_params
from ..timing import median_launch_time

SQRT6 = math.sqrt(6.0)


@functools.cache
def _kernels(T, dim):
    M, V3 = mat(dim, T), vec(3, T)
    P = material_struct(T)
    trial = trial_func(T, dim)
    updates = {free: constitutive_update_func(dim, T, "camclay", free) for free in (True, False)}
    principal_strain = principal_strain_func(T, dim)
    ret = camclay_return_strain_func(T)
    log_strain = log_strain_func(T, dim)
    log1p = log1p_func(T)
    p0_fn = camclay_p0_func(T)
    yield_fn = camclay_yield_func(T)

    def full(free):
        update = updates[free]

        @wp.kernel(enable_backward=False, module="unique")
        def full_update(H: wp.array(dtype=M), hzz: wp.array(dtype=T), C: wp.array(dtype=M), dt: T,
                        log_jp: wp.array(dtype=T), m: P, H_out: wp.array(dtype=M), hzz_out: wp.array(dtype=T),
                        tau_out: wp.array(dtype=M), lj_out: wp.array(dtype=T)):
            i = wp.tid()
            H_tr = trial(H[i], dt * C[i])
            if wp.static(dim == 2):
                H_new, hzz_new, tau, lj_new, kappa_new, flags = update(H_tr, hzz[i], log_jp[i], T(0.0), m)
                hzz_out[i] = hzz_new
            else:
                H_new, tau, lj_new, kappa_new, flags = update(H_tr, log_jp[i], T(0.0), m)
            H_out[i] = H_new
            tau_out[i] = tau
            lj_out[i] = lj_new

        return full_update

    @wp.kernel(enable_backward=False, module="unique")
    def series_check(H: wp.array(dtype=M), hzz: wp.array(dtype=T), C: wp.array(dtype=M), dt: T,
                     log_jp: wp.array(dtype=T), m: P, yielding: wp.array(dtype=wp.int32),
                     in_range: wp.array(dtype=wp.int32)):
        i = wp.tid()
        eps, ok = log_strain(trial(H[i], dt * C[i]))
        tr = wp.trace(eps)
        ezz = T(0.0)
        if wp.static(dim == 2):
            ezz = log1p(hzz[i])
            tr = tr + ezz
        mean = tr / T(3.0)
        dev = eps - mean * wp.identity(dim, dtype=T)
        dev2 = wp.ddot(dev, dev)
        if wp.static(dim == 2):
            dev2 = dev2 + (ezz - mean) * (ezz - mean)
        K = m.lam + (T(2.0) / T(3.0)) * m.mu
        y = int(0)
        if ok == 0 or yield_fn(-K * tr, T(SQRT6) * m.mu * wp.sqrt(dev2), p0_fn(log_jp[i], K, m.xi, m.p0_floor), m.M,
                               m.beta) > T(0.0):
            y = 1
        yielding[i] = y
        in_range[i] = ok

    @wp.kernel(enable_backward=False, module="unique")
    def principal(H: wp.array(dtype=M), hzz: wp.array(dtype=T), C: wp.array(dtype=M), dt: T, m: P,
                  eps_out: wp.array(dtype=V3)):
        i = wp.tid()
        U, eps, Vm, s, svd = principal_strain(trial(H[i], dt * C[i]), hzz[i], m.s_floor)
        eps_out[i] = eps

    @wp.kernel(enable_backward=False, module="unique")
    def return_only(eps: wp.array(dtype=V3), log_jp: wp.array(dtype=T), m: P, eps_out: wp.array(dtype=V3),
                    lj_out: wp.array(dtype=T), yielded: wp.array(dtype=wp.int32)):
        i = wp.tid()
        e, lj, y = ret(eps[i], log_jp[i], m.mu, m.lam, m.M, m.beta, m.xi, m.p0_floor)
        eps_out[i] = e
        lj_out[i] = lj
        yielded[i] = y

    return full(True), full(False), series_check, principal, return_only


def update_cost(sim, repeats: int = 5) -> dict:
    """Seconds per launch (all particles) of the update and its parts for the current state of ``sim``.

    Parameters
    ----------
    sim : mpm_warp.Simulation
        A single-group Cam-Clay scene (2D or 3D) with a fixed time step, in the state to measure.
    repeats : int
        Timed launches; the median is reported.

    Returns
    -------
    dict
        Seconds per launch (process CPU time on the CPU, wall time on CUDA) of ``update_s``: the whole update
        (``constitutive_update_func``, what P2G does per particle before its scatter);
        ``principal_path_update_s``: the same built with ``decomposition_free=False`` (every yielding trial takes
        the eigen-decomposition); ``series_check_s``: the small-strain prefix (``log_strain`` series, p, q, yield
        check); ``principal_s``: the principal strains of the general path; ``return_s``:
        ``camclay_return_strain`` alone on those. Fractions of the particles: ``series_says_yielding`` (outside
        the series range or yielding), ``series_range_fraction``, ``return_yielded``. And
        ``engine_vs_principal_path``: the largest differences of the principal-path update's ``H`` (and
        ``hzz``, dimensionless), ``tau_Pa`` (Pa) and ``log_jp`` from the engine's.
    """
    dim = sim.model.dim
    T = sim.model.T
    dev = sim.device
    n = sim.model.n_particles
    m = material_params(sim.model.groups[0].material, T)
    s = sim.state
    hzz = s.hzz if s.hzz is not None else wp.zeros(n, dtype=T, device=dev)
    full_update, principal_update, series_check, principal, return_only = _kernels(T, dim)
    dt = T(sim.scenario.time.dt)
    ins = [s.H, hzz, s.C, dt]

    def outs():
        return [wp.zeros_like(s.H), wp.zeros_like(hzz), wp.zeros_like(s.H), wp.zeros_like(s.log_jp)]

    eng, ref = outs(), outs()
    flags = wp.zeros(n, dtype=wp.int32, device=dev)
    in_range = wp.zeros(n, dtype=wp.int32, device=dev)
    eps = wp.zeros(n, dtype=vec(3, T), device=dev)
    eps_out, lj_out = wp.zeros_like(eps), wp.zeros_like(s.log_jp)
    yielded = wp.zeros(n, dtype=wp.int32, device=dev)

    def timed(kernel, inputs):
        return median_launch_time(lambda: wp.launch(kernel, n, inputs=inputs, device=dev), dev, repeats)

    t_upd = timed(full_update, [*ins, s.log_jp, m, *eng])
    t_ref = timed(principal_update, [*ins, s.log_jp, m, *ref])
    t_chk = timed(series_check, [*ins, s.log_jp, m, flags, in_range])
    t_pri = timed(principal, [*ins, m, eps])
    t_ret = timed(return_only, [eps, s.log_jp, m, eps_out, lj_out, yielded])

    def maxdiff(a, b):
        return float(np.abs(a.numpy().astype(np.float64) - b.numpy().astype(np.float64)).max())

    diffs = {"H": maxdiff(ref[0], eng[0]), "tau_Pa": maxdiff(ref[2], eng[2]), "log_jp": maxdiff(ref[3], eng[3])}
    if dim == 2:
        diffs["hzz"] = maxdiff(ref[1], eng[1])
    return {"update_s": t_upd, "principal_path_update_s": t_ref, "series_check_s": t_chk, "principal_s": t_pri,
            "return_s": t_ret, "series_says_yielding": float(flags.numpy().mean()),
            "series_range_fraction": float(in_range.numpy().mean()),
            "return_yielded": float(yielded.numpy().mean()), "engine_vs_principal_path": diffs}
