"""Hencky St Venant-Kirchhoff elasticity (docs/model.md §1).

Tolerances: principal stresses and energies agree with float64 NumPy to a
relative ``16 u (1 + |eps|)`` of the stress scale ``(2 mu + 3 lam)``
(``u = 2^-24`` float32, ``2^-53`` float64); the full tensor built from
``wp.svd3`` to ``1e-4`` (float32) and ``1e-11`` (float64) of
``(2 mu + 3 lam)(1 + |eps|)``: the SVD runs a fixed number of Jacobi sweeps,
worst seen 640 u (float32) and 2500 u (float64) on 500 random ``F``.
"""

import functools

import numpy as np
import pytest
import warp as wp
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

from mpm_warp.kernels.elasticity import clamp_singular_func, hencky_energy_func, hencky_func
from mpm_warp.kernels.types import mat33, vec3

TYPES = {"float32": (wp.float32, np.float32, 2.0**-24), "float64": (wp.float64, np.float64, 2.0**-53)}
S_FLOOR = 1e-6


@functools.cache
def _probe(T):
    v3, m33 = vec3(T), mat33(T)
    hencky, energy, clamp = hencky_func(T), hencky_energy_func(T), clamp_singular_func(T)

    @wp.kernel(enable_backward=False)
    def probe(sig: wp.array(dtype=v3), F: wp.array(dtype=m33), par: wp.array2d(dtype=T),
              tau_p: wp.array(dtype=v3), psi: wp.array(dtype=T), clamped: wp.array(dtype=v3),
              tau: wp.array(dtype=m33)):
        i = wp.tid()
        mu, lam, sf = par[i, 0], par[i, 1], par[i, 2]
        tau_p[i] = hencky(sig[i], mu, lam, sf)
        psi[i] = energy(sig[i], mu, lam, sf)
        clamped[i] = clamp(sig[i], sf)
        U, s, V = wp.svd3(F[i])
        tau[i] = U * wp.diag(hencky(s, mu, lam, sf)) * wp.transpose(U)

    return probe


def run(dtype, sig, F, mu, lam):
    T, nt, _ = TYPES[dtype]
    n = len(sig)
    par = np.stack([mu, lam, np.full(n, S_FLOOR)], axis=1)
    ins = [wp.array(np.asarray(sig, nt), dtype=vec3(T), device=DEVICE),
           wp.array(np.asarray(F, nt), dtype=mat33(T), device=DEVICE),
           wp.array(par.astype(nt), dtype=T, device=DEVICE)]
    outs = [wp.zeros(n, dtype=vec3(T), device=DEVICE), wp.zeros(n, dtype=T, device=DEVICE),
            wp.zeros(n, dtype=vec3(T), device=DEVICE), wp.zeros(n, dtype=mat33(T), device=DEVICE)]
    wp.launch(_probe(T), dim=n, inputs=ins, outputs=outs, device=DEVICE)
    return [o.numpy().astype(np.float64) for o in outs]


def hencky_np(sig, mu, lam):
    eps = np.log(np.maximum(sig, S_FLOOR))
    tr = eps.sum(axis=-1, keepdims=True)
    return 2 * mu[:, None] * eps + lam[:, None] * tr, mu * (eps**2).sum(-1) + 0.5 * lam * tr[:, 0] ** 2


def cases(n, seed=0):
    rng = np.random.default_rng(seed)
    E, nu = 10.0 ** rng.uniform(4, 9, n), rng.uniform(0.0, 0.45, n)
    mu, lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    sig = -np.sort(-rng.uniform(0.3, 2.0, (n, 3)), axis=1)
    F = rng.normal(0.0, 0.3, (n, 3, 3)) + np.eye(3)
    F[np.linalg.det(F) < 0, :, 0] *= -1  # det F > 0
    return sig, F, mu, lam


@pytest.mark.parametrize("dtype", list(TYPES))
def test_principal_stress_and_energy_closed_form(dtype):
    u = TYPES[dtype][2]
    sig, F, mu, lam = cases(1000)
    tau_p, psi, clamped, _ = run(dtype, sig, F, mu, lam)
    ref_tau, ref_psi = hencky_np(np.asarray(sig, TYPES[dtype][1]).astype(np.float64), mu, lam)
    eps_max = np.abs(np.log(sig)).max(1)
    scale = 16 * u * (1 + eps_max) * (2 * mu + 3 * lam)
    assert np.all(np.abs(tau_p - ref_tau) <= scale[:, None])
    assert np.all(np.abs(psi - ref_psi) <= scale * (1 + eps_max) + 16 * u * ref_psi)
    assert np.all(psi >= 0)
    np.testing.assert_array_equal(clamped, np.asarray(sig, TYPES[dtype][1]))


@pytest.mark.parametrize("dtype", list(TYPES))
def test_floor_gives_finite_compressive_stress(dtype):
    nt = TYPES[dtype][1]
    sig = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, -0.5], [1.0, 1.0, 1e-9], [1.0, 1.0, S_FLOOR],
                    [1e-12, 1e-12, -1e-12], [1.0, 1.0, 1.0]])
    n = len(sig)
    mu, lam = np.full(n, 4e5), np.full(n, 6e5)
    tau_p, psi, clamped, _ = run(dtype, sig, np.tile(np.eye(3), (n, 1, 1)), mu, lam)
    assert np.all(np.isfinite(tau_p)) and np.all(np.isfinite(psi))
    for i in (0, 1, 2):  # floored: identical to the stress at the floor
        np.testing.assert_array_equal(tau_p[i], tau_p[3])
        assert clamped[i, 2] == np.asarray(S_FLOOR, nt)
    ln_f = np.log(S_FLOOR)
    np.testing.assert_allclose(tau_p[3], [lam[0] * ln_f, lam[0] * ln_f, (2 * mu[0] + lam[0]) * ln_f], rtol=1e-6)
    np.testing.assert_allclose(tau_p[4], (2 * mu[0] + 3 * lam[0]) * ln_f, rtol=1e-6)
    assert np.all(tau_p[:5, 2] < -1e6)  # strongly compressive
    assert np.all(tau_p[5] == 0) and psi[5] == 0


def test_energy_derivative_is_stress():
    """d psi / d eps_i = tau_i (central differences in float64)."""
    sig, F, mu, lam = cases(200, seed=1)
    h = 1e-6
    tau_p, _, _, _ = run("float64", sig, F, mu, lam)
    for i in range(3):
        step = np.zeros(3)
        step[i] = h
        psi_p = run("float64", sig * np.exp(step), F, mu, lam)[1]
        psi_m = run("float64", sig * np.exp(-step), F, mu, lam)[1]
        np.testing.assert_allclose((psi_p - psi_m) / (2 * h), tau_p[:, i], rtol=1e-6,
                                   atol=1e-6 * np.abs(tau_p).max())


@pytest.mark.parametrize("dtype,tol", [("float32", 1e-4), ("float64", 1e-11)])
def test_kirchhoff_tensor_from_svd(dtype, tol):
    """tau = U diag(tau_i) U^T equals 2 mu ln V + lam tr(ln V) I, V = sqrt(F F^T); R F gives R tau R^T."""
    sig, F, mu, lam = cases(500, seed=2)
    _, _, _, tau = run(dtype, sig, F, mu, lam)
    w, Q = np.linalg.eigh(np.einsum("pij,pkj->pik", F, F))
    lnV = np.einsum("pij,pj,pkj->pik", Q, 0.5 * np.log(w), Q)
    ref = 2 * mu[:, None, None] * lnV + (lam * np.trace(lnV, axis1=1, axis2=2))[:, None, None] * np.eye(3)
    scale = ((2 * mu + 3 * lam) * (1 + np.abs(np.log(w)).max(axis=1)))[:, None, None]
    assert np.all(np.abs(tau - ref) <= tol * scale)
    R, _ = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))
    R *= np.sign(np.linalg.det(R))
    _, _, _, tau_r = run(dtype, sig, np.einsum("ij,pjk->pik", R, F), mu, lam)
    assert np.all(np.abs(tau_r - np.einsum("ij,pjk,lk->pil", R, tau, R)) <= 2 * tol * scale)
