"""The bonded Cam-Clay return of independent principal states, for the tests (kernels/bonded_camclay.py).

As ``tests/helpers_camclay.py``: singular values in, their principal Hencky strains
``ln max(s, SINGULAR_VALUE_FLOOR)`` through the engine's ``bonded_camclay_return_strain``, the new state as
singular values ``exp(eps_new)``, with ``p, q`` and the yield function at the *new* state. The units of the
yield residual, ``Y_u``, are explained in ``tests/test_bonded_camclay.py``.
"""

import functools

import numpy as np
import warp as wp
from helpers_camclay import TYPES, strain_size
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

from mpm_warp.kernels.bonded_camclay import bonded_camclay_return_strain_func, bonded_p0_func, bonded_yield_func
from mpm_warp.kernels.camclay import SINGULAR_VALUE_FLOOR, camclay_pq_func
from mpm_warp.kernels.types import vec3
from mpm_warp.material_point import lame_parameters

PARAMS = ("mu", "lam", "M", "beta", "xi", "p0_floor", "p_bond", "kappa_s")


@functools.cache
def _probe(T):
    """Kernel: return of independent states; new p, q, p0, bond and y at the new state."""
    v3 = vec3(T)
    ret, pq = bonded_camclay_return_strain_func(T), camclay_pq_func(T)
    p0f, yf = bonded_p0_func(T), bonded_yield_func(T)
    s_floor = SINGULAR_VALUE_FLOOR

    @wp.kernel(enable_backward=False)
    def probe(sig: wp.array(dtype=v3), state: wp.array2d(dtype=T), par: wp.array2d(dtype=T),
              sig_out: wp.array(dtype=v3), flag: wp.array(dtype=wp.int32), res: wp.array2d(dtype=T)):
        i = wp.tid()
        mu, lam, M, beta, xi, pf, pb, ks = (par[i, 0], par[i, 1], par[i, 2], par[i, 3], par[i, 4], par[i, 5],
                                            par[i, 6], par[i, 7])
        s = sig[i]
        sf = T(s_floor)
        eps = v3(wp.log(wp.max(s[0], sf)), wp.log(wp.max(s[1], sf)), wp.log(wp.max(s[2], sf)))
        e2, l2, k2, y = ret(eps, state[i, 0], state[i, 1], mu, lam, M, beta, xi, pf, pb, ks)
        s2 = s
        if y != 0:
            s2 = v3(wp.exp(e2[0]), wp.exp(e2[1]), wp.exp(e2[2]))
        sig_out[i] = s2
        flag[i] = y
        K = lam + T(2.0) / T(3.0) * mu
        p0, b = p0f(l2, k2, K, xi, pf, pb, ks)
        p, q = pq(s2, mu, lam)
        res[i, 0] = l2
        res[i, 1] = k2
        res[i, 2] = p
        res[i, 3] = q
        res[i, 4] = p0
        res[i, 5] = b
        res[i, 6] = yf(p, q, l2, k2, K, M, beta, xi, pf, pb, ks)

    return probe


def run_return(sig, ljp, kap, c, dtype):
    """Run the probe; dict of float64 arrays (``sig_raw`` in the kernel's type)."""
    T, nt, _ = TYPES[dtype]
    n = len(sig)
    par = np.stack([c[k] for k in PARAMS], axis=1)
    outs = [wp.zeros(n, dtype=vec3(T), device=DEVICE), wp.zeros(n, dtype=wp.int32, device=DEVICE),
            wp.zeros((n, 7), dtype=T, device=DEVICE)]
    wp.launch(_probe(T), dim=n, inputs=[wp.array(np.asarray(sig, nt), dtype=vec3(T), device=DEVICE),
                                        wp.array(np.stack([ljp, kap], 1).astype(nt), dtype=T, device=DEVICE),
                                        wp.array(par.astype(nt), dtype=T, device=DEVICE)],
              outputs=outs, device=DEVICE)
    s, flag, res = (o.numpy() for o in outs)
    r = {k: res[:, i].astype(np.float64) for i, k in enumerate(("ljp", "kappa", "p", "q", "p0", "b", "y"))}
    return r | {"sig_raw": s, "sig": s.astype(np.float64), "flag": flag}


def random_cases(n, seed=0):
    """Random parameters and trial states: E 1e4-1e8 Pa, nu 0-0.45, M 0.5-2, beta 0-1, xi 0.1-10,
    p_bond 1e-4 to 1e-1 K, kappa_s (a work, J/m^3) p_bond times 1e-3 to 0.3; bonds intact, partly gone and gone;
    trials near and far."""
    rng = np.random.default_rng(seed)
    E, nu = 10.0 ** rng.uniform(4, 8, n), rng.uniform(0.0, 0.45, n)
    mu, lam, K = lame_parameters(E, nu)
    c = {"mu": mu, "lam": lam, "K": K, "M": rng.uniform(0.5, 2.0, n), "beta": rng.uniform(0.0, 1.0, n),
         "xi": rng.uniform(0.1, 10.0, n), "p0_floor": 1e-5 * K, "p_bond": K * 10.0 ** rng.uniform(-4, -1, n),
         "kappa_s": None}
    c["kappa_s"] = c["p_bond"] * 10.0 ** rng.uniform(-3, -0.5, n)
    ljp = rng.uniform(-0.5, 0.5, n)
    kap = c["kappa_s"] * np.choose(np.arange(n) % 4, [np.zeros(n), rng.uniform(0, 0.5, n), rng.uniform(0.5, 1, n),
                                                      rng.uniform(1, 2, n)])
    p0 = np.maximum(K * np.sinh(c["xi"] * np.maximum(-ljp, 0.0)), c["p0_floor"]) + np.maximum(
        0.0, 1.0 - kap / c["kappa_s"]) * c["p_bond"]
    sig = np.exp(rng.normal(0.0, 1.0, (n, 3)) * np.minimum(p0 / K, 0.3)[:, None] * rng.uniform(0.3, 3.0, n)[:, None])
    k = np.arange(n) % 7
    sig[k == 3] = sig[k == 3][:, :1]  # three equal: q_tr = 0
    sig[k == 5, 1] = sig[k == 5, 0]  # two equal
    return -np.sort(-sig, axis=1), ljp, kap, c


def yield_scale(c, r, u, sig, sig_tr):
    """``Y_u`` (Pa^2) at the new state (module docstring): camclay's strain and ellipse terms plus the change
    of ``p0`` for a rounding of the state, ``|dp0/dL| u (1 + |L| + S) + (p_bond + beta p0)/kappa_s u k_u`` (the bond
    moves ``p0`` and the tensile tip ``-beta b p0``); ``kappa`` is a
    work, rounded as its stresses (``u K S`` from the strains) times the plastic increment ``|d|``:
    ``k_u = kappa + (|p| + q + (K + 3 mu) S) |d|``."""
    M, K, b = c["M"], c["K"], r["b"]
    beta_e, p0, L, S = c["beta"] * b, r["p0"], r["ljp"], strain_size(sig)
    x = c["xi"] * np.maximum(-L, 0.0)
    slope = np.where(K * np.sinh(x) > c["p0_floor"], K * c["xi"] * np.cosh(x), 0.0)
    ln = np.log(np.maximum(np.abs(np.asarray(sig_tr, dtype=np.float64)), SINGULAR_VALUE_FLOOR))
    d = np.linalg.norm(ln - np.log(np.maximum(np.abs(sig), SINGULAR_VALUE_FLOOR)), axis=-1)
    k_u = r["kappa"] + (np.abs(r["p"]) + r["q"] + (K + 3 * c["mu"]) * S) * d
    # the bond moves p0 by p_bond db and the tensile tip -beta b p0 by beta p0 db, db = k_u / kappa_s
    dp0 = slope * (1 + np.abs(L) + S) + np.where(b > 0, (c["p_bond"] + c["beta"] * p0) / c["kappa_s"], 0.0) * k_u
    return M * p0 * (1 + beta_e) * u * ((M * K + np.sqrt(6 * (1 + 2 * beta_e)) * c["mu"]) * S
                                        + M * p0 * (1 + beta_e) + 2 * M * dp0)
