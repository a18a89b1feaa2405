"""Where the plastic step's constitutive update spends its time, on the trial states of a real step.

mpm_warp compiles the update into P2G, so its parts cannot be read from a stage
timer. These kernels run the engine's own ``wp.func``s on the very inputs of a
step (the trial ``H_tr = H + L + L H``, ``L = dt C``, of every particle of a
snapshot and its ``log_Jp``), each loading its inputs and storing its outputs:

``update``
    the whole update (``constitutive.constitutive_update_func``): what P2G
    does per particle before its scatter; a yielding trial in the series range
    takes the return without a decomposition;
``principal_path_update``
    the same update built with ``decomposition_free=False``: every yielding
    trial takes the eigen-decomposition (the engine before the
    decomposition-free return), with the largest differences of its new state
    from the engine's (``engine_vs_principal_path``: rounding);
``series_check``
    the small-strain prefix that every particle runs (``log_strain`` series,
    p, q, yield check);
``principal``
    the principal strains of the general path (``principal_strain_func``: the
    eigen-decomposition of ``F F^T - I``), now taken only by trials beyond the
    series range (``series_range_fraction`` of the particles are inside it);
``return``
    ``camclay_return_strain`` alone on those principal strains.

The loads and stores make every figure slightly larger than the same work
inside the fused P2G. On the CPU the figures are process CPU time (one thread).

``plastic_step.py`` calls :func:`update_cost` for every size it times; on its own::

    python benchmarks/perf/return_cost.py [--dim 3] [--n-grid 32] [--repeats 5] [--quick]

measures the struck block (``mpm_warp.studies.plastic_block``) after its warm-up and writes
``benchmarks/perf/results/return_cost_<device>.json``.
"""

import functools
import math
import os
import sys

import numpy as np
import warp as wp

from mpm_warp.kernels.camclay import camclay_p0_func, camclay_return_strain_func, camclay_yield_func
from mpm_warp.kernels.constitutive import constitutive_update_func, material_struct, trial_func
from mpm_warp.kernels.logstrain import log1p_func, log_strain_func
from mpm_warp.kernels.principal import principal_strain_func
from mpm_warp.kernels.types import mat, vec
from mpm_warp.model import material_params
from mpm_warp.studies import plastic_block as pb
from mpm_warp.studies.blocks import block_simulation
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser, result_name
from mpm_warp.studies.timing import median_launch_time

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")

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
        ``update_s``, ``principal_path_update_s``, ``series_check_s``, ``principal_s``, ``return_s``
        (seconds), ``series_says_yielding`` (fraction outside the series range or yielding),
        ``series_range_fraction``, ``return_yielded`` (fractions), and ``engine_vs_principal_path``:
        the largest differences of the principal-path update's ``H`` (and ``h_zz``), ``tau`` (Pa) and
        ``log_Jp`` from the engine's.
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


def main(argv=None) -> int:
    ap = parser(__doc__, "the 3D block at 24 cells")
    ap.add_argument("--dim", type=int, default=3, choices=(2, 3))
    ap.add_argument("--n-grid", type=int, default=32, help="cells per axis of the unit box")
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args(argv)
    if a.quick:
        a.dim, a.n_grid = 3, 24
    sim = block_simulation(a.dim, "plastic", a.n_grid, a.device, n_threads=1)
    sim.stepper.set_frame_end(1e9)
    sim.stepper.steps(pb.warmup_steps(a.n_grid))     # the state the timed steps of plastic_step see
    cost = update_cost(sim, a.repeats)
    print({k: v for k, v in cost.items() if k.endswith("_s")}, flush=True)
    name = result_name("return_cost", a)
    data = {"benchmark": "the Cam-Clay update and its parts on the trial states of the struck block, per launch",
            "dim": a.dim, "n_grid": a.n_grid, "n_particles": sim.model.n_particles, "repeats": a.repeats,
            "clock": "process CPU time" if not a.device.startswith("cuda") else "wall time", "cost": cost,
            "environment": environment(a.device)}
    print("wrote", write_json(name, data, out_dir(a, RESULTS, "return_cost")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
