"""Weak-layer collapse under a slab against the hardening rule (docs/validation.md "Snow"; SI Note 3).

Set-up (:func:`weak_layer_column`)
----------------------------------
A quasi-1D column one cell square between frictionless (slip) side walls on a
sticky floor ``y = 0``: a Cam-Clay weak layer of thickness ``D_wl`` under an
elastic slab of thickness ``h`` and density ``rho_s``, loaded by gravity
ramped from 0 over ``ramp`` seconds. The slab weight is the load; ``p0`` is
varied through the slab density, as in the paper. The layer is laterally
confined: the loading is uniaxial strain (oedometric), not isotropic.

Closed form for this loading (derived here, docs/model.md §2-3)
---------------------------------------------------------
Under uniaxial strain with ``xi`` small the state leaves the elastic line
``q/p = 2 mu/K`` and settles on the cap at the point where the flow direction
``(dy/dp, dy/dq)`` is parallel to the imposed strain ``(eps_v, eps_q) = (1, 2/3)``:
that is the point of the ellipse where the axial stress ``tau_v = p + 2 q/3``
is largest (normality). Hence, on the cap,

    tau_v = lambda_oed p0,
    lambda_oed = [(1 - beta) + (1 + beta) sqrt(1 + 4 M^2 / (9 (1 + 2 beta)))] / 2

(1.0848 for M = 1, beta = 0.3: p0 = 0.922 tau_v, q/p = 0.259 instead of 0 in
isotropic compression). Because ``tau_v`` is stationary there, the O(xi) shift of
the state along the ellipse (elastic strains) changes ``p0 / tau_v`` only at
second order: the engine's own return under uniaxial strain
(:func:`oedometric_state`, float64) gives 0.92192, 0.92195, 0.92244 for
xi = 0.01, 0.04, 0.16 against 1/lambda_oed = 0.92187.

The yield surface is in Kirchhoff stress, ``tau = J sigma`` with the total
``J = J_E J_P`` (relative to the start), while the slab weight fixes the
Cauchy stress: ``sigma_v = W`` (weight per area above the point; the area is
fixed by the side walls). So ``tau_v = J W`` and the hardening rule (docs/model.md §3)
gives the collapse implicitly:

    1 - J_P = 1 - exp(-(asinh(p0 / K) - asinh(p0_ini / K)) / xi),
    p0 = J_E J_P W / lambda_oed,   J_E = exp(-p/K)

(:func:`oedometric_collapse`, solved by bisection). Dropping ``J`` (using the
Cauchy load) over-predicts the collapse by about the collapse itself (+10 % at
1 - J_P = 0.09, +37 % at 0.32); the isotropic formula of docs/model.md §6 with
``p = W`` (``lambda_oed = 1``, ``q = 0``, no ``J``) by +19 % and +45 %.

What each particle can assert exactly: ``log_Jp`` fixes ``p0`` through the
hardening rule, and a particle that yielded in its last step lies on the
ellipse of that ``p0``, so ``p0 = p0_ellipse(p, q)``
(:func:`consolidation_pressure`, any q), not ``p0 = p`` (only when q = 0).
After the load stops the state may sit inside (unloading is elastic), so
``p0_ellipse(p, q) <= K sinh(-xi log_Jp)`` always holds and equality holds up to
the explicit-hardening lag of one step.

Explicit hardening: ``p0`` comes from the previous ``log_Jp``, so the
collapse converges at first order in the number of plastic increments
(material-point driver: relative error 1.0e-2, 1.0e-3, 1.4e-4 after 1e2, 1e3,
1e4 increments); the column compacts over ~1e3 steps (2 cells across the
layer) to ~3e4 (32 cells), so this error is 1e-3 to 3e-5 here.

Findings (CPU; details in the tests and ``benchmarks/convergence/mesh_study.py``)
--------------------------------------------------------------------
* Interface cell: the layer under-compacts within about half a cell of the
  slab (one velocity field across a stiff/soft interface; the top particle
  row reaches ~0.3 of the closed form), the layer interior slightly over-
  compacts. Whole-layer 1 - J_P error: -18..-27 % at 2 cells across the layer,
  -5..-13 % at 4, -1.3..-5.7 % at 8, -0.3..-2.1 % at 16, -0.05..-0.5 % at 32;
  the interior converges to the closed form (|error| <= 0.2 % at 32 cells).
* float32 creep (engine issue, :func:`test_settled_layer_does_not_creep`): in
  float32 about 60 % of the settled layer's particles go through the Cam-Clay
  return every step (-log_Jp grows ~2.7e-7 each), float64: none. P2G rebuilds
  ``F_E = U diag(s_new) V^T`` from the float32 SVD whenever the return is
  active; the SVD round-off (worst for the two equal lateral singular values of
  a confined layer) puts the state back outside the ellipse the next step, so
  it ratchets. Applying the correction to the trial gradient instead,
  ``F_E = F_tr + F_tr V diag((s_new - s)/s) V^T`` (equal in exact arithmetic),
  removed it in a scratch copy of the engine: no returns while settled, the
  float32 collapse equal to float64 within 5e-6 (the float32 case below then
  passes; the slab tests still pass).

Measured (CPU, float32 unless noted) and tolerances: see the constants below.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

import mpm_warp as mw
from mpm_warp.camclay_forms import consolidation_pressure, hardening_collapse, oedometric_point, oedometric_ratio
from mpm_warp.validation import (
    measure_column,
    oedometric_collapse,
    oedometric_state,
    run_column,
    weak_layer_column,
)

G = 9.81


# set-ups and closed forms live in the library (mpm_warp.validation), shared with the benchmarks

# ---------------------------------------------------------------- tests
#: closed form against the engine's own return mapping at one material point (float64, 2e4 increments):
#: worst seen 7e-4 (xi = 0.16: the O(xi^2) shift of the uniaxial-strain state), else <= 2e-4
CLOSED_FORM_TOL = 2e-3
#: mean collapse of the layer against the closed form at 8 cells across it: -1.4 % (xi 0.04) and -0.6 %
#: (xi 0.02, p0_ini 200 Pa) measured, -1.3..-5.7 % over the mesh study's cases at 8 cells; the deficit is
#: the slab/layer interface cell (test_collapse_converges_with_dx); 3 % is twice the worst tested case
COLLAPSE_TOL = 0.03
#: mean Cauchy sigma_v of the layer against the overburden: -1.0 % and +0.6 % measured
EQUILIBRIUM_TOL = 0.02
#: p0 from log_Jp against the ellipse through the particle's (p, q): 1e-5 median measured
ON_CAP_TOL = 2e-3
#: geometric thickness change against D_wl (1 - mean J): +0.3 %, +0.6 % measured
THICKNESS_TOL = 0.03


@pytest.mark.parametrize("xi, p0_ini", [(0.01, 0.0), (0.04, 0.0), (0.16, 0.0), (0.04, 300.0), (0.02, 0.0)])
def test_oedometric_closed_form_matches_material_point(xi, p0_ini):
    """Uniaxial strain at one point (engine return, float64): collapse = closed form within 2e-3.

    float64 because the float32 driver drifts by about 1 % over 1e4-1e5 tiny
    increments (round-off rectified by the return mapping, see
    :func:`test_settled_layer_does_not_creep`). Also checks ``p0 = tau_v /
    lambda_oed`` and that the naive isotropic formula (``p = W``) and the
    formula without the Kirchhoff factor ``J`` would be far off.
    """
    mat = mw.CamClaySnow(2.0e5, 0.3, 150.0, M=1.0, beta=0.3, xi=xi, p0_ini=p0_ini)
    st = oedometric_state(mat, axial_strain=0.4 if xi < 0.03 else 0.12, n=20000)
    c = 1.0 - math.exp(-st["e"])
    J = math.exp(-st["p"] / mat.bulk) * (1.0 - c)  # J_E J_P with J_E = exp(tr eps) = exp(-p/K)
    W = st["tau_v"] / J  # the Cauchy load that holds this state
    closed = float(oedometric_collapse(W, mat)[0])
    print(f"xi {xi} p0_ini {p0_ini}: collapse {c:.5f}, closed form {closed:.5f} ({closed / c - 1:+.1e}); "
          f"p0/tau_v {st['p0'] / st['tau_v']:.5f} vs 1/lambda_oed {1 / oedometric_ratio(1.0, 0.3):.5f}")
    assert closed == pytest.approx(c, rel=CLOSED_FORM_TOL)
    assert st["p0"] / st["tau_v"] == pytest.approx(1.0 / oedometric_ratio(mat.M, mat.beta), rel=CLOSED_FORM_TOL)
    assert st["p0"] == pytest.approx(consolidation_pressure(st["p"], st["q"], mat.M, mat.beta), rel=1e-3)
    assert hardening_collapse(W, mat.bulk, xi, p0_ini) / c - 1.0 > 0.1  # isotropic formula with p = W
    assert hardening_collapse(W / oedometric_ratio(mat.M, mat.beta), mat.bulk, xi, p0_ini) / c - 1.0 > 0.04


def test_oedometric_ratio_closed_form():
    """lambda_oed = max (p + 2q/3)/p0 on the ellipse, by brute force over the ellipse; (p, q) is that point."""
    for M, beta in [(1.0, 0.3), (1.2, 0.0), (0.8, 1.0)]:
        p0 = 1.0
        t = np.linspace(0.0, math.pi, 200001)
        a = 0.5 * p0 * (1.0 + beta)
        p = 0.5 * p0 * (1.0 - beta) + a * np.cos(t)
        q = M * a / math.sqrt(1.0 + 2.0 * beta) * np.sin(t)
        k = np.argmax(p + 2.0 * q / 3.0)
        assert oedometric_ratio(M, beta) == pytest.approx(p[k] + 2.0 * q[k] / 3.0, rel=1e-9)
        assert oedometric_point(M, beta) == pytest.approx((p[k], q[k]), abs=1e-4)
        assert consolidation_pressure(p[k], q[k], M, beta) == pytest.approx(p0, rel=1e-9)
    assert oedometric_ratio(1.0, 0.3) == pytest.approx(1.08475, rel=1e-5)


@pytest.mark.slow
@pytest.mark.parametrize("xi, rho_slab, p0_ini", [(0.04, 1200.0, 0.0), (0.02, 2400.0, 200.0)])
def test_weak_layer_collapse_under_slab(xi, rho_slab, p0_ini):
    """Slab on a weak layer, 8 cells across it (float32): 1 - J_P and h_c against the closed form.

    xi 0.04, rho_s 1200 (W = 736 Pa + layer weight): collapse 0.0894 vs 0.0907 (-1.4 %), h_c 2.79 mm.
    xi 0.02, rho_s 2400, p0_ini 200 Pa: 0.2257 vs 0.2271 (-0.6 %), h_c 7.05 mm.
    """
    m, sim, info = run_column(dx=1.0 / 256.0, xi=xi, rho_slab=rho_slab, p0_ini=p0_ini)
    pp = m["per_particle"]
    err = m["collapse"] / m["collapse_theory"] - 1.0
    print(f"collapse {m['collapse']:.5f} vs {m['collapse_theory']:.5f} ({err:+.4f}); h_c {m['h_c'] * 1e3:.3f} mm; "
          f"sigma_v {m['sigma_v']:.1f} vs W {m['W_mean']:.1f} Pa; q/p {m['q_over_p']:.3f}; "
          f"steps {info['steps']}, {info['wall_time']:.1f} s")
    assert abs(err) < COLLAPSE_TOL
    assert m["h_c"] == pytest.approx(m["collapse_theory"] * info["D_wl"], rel=COLLAPSE_TOL)
    assert m["sigma_v"] == pytest.approx(m["W_mean"], rel=EQUILIBRIUM_TOL)
    assert m["thickness_change"] == pytest.approx(m["thickness_change_from_J"], rel=THICKNESS_TOL)
    # on the cap: p0(log_Jp) = p0 of the ellipse through (p, q); never outside the ellipse
    ratio = pp["p0_hard"] / pp["p0_ellipse"]
    assert abs(np.median(ratio) - 1.0) < ON_CAP_TOL
    assert ratio.min() > 1.0 - ON_CAP_TOL
    # uniaxial strain: p0 = tau_v / lambda_oed, not p0 = p (q/p = 0.26, not 0)
    assert m["p0_over_tau_v"] == pytest.approx(1.0 / oedometric_ratio(1.0, 0.3), rel=0.01)
    assert m["q_over_p"] > 0.15  # 0.265 in float64; the float32 creep lowers it (test_settled_layer_does_not_creep)


@pytest.mark.slow
def test_collapse_converges_with_dx():
    """The layer under-compacts in the cell it shares with the slab: the deficit falls with dx.

    xi 0.04, rho_s 1200: -11 % at 4 cells across the layer, -1.4 % at 8 (the
    top half-cell of particles compacts to ~0.3 of the closed form at 8 cells;
    the interior within a few %).
    """
    errs = []
    for dx in (1.0 / 128.0, 1.0 / 256.0):
        m, _, _ = run_column(dx=dx, xi=0.04, rho_slab=1200.0)
        errs.append(m["collapse"] / m["collapse_theory"] - 1.0)
    print(f"collapse error at 4 and 8 cells: {errs}")
    assert -0.2 < errs[0] < -0.05
    assert abs(errs[1]) < abs(errs[0]) / 3.0


@pytest.mark.slow
@pytest.mark.parametrize("precision", [
    "float32",
    "float64"])
def test_settled_layer_does_not_creep(precision):
    """Under a constant load the settled layer must stay put, in float32 as in float64.

    Guards the fix in kernels/p2g.py: F_E after an active return is written as a
    correction of F_tr instead of being rebuilt from the float32 SVD factors.

    xi 0.01, rho_s 2400 (collapse 0.38), 8 cells; the slab settles by t = 0.4 s.
    Between 0.5 and 0.9 s, float32 (measured): the slab sinks at ~3e-5 m/s,
    the collapse grows 0.3832 -> 0.3841 (+0.2 %) and q/p drifts 0.238 -> 0.217
    (0.15 by 1.8 s); float64: slab speed 1e-14 m/s, nothing changes, q/p stays
    at the uniaxial-strain value 0.259.
    """
    sc, mat, info = weak_layer_column(dx=1.0 / 256.0, xi=0.01, rho_slab=2400.0, precision=precision)
    sim = mw.Simulation(sc, device=DEVICE)
    sim.run(None, end_time=0.5, frame_interval=0.1)
    m1 = measure_column(sim, mat, info)
    sim.run(None, end_time=0.9, frame_interval=0.1)
    m2 = measure_column(sim, mat, info)
    print(f"{precision}: collapse {m1['collapse']:.6f} -> {m2['collapse']:.6f}, q/p {m1['q_over_p']:.4f} -> "
          f"{m2['q_over_p']:.4f} from 0.5 to 0.9 s")
    assert abs(m2["collapse"] / m1["collapse"] - 1.0) < 1e-4
    assert abs(m2["q_over_p"] - m1["q_over_p"]) < 1e-3
    p_k0, q_k0 = oedometric_point(mat.M, mat.beta)
    assert m2["q_over_p"] == pytest.approx(q_k0 / p_k0, rel=0.03)
    assert m2["p0_over_tau_v"] == pytest.approx(1.0 / oedometric_ratio(mat.M, mat.beta), rel=0.01)
