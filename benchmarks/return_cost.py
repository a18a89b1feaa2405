"""What the SVD and the Cam-Clay return cost alone, on the trial states of a real step.

mpm_warp compiles the return into P2G, so its share of the step cannot be read
from a stage timer. These kernels isolate it on the very inputs of a step: the
trial ``F_tr = (I + dt C) F_E`` of every particle of a snapshot, its SVD, and
``camclay_return`` (the engine's own ``wp.func``) on the trial singular values
and ``log_Jp``. Each kernel loads its inputs and stores its outputs (trial: 72
bytes in, 12 out; return: 16 in, 16 out), so the figures slightly overstate
the compute inside the step.

Two more kernels profile the engine's plastic path and a cheaper one:
``series_check`` is the small-strain prefix every Cam-Clay particle runs first
(``log_strain`` series, p, q, yield check: wasted work when the particle then
yields and falls back to the SVD); ``svd_free`` is a prototype of the return
without any SVD, valid where the series is (``|F F^T - I| <= 0.1``): the
return needs only the invariants (p, q) of the trial Hencky strain and keeps
its eigenvectors, so ``eps_new = scale dev(eps_tr) + tr(eps_new)/3 I`` and,
``eps_new`` being coaxial with ``eps_tr``, ``F_E,new = exp(eps_new - eps_tr)
F_tr`` (a short series). The engine's ``camclay_return`` is called on
principal strains with the trial's trace and deviatoric norm, so the
projection itself is the engine's.
"""

import functools
import math
import statistics
import time

import numpy as np
import warp as wp

from mpm_warp.kernels.camclay import camclay_p0_func, camclay_return_func, camclay_yield_func
from mpm_warp.kernels.logstrain import log_strain_func
from mpm_warp.kernels.types import mat33, vec3

SQRT6 = math.sqrt(6.0)


@functools.cache
def _kernels(T):
    V, M = vec3(T), mat33(T)
    camclay = camclay_return_func(T)

    @wp.kernel(enable_backward=False)
    def trial_svd(F: wp.array(dtype=M), C: wp.array(dtype=M), dt: T, sig: wp.array(dtype=V)):
        i = wp.tid()
        F_tr = (wp.identity(3, dtype=T) + dt * C[i]) * F[i]
        U = M()
        s = V()
        Vt = M()
        wp.svd3(F_tr, U, s, Vt)
        sig[i] = s

    @wp.kernel(enable_backward=False)
    def camclay_only(sig: wp.array(dtype=V), log_jp: wp.array(dtype=T), mu: T, lam: T, M_csl: T, beta: T, xi: T,
                     p0_floor: T, sig_out: wp.array(dtype=V), log_jp_out: wp.array(dtype=T),
                     yielded: wp.array(dtype=wp.int32)):
        i = wp.tid()
        s, lj, y = camclay(sig[i], log_jp[i], mu, lam, M_csl, beta, xi, p0_floor)
        sig_out[i] = s
        log_jp_out[i] = lj
        yielded[i] = y

    log_strain = log_strain_func(T)
    p0_fn = camclay_p0_func(T)
    yield_fn = camclay_yield_func(T)

    @wp.kernel(enable_backward=False)
    def series_check(F: wp.array(dtype=M), C: wp.array(dtype=M), dt: T, log_jp: wp.array(dtype=T), mu: T, lam: T,
                     M_csl: T, beta: T, xi: T, p0_floor: T, yielding: wp.array(dtype=wp.int32)):
        i = wp.tid()
        F_tr = (wp.identity(3, dtype=T) + dt * C[i]) * F[i]
        eps, ok = log_strain(F_tr)
        tr_eps = wp.trace(eps)
        K = lam + T(2.0 / 3.0) * mu
        dev = eps - (tr_eps / T(3.0)) * wp.identity(3, dtype=T)
        q = T(SQRT6) * mu * wp.sqrt(wp.ddot(dev, dev))
        p0 = p0_fn(log_jp[i], K, xi, p0_floor)
        y = int(0)
        if ok == 0 or yield_fn(-K * tr_eps, q, p0, M_csl, beta) > T(0.0):
            y = 1
        yielding[i] = y

    @wp.kernel(enable_backward=False)
    def svd_free(F: wp.array(dtype=M), C: wp.array(dtype=M), dt: T, log_jp: wp.array(dtype=T), mu: T, lam: T,
                 M_csl: T, beta: T, xi: T, p0_floor: T, F_out: wp.array(dtype=M), log_jp_out: wp.array(dtype=T),
                 tau_out: wp.array(dtype=M)):
        i = wp.tid()
        I = wp.identity(3, dtype=T)
        F_tr = (I + dt * C[i]) * F[i]
        eps, ok = log_strain(F_tr)  # the prototype assumes ok (small elastic strain), as in the benchmark scene
        tr_eps = wp.trace(eps)
        dev = eps - (tr_eps / T(3.0)) * I
        r = wp.sqrt(wp.ddot(dev, dev))
        m = tr_eps / T(3.0)
        # principal strains with the trial's trace and deviatoric norm: the return sees the same (p, q)
        a = r * T(math.sqrt(2.0 / 3.0))
        b = r / T(SQRT6)
        sig = V(wp.exp(m + a), wp.exp(m - b), wp.exp(m - b))
        s_new, lj, y = camclay(sig, log_jp[i], mu, lam, M_csl, beta, xi, p0_floor)
        e_new = V(wp.log(s_new[0]), wp.log(s_new[1]), wp.log(s_new[2]))
        tr_new = e_new[0] + e_new[1] + e_new[2]
        scale = T(1.0)
        if r > T(0.0):
            d_new = e_new - V(tr_new, tr_new, tr_new) / T(3.0)
            scale = wp.length(d_new) / r
        eps_new = scale * dev + (tr_new / T(3.0)) * I
        D = eps_new - eps  # coaxial with eps: exp(eps_new) exp(-eps) = exp(D)
        E = I + T(0.2) * D  # exp(D) = I + D (I + D/2 (I + D/3 (I + D/4 (I + D/5)))), Horner
        E = I + (D * E) / T(4.0)
        E = I + (D * E) / T(3.0)
        E = I + (D * E) / T(2.0)
        E = I + D * E
        F_out[i] = E * F_tr
        log_jp_out[i] = lj
        tau_out[i] = T(2.0) * mu * eps_new + (lam * tr_new) * I

    return trial_svd, camclay_only, series_check, svd_free


def _median_time(launch, device, repeats: int) -> float:
    launch()  # compile / load
    wp.synchronize_device(device)
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        launch()
        wp.synchronize_device(device)
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def return_cost(sim, repeats: int = 5) -> dict:
    """Seconds per step of the trial SVD and of the return alone, for the state of ``sim`` (one launch).

    Parameters
    ----------
    sim : mpm_warp.Simulation
        A single-group Cam-Clay scene with a fixed time step, in the state to measure.
    repeats : int
        Timed launches; the median is reported.

    Returns
    -------
    dict
        ``trial_svd_s`` and ``return_s`` (s per launch over all particles),
        ``yielded_fraction`` of the return launch (the share that ran the
        projection, not just the yield check).
    """
    T = sim.model.T
    dev = sim.device
    n = sim.model.n_particles
    g = sim.model.groups[0]
    mat = g.material
    s = sim.state
    trial_svd, camclay_only, series_check, svd_free = _kernels(T)
    sig = wp.zeros(n, dtype=vec3(T), device=dev)
    sig_out = wp.zeros_like(sig)
    lj_out = wp.zeros(n, dtype=T, device=dev)
    yielded = wp.zeros(n, dtype=wp.int32, device=dev)
    dt = T(sim.scenario.time.dt)
    t_svd = _median_time(lambda: wp.launch(trial_svd, n, inputs=[s.F, s.C, dt, sig], device=dev), dev, repeats)
    args = [sig, s.log_jp, T(mat.mu), T(mat.lam), T(mat.M), T(mat.beta), T(mat.xi), T(mat.p0_floor),
            sig_out, lj_out, yielded]
    t_ret = _median_time(lambda: wp.launch(camclay_only, n, inputs=args, device=dev), dev, repeats)
    cc = [T(mat.mu), T(mat.lam), T(mat.M), T(mat.beta), T(mat.xi), T(mat.p0_floor)]
    flags = wp.zeros(n, dtype=wp.int32, device=dev)
    t_check = _median_time(lambda: wp.launch(series_check, n, inputs=[s.F, s.C, dt, s.log_jp, *cc, flags],
                                             device=dev), dev, repeats)
    F_out = wp.zeros_like(s.F)
    tau = wp.zeros_like(s.F)
    t_free = _median_time(lambda: wp.launch(svd_free, n, inputs=[s.F, s.C, dt, s.log_jp, *cc, F_out, lj_out, tau],
                                            device=dev), dev, repeats)
    return {"trial_svd_s": t_svd, "return_s": t_ret, "series_check_s": t_check, "svd_free_update_s": t_free,
            "yielded_fraction": float(np.mean(yielded.numpy())),
            "series_says_yielding_fraction": float(np.mean(flags.numpy())),
            "svd_free_F": F_out.numpy().copy(), "svd_free_log_jp": lj_out.numpy().copy()}
