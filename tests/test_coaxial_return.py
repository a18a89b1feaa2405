"""The return without a decomposition equals the principal-strain return (kernels/constitutive.py).

A yielding trial whose series strain applies (``|F F^T - I|_F <= 0.1``, ``det F > 0``)
takes the return on the invariants of ``eps`` and ``F_new = exp(eps_new - eps) F_tr``;
the reference is the same update built with ``decomposition_free=False``, which
takes the eigen-decomposition for every yielding trial. Both must give the same
new state, stress, hardening and bond to rounding, on yielding and elastic states,
2D and 3D, float32 and float64, Cam-Clay and the bonded weak layer, and on the edge
cases: repeated principal strains (pure volumetric and axisymmetric trials, where
the direction of ``dev eps`` is undefined or degenerate), tiny strains (a trial of
1e-8 projected onto a floored ellipse), and the inversion floor (``det F <= 0``:
both take the SVD path, bit for bit the same).

Tolerances are rounding-level: the two paths compute the strain by different
algorithms (series, Jacobi eigenvalues), each good to a few rounding units of
``|X|``; measured worst differences are listed with each assertion.
"""


import numpy as np
import pytest
import warp as wp
from helpers_validation import DEVICE

import mpm_warp as mw
from mpm_warp.kernels.constitutive import FLOORED, INVERTED, YIELDED, constitutive_update_func, material_struct
from mpm_warp.kernels.types import mat
from mpm_warp.model import material_params

SNOW = mw.CamClaySnow(1.0e6, 0.3, 200.0, M=1.2, beta=0.3, xi=0.5, p0_ini=800.0)
LAYER = mw.BondedCamClay(1.0e6, 0.3, 150.0, M=1.2, beta=0.3, xi=0.01, p_bond=1500.0, kappa_s=20.0)  # J/m^3
TYPES = {"float32": (wp.float32, np.float32), "float64": (wp.float64, np.float64)}
#: rounding unit per precision
U = {"float32": 2.0**-24, "float64": 2.0**-53}
#: tolerances in rounding units of each quantity's scale (``_errors``), beyond the principal-strain path's own error
#: (float64 worst measured: H 2.8, tau 31, log_jp 51, kappa 5.6; heavy projections onto small ellipses amplify
#: the rounding of the trial)
TOL_U = {"H": 16, "hzz": 16, "tau": 128, "log_jp": 128, "kappa": 128}


def _kernel(dim, T, model, decomposition_free):
    M = mat(dim, T)
    P = material_struct(T)
    update = constitutive_update_func(dim, T, model, decomposition_free)

    @wp.kernel(enable_backward=False, module="unique")
    def k(H: wp.array(dtype=M), hzz: wp.array(dtype=T), lj: wp.array(dtype=T), kap: wp.array(dtype=T), m: P,
          H_out: wp.array(dtype=M), hzz_out: wp.array(dtype=T), tau_out: wp.array(dtype=M),
          lj_out: wp.array(dtype=T), kap_out: wp.array(dtype=T), flags_out: wp.array(dtype=wp.int32)):
        i = wp.tid()
        if wp.static(dim == 2):
            H_new, hzz_new, tau, lj_new, kap_new, flags = update(H[i], hzz[i], lj[i], kap[i], m)
            hzz_out[i] = hzz_new
        else:
            H_new, tau, lj_new, kap_new, flags = update(H[i], lj[i], kap[i], m)
        H_out[i] = H_new
        tau_out[i] = tau
        lj_out[i] = lj_new
        kap_out[i] = kap_new
        flags_out[i] = flags

    return k


def _update(dim, precision, material, H, hzz, lj, kap, decomposition_free):
    T, nt = TYPES[precision]
    M = mat(dim, T)
    n = len(H)
    ins = [wp.array(H.astype(nt), dtype=M, device=DEVICE), wp.array(hzz.astype(nt), dtype=T, device=DEVICE),
           wp.array(lj.astype(nt), dtype=T, device=DEVICE), wp.array(kap.astype(nt), dtype=T, device=DEVICE),
           material_params(material, T)]
    outs = [wp.zeros(n, dtype=M, device=DEVICE), wp.zeros(n, dtype=T, device=DEVICE),
            wp.zeros(n, dtype=M, device=DEVICE), wp.zeros(n, dtype=T, device=DEVICE),
            wp.zeros(n, dtype=T, device=DEVICE), wp.zeros(n, dtype=wp.int32, device=DEVICE)]
    wp.launch(_kernel(dim, T, material.model, decomposition_free), n, inputs=ins, outputs=outs, device=DEVICE)
    names = ("H", "hzz", "tau", "log_jp", "kappa", "flags")
    return {k: a.numpy().astype(np.int64 if k == "flags" else np.float64) for k, a in zip(names, outs, strict=True)}


def _both(dim, precision, material, H, hzz, lj, kap):
    """Decomposition-free update, principal-strain update (both in ``precision``) and the float64 principal-strain
    update of the same (rounded) inputs, the reference."""
    nt = TYPES[precision][1]
    rounded = [np.asarray(a, dtype=nt).astype(np.float64) for a in (H, hzz, lj, kap)]
    return (_update(dim, precision, material, *rounded, True), _update(dim, precision, material, *rounded, False),
            _update(dim, "float64", material, *rounded, False), rounded)


def _rotations(dim, n, rng):
    """Random proper rotations (det +1)."""
    R, _ = np.linalg.qr(rng.normal(size=(n, dim, dim)))
    R[:, :, 0] *= np.sign(np.linalg.det(R))[:, None]
    return R


def _random_trials(dim, n, rng, scale):
    """Trial displacement gradients: random rotations of random stretches, ``|X|`` up to about ``scale``."""
    Q, _ = np.linalg.qr(rng.normal(size=(n, dim, dim)))
    e = rng.normal(size=(n, dim)) * scale / 2.0 - scale / 4.0   # compression-biased principal strains
    F = np.einsum("nij,nj,nkj->nik", Q, np.exp(e), Q)
    return np.einsum("nij,njk->nik", _rotations(dim, n, rng), F) - np.eye(dim)


def _series_applies(H):
    X = H + np.swapaxes(H, 1, 2) + H @ np.swapaxes(H, 1, 2)
    return (np.sqrt((X * X).sum(axis=(1, 2))) < 0.1 * (1 - 1e-4)) & (np.linalg.det(np.eye(H.shape[1]) + H) > 0)


def _errors(got, ref, inputs, material, which):
    """Largest errors of an update against the reference, in rounding units of the quantity's natural scale:
    ``H`` of ``|F_tr|``, ``h_zz`` of ``1 + h_zz``, ``tau`` of the trial stress ``(2 mu + 3 |lam|) |X| / 2``,
    ``log_jp`` of ``|log_jp| + |X|``, ``kappa`` (plastic work, J/m^3) of ``kappa`` plus the trial stress scale times
    ``|X|`` (``X = F_tr F_tr^T - I``, in plane strain with its out-of-plane entry ``(1 + h_zz)^2 - 1``)."""
    H, hzz, lj, kap = inputs
    dim = H.shape[1]
    F = np.eye(dim) + H
    X = np.sqrt(((F @ np.swapaxes(F, 1, 2) - np.eye(dim)) ** 2).sum(axis=(1, 2)) + ((1.0 + hzz) ** 2 - 1.0) ** 2)
    tau = (2.0 * material.mu + 3.0 * abs(material.lam)) * X / 2.0
    scales = {"H": np.abs(F).max(axis=(1, 2)), "hzz": 1.0 + np.abs(hzz), "tau": tau, "log_jp": np.abs(lj) + X,
              "kappa": kap + tau * X}
    out = {}
    for key, sc in scales.items():
        d = np.abs(got[key] - ref[key])
        if d.ndim == 3:
            d = d.max(axis=(1, 2))
        out[key] = float((d / sc)[which].max())
    return out


def _assert_agree(free, eig, ref, inputs, material, precision, which):
    """The same yield decisions as the principal-strain update in the same precision (a state within rounding of
    the yield surface may go either way: at most 1 in 1000), and, where both agree with the float64 reference, as
    close to it as the principal-strain update, to within a few rounding units (in float64 the principal-strain
    update is the reference; in float32 both carry float32's rounding of the return, the principal one also that
    of ``eig3``)."""
    assert (free["flags"] != eig["flags"])[which].mean() <= 1e-3
    which = which & (free["flags"] == ref["flags"]) & (eig["flags"] == ref["flags"])
    u = U[precision]
    e_free = {k: v / u for k, v in _errors(free, ref, inputs, material, which).items()}
    e_eig = {k: v / u for k, v in _errors(eig, ref, inputs, material, which).items()}
    print(f"{precision}: errors in rounding units, decomposition-free {e_free}, principal {e_eig}")
    for key, tol in TOL_U.items():
        assert e_free[key] <= e_eig[key] + tol, (key, e_free[key], e_eig[key], tol)
    return e_free


@pytest.mark.slow
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("material", [SNOW, LAYER], ids=["camclay", "bonded"])
def test_decomposition_free_return_equals_the_principal_return(dim, precision, material):
    rng = np.random.default_rng(7)
    n = 4000
    H = _random_trials(dim, n, rng, np.geomspace(1e-4, 0.06, n)[:, None])
    hzz = np.expm1(rng.normal(size=n) * 0.01 - 0.005) if dim == 2 else np.zeros(n)
    lj = material.initial_log_jp + rng.normal(size=n) * 0.002
    kap = rng.uniform(0.0, 0.5 * getattr(material, "kappa_s", 0.0), size=n)
    a, b, ref, inputs = _both(dim, precision, material, H, hzz, lj, kap)
    series = _series_applies(inputs[0])
    yielded = (ref["flags"] & YIELDED) != 0
    assert (series & yielded).sum() > 0.3 * n and (series & ~yielded).sum() >= 40  # both kinds tested
    _assert_agree(a, b, ref, inputs, material, precision, series & yielded)
    # elastic states (inside the surface) and trials beyond the series: the very same computation
    same = ~series | ~yielded
    for key in ("H", "tau", "log_jp", "kappa", "flags"):
        np.testing.assert_array_equal(a[key][same], b[key][same])


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_repeated_principal_strains(dim, precision):
    """Pure volumetric trials beyond the cap and axisymmetric ones (two equal principal strains)."""
    rng = np.random.default_rng(3)
    vol = [h * np.eye(dim) for h in (-0.02, -0.01, -0.004, 0.003)]         # dev eps = 0: projected onto the axis
    R = _rotations(dim, 6, rng)
    axi = [R[k] @ np.diag([np.exp(-0.03), *[np.exp(0.004)] * (dim - 1)]) @ R[k].T - np.eye(dim) for k in range(6)]
    H = np.array(vol + axi)
    n = len(H)
    hzz = np.zeros(n)
    if dim == 2:   # out of plane as in plane: three equal principal strains; the axisymmetric ones take the pair
        hzz[:len(vol)] = [v[0, 0] for v in vol]
        hzz[len(vol):] = np.expm1(0.004)
    lj = np.full(n, SNOW.initial_log_jp)
    a, b, ref, inputs = _both(dim, precision, SNOW, H, hzz, lj, np.zeros(n))
    assert ((ref["flags"] & YIELDED) != 0).all()
    _assert_agree(a, b, ref, inputs, SNOW, precision, np.ones(n, dtype=bool))
    # a volumetric trial stays volumetric: no shear in the new state
    for k in range(len(vol)):
        off = a["tau"][k] - np.diag(np.diag(a["tau"][k]))
        assert np.abs(off).max() <= 64 * U[precision] * np.abs(a["tau"][k]).max()


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_tiny_strains_on_a_floored_ellipse(dim, precision):
    """A softened material (p0 at its floor, 1e-10 K): trials of 1e-8 to 1e-5 yield and are projected."""
    mat = mw.CamClaySnow(1.0e6, 0.3, 200.0, M=1.2, beta=0.3, xi=0.5, p0_ini=0.0, p0_floor_ratio=1e-10)
    rng = np.random.default_rng(5)
    n = 2000
    H = _random_trials(dim, n, rng, np.geomspace(1e-8, 1e-5, n)[:, None])
    hzz = np.zeros(n)
    a, b, ref, inputs = _both(dim, precision, mat, H, hzz, np.zeros(n), np.zeros(n))
    yielded = (ref["flags"] & YIELDED) != 0
    assert yielded.mean() > 0.9
    _assert_agree(a, b, ref, inputs, mat, precision, np.ones(n, dtype=bool))


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_inversion_floor_is_unchanged(dim, precision):
    """``det F <= 0``: the series declines, both updates take the SVD path with the floor, bit for bit."""
    flip = np.diag([-1.5, -0.02, -0.01][:dim])          # F = diag(-0.5, 0.98[, 0.99]): inverted
    crush = np.diag([-1.0 + 1e-7, -0.3, -0.2][:dim])    # a stretch of 1e-7, below the floor 1e-6
    H = np.array([flip, crush])
    n = len(H)
    a, b, _, _ = _both(dim, precision, SNOW, H, np.zeros(n), np.full(n, SNOW.initial_log_jp), np.zeros(n))
    assert (a["flags"] & FLOORED).all() and (a["flags"][0] & INVERTED)
    for key in ("H", "hzz", "tau", "log_jp", "flags"):
        np.testing.assert_array_equal(a[key], b[key])
