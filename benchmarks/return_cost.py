"""What the SVD and the Cam-Clay return cost alone, on the trial states of a real step.

mpm_warp compiles the return into P2G, so its share of the step cannot be read
from a stage timer. These kernels isolate it on the very inputs of a step: the
trial ``F_tr = (I + dt C) F_E`` of every particle of a snapshot, its SVD, and
``camclay_return`` (the engine's own ``wp.func``) on the trial singular values
and ``log_Jp``. Each kernel loads its inputs and stores its outputs (trial: 72
bytes in, 12 out; return: 16 in, 16 out), so the figures slightly overstate
the compute inside the step.
"""

import functools
import statistics
import time

import numpy as np
import warp as wp

from mpm_warp.kernels.camclay import camclay_return_func
from mpm_warp.kernels.types import mat33, vec3


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

    return trial_svd, camclay_only


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
    trial_svd, camclay_only = _kernels(T)
    sig = wp.zeros(n, dtype=vec3(T), device=dev)
    sig_out = wp.zeros_like(sig)
    lj_out = wp.zeros(n, dtype=T, device=dev)
    yielded = wp.zeros(n, dtype=wp.int32, device=dev)
    dt = T(sim.scenario.time.dt)
    t_svd = _median_time(lambda: wp.launch(trial_svd, n, inputs=[s.F, s.C, dt, sig], device=dev), dev, repeats)
    args = [sig, s.log_jp, T(mat.mu), T(mat.lam), T(mat.M), T(mat.beta), T(mat.xi), T(mat.p0_floor),
            sig_out, lj_out, yielded]
    t_ret = _median_time(lambda: wp.launch(camclay_only, n, inputs=args, device=dev), dev, repeats)
    return {"trial_svd_s": t_svd, "return_s": t_ret, "yielded_fraction": float(np.mean(yielded.numpy()))}
