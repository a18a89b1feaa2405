"""The Cam-Clay return of independent principal states, for the tests (kernels/camclay.py).

A probe kernel takes the singular values ``s`` of trial elastic states, forms their principal Hencky
strains ``ln max(s, SINGULAR_VALUE_FLOOR)`` (the SVD path of ``kernels/principal.py``), runs the engine's
return ``camclay_return_strain`` and gives the new state as singular values ``exp(eps_new)`` (the input
itself for an elastic trial), with ``p, q`` of the new state, ``p0`` of the old ``log_jp``, the yield
function there and the Hencky stress.
"""

import functools

import numpy as np
import warp as wp
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

from mpm_warp.kernels.camclay import (
    SINGULAR_VALUE_FLOOR,
    camclay_p0_func,
    camclay_pq_func,
    camclay_return_strain_func,
    camclay_yield_func,
)
from mpm_warp.kernels.elasticity import hencky_func
from mpm_warp.kernels.types import vec3

TYPES = {"float32": (wp.float32, np.float32, 2.0**-24), "float64": (wp.float64, np.float64, 2.0**-53)}


@functools.cache
def _probe(T):
    """Kernel: return mapping of independent states, then p, q, p0, y, Hencky tau."""
    v3 = vec3(T)
    ret, pq, p0f = camclay_return_strain_func(T), camclay_pq_func(T), camclay_p0_func(T)
    yf, hencky = camclay_yield_func(T), hencky_func(T)
    s_floor = SINGULAR_VALUE_FLOOR

    @wp.kernel(enable_backward=False)
    def probe(sig: wp.array(dtype=v3), ljp: wp.array(dtype=T), par: wp.array2d(dtype=T),
              sig_out: wp.array(dtype=v3), ljp_out: wp.array(dtype=T), flag: wp.array(dtype=wp.int32),
              res: wp.array2d(dtype=T), tau: wp.array(dtype=v3), eps_out: wp.array(dtype=v3)):
        i = wp.tid()
        mu, lam, M, beta, xi, pf = par[i, 0], par[i, 1], par[i, 2], par[i, 3], par[i, 4], par[i, 5]
        s = sig[i]
        sf = T(s_floor)
        eps = v3(wp.log(wp.max(s[0], sf)), wp.log(wp.max(s[1], sf)), wp.log(wp.max(s[2], sf)))
        e2, l2, y = ret(eps, ljp[i], mu, lam, M, beta, xi, pf)
        s2 = s
        if y != 0:
            s2 = v3(wp.exp(e2[0]), wp.exp(e2[1]), wp.exp(e2[2]))
        sig_out[i] = s2
        eps_out[i] = e2
        ljp_out[i] = l2
        flag[i] = y
        p0 = p0f(ljp[i], lam + T(2.0) / T(3.0) * mu, xi, pf)
        p, q = pq(s2, mu, lam)
        res[i, 0] = p
        res[i, 1] = q
        res[i, 2] = p0
        res[i, 3] = yf(p, q, p0, M, beta)
        tau[i] = hencky(s2, mu, lam, sf)

    return probe


def run_return(sig, ljp, cases, dtype):
    """Run the probe kernel; returns dict of numpy arrays (float64 except ``flag``; ``sig_raw`` in the
    kernel's type; ``eps`` the new principal strains as the return gave them). ``cases``: arrays ``mu``,
    ``lam`` (Pa), ``M``, ``beta``, ``xi`` (-), ``p0_floor`` (Pa)."""
    T, nt, _ = TYPES[dtype]
    n = len(sig)
    v3 = vec3(T)
    par = np.stack([cases[k] for k in ("mu", "lam", "M", "beta", "xi", "p0_floor")], axis=1)
    args = [wp.array(np.asarray(sig, nt), dtype=v3, device=DEVICE), wp.array(np.asarray(ljp, nt), dtype=T,
            device=DEVICE), wp.array(par.astype(nt), dtype=T, device=DEVICE)]
    outs = [wp.zeros(n, dtype=v3, device=DEVICE), wp.zeros(n, dtype=T, device=DEVICE),
            wp.zeros(n, dtype=wp.int32, device=DEVICE), wp.zeros((n, 4), dtype=T, device=DEVICE),
            wp.zeros(n, dtype=v3, device=DEVICE), wp.zeros(n, dtype=v3, device=DEVICE)]
    wp.launch(_probe(T), dim=n, inputs=args, outputs=outs, device=DEVICE)
    sig_out, ljp_out, flag, res, tau, eps = (o.numpy() for o in outs)
    return {"sig_raw": sig_out, "sig": sig_out.astype(np.float64), "ljp": ljp_out.astype(np.float64),
            "flag": flag, "p": res[:, 0].astype(np.float64), "q": res[:, 1].astype(np.float64),
            "p0": res[:, 2].astype(np.float64), "y": res[:, 3].astype(np.float64), "tau": tau.astype(np.float64),
            "eps": eps.astype(np.float64)}


def pq_np(sig, mu, lam):
    """Reference p, q (Pa) and dev eps from singular values, float64 (docs/model.md §1)."""
    eps = np.log(np.maximum(np.asarray(sig, np.float64), SINGULAR_VALUE_FLOOR))
    tr = eps.sum(axis=-1)
    dev = eps - tr[..., None] / 3.0
    return -(lam + 2.0 * mu / 3.0) * tr, np.sqrt(6.0) * mu * np.linalg.norm(dev, axis=-1), dev


def strain_size(sig):
    """``1 + max_i |ln sig_i|`` with the same floor as the kernels."""
    return 1 + np.abs(np.log(np.maximum(np.abs(sig), SINGULAR_VALUE_FLOOR))).max(axis=-1)
