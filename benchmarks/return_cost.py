"""Where the plastic step's constitutive update spends its time, on the trial states of a real step.

mpm_warp compiles the update into P2G, so its parts cannot be read from a stage
timer. These kernels run the engine's own ``wp.func``s on the very inputs of a
step (the trial ``H_tr = H + L + L H``, ``L = dt C``, of every particle of a
snapshot and its ``log_Jp``), each loading its inputs and storing its outputs:

``update``
    the whole update (``constitutive.constitutive_update_func``): what P2G
    does per particle before its scatter;
``series_check``
    its small-strain prefix (``log_strain`` series, p, q, yield check), run by
    every particle and wasted when the particle then yields;
``principal``
    the principal strains of the general path (``principal_strain_func``: the
    eigen-decomposition of ``F F^T - I``);
``return``
    ``camclay_return_strain`` alone on those principal strains;
``no_eig``
    a prototype of the yielding update without any decomposition, valid where
    the series is (``|F F^T - I| <= 0.1``): the return needs only the
    invariants (p, q) of the trial Hencky strain ``eps`` (already computed by the
    series) and keeps its eigenvectors, so ``eps_new = scale dev(eps) +
    tr(eps_new)/3 I``; ``eps_new`` is coaxial with ``eps``, so ``F_new =
    exp(eps_new - eps) F_tr``, i.e. ``H_new = H_tr + expm1(D) (I + H_tr)`` with
    ``D = eps_new - eps`` (a short series), and ``tau = 2 mu eps_new + lam
    tr(eps_new) I``. The engine's ``camclay_return_strain`` is called on principal
    strains with the trial's trace and deviatoric norm, so the projection is the
    engine's; its result is compared with the engine's update.

The loads and stores make every figure slightly larger than the same work
inside the fused P2G. On the CPU the figures are process CPU time (one thread).
"""

import functools
import math
import statistics
import time

import numpy as np
import warp as wp

from mpm_warp.kernels.camclay import camclay_p0_func, camclay_return_strain_func, camclay_yield_func
from mpm_warp.kernels.constitutive import constitutive_update_func, material_struct, trial_func
from mpm_warp.kernels.logstrain import expm1_func, log1p_func, log_strain_func
from mpm_warp.kernels.principal import principal_strain_func
from mpm_warp.kernels.types import mat, vec
from mpm_warp.model import material_params

SQRT6 = math.sqrt(6.0)


@functools.cache
def _kernels(T, dim):
    M, V3 = mat(dim, T), vec(3, T)
    P = material_struct(T)
    trial = trial_func(T, dim)
    update = constitutive_update_func(dim, T, "camclay")
    principal_strain = principal_strain_func(T, dim)
    ret = camclay_return_strain_func(T)
    log_strain = log_strain_func(T, dim)
    log1p = log1p_func(T)
    expm1 = expm1_func(T)
    p0_fn = camclay_p0_func(T)
    yield_fn = camclay_yield_func(T)

    @wp.func
    def update_any(H_tr: M, hzz: T, lj: T, m: P):
        if wp.static(dim == 2):
            H_new, hzz_new, tau, lj_new, kappa_new, flags = update(H_tr, hzz, lj, T(0.0), m)
            return H_new, hzz_new, tau, lj_new, flags
        else:
            H_new, tau, lj_new, kappa_new, flags = update(H_tr, lj, T(0.0), m)
            return H_new, hzz, tau, lj_new, flags

    @wp.func
    def strain_invariants(H_tr: M, hzz: T):
        """Series Hencky strain (in-plane block in 2D), eps_zz, trace, deviatoric norm, and whether it applies."""
        eps, ok = log_strain(H_tr)
        tr = wp.trace(eps)
        ezz = T(0.0)
        if wp.static(dim == 2):
            ezz = log1p(hzz)
            tr = tr + ezz
        mean = tr / T(3.0)
        dev = eps - mean * wp.identity(dim, dtype=T)
        dev2 = wp.ddot(dev, dev)
        if wp.static(dim == 2):
            dev2 = dev2 + (ezz - mean) * (ezz - mean)
        return eps, ezz, tr, wp.sqrt(dev2), ok

    @wp.kernel(enable_backward=False)
    def full_update(H: wp.array(dtype=M), hzz: wp.array(dtype=T), C: wp.array(dtype=M), dt: T,
                    log_jp: wp.array(dtype=T), m: P, H_out: wp.array(dtype=M), hzz_out: wp.array(dtype=T),
                    tau_out: wp.array(dtype=M), lj_out: wp.array(dtype=T)):
        i = wp.tid()
        H_new, hzz_new, tau, lj, flags = update_any(trial(H[i], dt * C[i]), hzz[i], log_jp[i], m)
        H_out[i] = H_new
        hzz_out[i] = hzz_new
        tau_out[i] = tau
        lj_out[i] = lj

    @wp.kernel(enable_backward=False)
    def series_check(H: wp.array(dtype=M), hzz: wp.array(dtype=T), C: wp.array(dtype=M), dt: T,
                     log_jp: wp.array(dtype=T), m: P, yielding: wp.array(dtype=wp.int32)):
        i = wp.tid()
        eps, ezz, tr, r, ok = strain_invariants(trial(H[i], dt * C[i]), hzz[i])
        K = m.lam + (T(2.0) / T(3.0)) * m.mu
        y = int(0)
        if ok == 0 or yield_fn(-K * tr, T(SQRT6) * m.mu * r, p0_fn(log_jp[i], K, m.xi, m.p0_floor), m.M,
                               m.beta) > T(0.0):
            y = 1
        yielding[i] = y

    @wp.kernel(enable_backward=False)
    def principal(H: wp.array(dtype=M), hzz: wp.array(dtype=T), C: wp.array(dtype=M), dt: T, m: P,
                  eps_out: wp.array(dtype=V3)):
        i = wp.tid()
        U, eps, Vm, s, svd = principal_strain(trial(H[i], dt * C[i]), hzz[i], m.s_floor)
        eps_out[i] = eps

    @wp.kernel(enable_backward=False)
    def return_only(eps: wp.array(dtype=V3), log_jp: wp.array(dtype=T), m: P, eps_out: wp.array(dtype=V3),
                    lj_out: wp.array(dtype=T), yielded: wp.array(dtype=wp.int32)):
        i = wp.tid()
        e, lj, y = ret(eps[i], log_jp[i], m.mu, m.lam, m.M, m.beta, m.xi, m.p0_floor)
        eps_out[i] = e
        lj_out[i] = lj
        yielded[i] = y

    @wp.kernel(enable_backward=False)
    def no_eig(H: wp.array(dtype=M), hzz: wp.array(dtype=T), C: wp.array(dtype=M), dt: T,
               log_jp: wp.array(dtype=T), m: P, H_out: wp.array(dtype=M), hzz_out: wp.array(dtype=T),
               tau_out: wp.array(dtype=M), lj_out: wp.array(dtype=T)):
        i = wp.tid()
        I = wp.identity(dim, dtype=T)
        H_tr = trial(H[i], dt * C[i])
        hz = hzz[i]
        # the prototype assumes the series applies (small elastic strain), as in the benchmark scene
        eps, ezz, tr, r, ok = strain_invariants(H_tr, hz)
        mean = tr / T(3.0)
        # principal strains with the trial's trace and deviatoric norm: the return sees the same (p, q)
        a = r * T(math.sqrt(2.0 / 3.0))
        b = r / T(SQRT6)
        e_new, lj, y = ret(V3(mean + a, mean - b, mean - b), log_jp[i], m.mu, m.lam, m.M, m.beta, m.xi,
                           m.p0_floor)
        tr_new = e_new[0] + e_new[1] + e_new[2]
        scale = T(1.0)
        if r > T(0.0):
            scale = wp.length(e_new - V3(tr_new, tr_new, tr_new) / T(3.0)) / r
        mean_new = tr_new / T(3.0)
        eps_new = scale * (eps - mean * I) + mean_new * I
        D = eps_new - eps
        # expm1(D) = D (I + D/2 (I + D/3 (I + D/4 (I + D/5)))), Horner; |D| is one step's plastic strain
        E = I + T(0.2) * D
        E = I + (D * E) / T(4.0)
        E = I + (D * E) / T(3.0)
        E = I + (D * E) / T(2.0)
        H_out[i] = H_tr + (D * E) * (I + H_tr)
        if wp.static(dim == 2):
            ezz_new = scale * (ezz - mean) + mean_new
            hzz_out[i] = hz + (T(1.0) + hz) * expm1(ezz_new - ezz)
        tau_out[i] = T(2.0) * m.mu * eps_new + (m.lam * tr_new) * I
        lj_out[i] = lj

    return full_update, series_check, principal, return_only, no_eig


def _median_time(launch, device, repeats: int) -> float:
    """Median seconds of a launch: process CPU time on the CPU (shared cores), wall time on CUDA."""
    clock = time.perf_counter if wp.get_device(device).is_cuda else time.process_time
    launch()  # compile / load
    wp.synchronize_device(device)
    ts = []
    for _ in range(repeats):
        t0 = clock()
        launch()
        wp.synchronize_device(device)
        ts.append(clock() - t0)
    return statistics.median(ts)


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
        ``update_s``, ``series_check_s``, ``principal_s``, ``return_s``,
        ``no_eig_s`` (seconds), ``series_says_yielding`` and ``return_yielded``
        (fractions), and ``no_eig_vs_engine``: the largest differences of the
        prototype's ``H`` (and ``h_zz``), ``tau`` (Pa) and ``log_Jp`` from the
        engine's update.
    """
    dim = sim.model.dim
    T = sim.model.T
    dev = sim.device
    n = sim.model.n_particles
    m = material_params(sim.model.groups[0].material, T)
    s = sim.state
    hzz = s.hzz if s.hzz is not None else wp.zeros(n, dtype=T, device=dev)
    full_update, series_check, principal, return_only, no_eig = _kernels(T, dim)
    dt = T(sim.scenario.time.dt)
    ins = [s.H, hzz, s.C, dt]

    def outs():
        return [wp.zeros_like(s.H), wp.zeros_like(hzz), wp.zeros_like(s.H), wp.zeros_like(s.log_jp)]

    eng = outs()
    t_upd = _median_time(lambda: wp.launch(full_update, n, inputs=[*ins, s.log_jp, m, *eng], device=dev), dev,
                         repeats)
    flags = wp.zeros(n, dtype=wp.int32, device=dev)
    t_chk = _median_time(lambda: wp.launch(series_check, n, inputs=[*ins, s.log_jp, m, flags], device=dev), dev,
                         repeats)
    eps = wp.zeros(n, dtype=vec(3, T), device=dev)
    t_pri = _median_time(lambda: wp.launch(principal, n, inputs=[*ins, m, eps], device=dev), dev, repeats)
    eps_out, lj_out = wp.zeros_like(eps), wp.zeros_like(s.log_jp)
    yielded = wp.zeros(n, dtype=wp.int32, device=dev)
    t_ret = _median_time(lambda: wp.launch(return_only, n, inputs=[eps, s.log_jp, m, eps_out, lj_out, yielded],
                                           device=dev), dev, repeats)
    pro = outs()
    t_ne = _median_time(lambda: wp.launch(no_eig, n, inputs=[*ins, s.log_jp, m, *pro], device=dev), dev, repeats)

    def maxdiff(a, b):
        return float(np.abs(a.numpy().astype(np.float64) - b.numpy().astype(np.float64)).max())

    diffs = {"H": maxdiff(pro[0], eng[0]), "tau_Pa": maxdiff(pro[2], eng[2]), "log_jp": maxdiff(pro[3], eng[3])}
    if dim == 2:
        diffs["hzz"] = maxdiff(pro[1], eng[1])
    return {"update_s": t_upd, "series_check_s": t_chk, "principal_s": t_pri, "return_s": t_ret, "no_eig_s": t_ne,
            "series_says_yielding": float(flags.numpy().mean()), "return_yielded": float(yielded.numpy().mean()),
            "no_eig_vs_engine": diffs}
