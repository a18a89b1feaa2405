"""Crack-front and shear-test analyses on synthetic data with known answers (fronts, PST, shear test)."""

import math

import numpy as np
import pytest

from mpm_warp.materials import Elastic, hardening_collapse
from mpm_warp.scenes import fronts, references
from mpm_warp.scenes.pst import Front, PSTParams, Saw, pst_summary
from mpm_warp.scenes.shear_test import shear_summary
from mpm_warp.scenes.snow import Settle


# ----------------------------------------------------------------------------- references
def test_heierli_reproduces_model_example():
    # docs/model.md §6: E = 5 MPa, h = 0.5 m, h_f = 2 mm, rho = 200 gives about 34 m/s and 1.6 m
    assert references.heierli_speed(5e6, 0.5, 200.0, 0.002) == pytest.approx(33.6, abs=0.5)
    assert references.heierli_touchdown(5e6, 0.5, 200.0, 0.002) == pytest.approx(1.59, abs=0.05)
    # c^4 h_f = const and l^4 / h_f = const
    c1, c2 = references.heierli_speed(5e6, 0.5, 200.0, 0.002), references.heierli_speed(5e6, 0.5, 200.0, 0.032)
    assert c1 / c2 == pytest.approx(2.0, rel=1e-12)
    assert references.heierli_speed(5e6, 0.5, 200.0, 0.0) == math.inf


def test_rayleigh_speed_model_example():
    # docs/model.md §7: E = 5 MPa, nu = 0.3, rho = 250: c_s 88, c_R 81 m/s
    assert Elastic(5e6, 0.3, 250.0).rayleigh_speed == pytest.approx(81.2, abs=0.3)


def test_critical_cut_length_formula():
    a = references.critical_cut_length_formula(500.0, 5e6, 0.3, 0.02, 2e5, 250.0)
    assert a == pytest.approx(math.sqrt(2 * 500 * 5e6 / 0.91 * 0.02 / (2e5 * 250 * 9.81)), rel=1e-12)


def test_hardening_collapse_law():
    K, xi = 8e5, 0.005
    assert hardening_collapse(1000.0, K, xi) == pytest.approx(1 - math.exp(-math.asinh(1000 / K) / xi))
    assert hardening_collapse(1000.0, K, xi, p0_ini=2000.0) == 0.0
    # small p: 1 - J_P ~ p / (xi K)
    assert hardening_collapse(1.0, K, xi) == pytest.approx(1.0 / (xi * K), rel=1e-3)


# ----------------------------------------------------------------------------- fronts
def test_collapse_fraction_sign():
    c = fronts.collapse_fraction([-0.2, 0.0, 0.1], [0.0, 0.0, 0.0])
    assert c[0] == pytest.approx(1 - math.exp(-0.2)) and c[1] == 0.0 and c[2] < 0


def test_front_from_synthetic_collapse_field():
    rng = np.random.default_rng(0)
    s = rng.uniform(0.0, 3.0, 20000)  # particles along the column
    s_front = 1.234
    collapse = np.where(s < s_front, 0.2, 0.0) + rng.normal(0.0, 0.005, s.size)
    failed = collapse >= 0.05
    bw = 0.02
    f = fronts.front_position(s, failed, bw, length=3.0)
    assert abs(f - s_front) <= bw
    # an isolated collapsed patch ahead of the front is not connected: the front stays
    failed2 = failed | ((s > 2.5) & (s < 2.6))
    assert fronts.front_position(s, failed2, bw, length=3.0) == f
    # nothing failed at the cut end: front 0
    assert fronts.front_position(s, s > 1.0, bw, length=3.0) == 0.0


def test_front_from_arrival_times():
    bw, c, t0 = 0.05, 25.0, 0.1
    s = (np.arange(60) + 0.5) * bw
    arrival = t0 + s / c
    arrival[40:] = np.inf  # arrested at bin 40
    assert fronts.front_from_arrival(arrival, t0 - 1e-3, bw) == 0.0
    t = t0 + 1.0 / c
    assert abs(fronts.front_from_arrival(arrival, t, bw) - 1.0) <= bw
    assert fronts.front_from_arrival(arrival, 10.0, bw) == pytest.approx(40 * bw)


def test_steady_speed_of_known_linear_front():
    t = np.linspace(0.0, 0.3, 301)
    front = np.clip(40.0 * (t - 0.1), 0.0, 5.0)  # starts at 0.1 s, 40 m/s, stops at the column end
    front += np.random.default_rng(1).normal(0, 1e-3, t.size) * (front > 0)
    fit = fronts.steady_speed(t, front, 1.0, 4.0)
    assert fit.speed == pytest.approx(40.0, rel=2e-3)
    assert fit.r2 > 0.999 and fit.n > 50
    # an arrested front (repeated values) does not bias the fit
    f2 = np.minimum(40.0 * np.clip(t - 0.1, 0, None), 3.0)
    assert fronts.steady_speed(t, f2, 0.5, 3.0).speed == pytest.approx(40.0, rel=1e-9)
    assert math.isnan(fronts.steady_speed(t[:2], front[:2], 0, 5).speed)


def test_arrival_speed():
    s = np.linspace(0.0, 5.0, 251)
    t = 0.2 + s / 31.0
    t[200:] = np.inf
    fit = fronts.arrival_speed(s, t, 1.0, 4.5)
    assert fit.speed == pytest.approx(31.0, rel=1e-9)
    assert fit.intercept == pytest.approx(0.2, rel=1e-9)


def test_touchdown_from_synthetic_profile():
    # slab-base deflection: collapse height behind the touchdown point, smooth rise to 0 at the front
    h, l, s_f = 0.004, 1.3, 3.7
    s = np.arange(0.05, 5.0, 0.1)
    x = np.clip((s_f - s) / l, 0.0, 1.0)
    w = h * (3 * x**2 - 2 * x**3)  # 0 at the front, h (zero slope) at touchdown
    td = fronts.touchdown_distance(s, w, s_f, w_collapsed=h, level=0.999)
    assert td == pytest.approx(l, abs=0.05)
    # default collapse estimate (90th percentile behind the front) and 95 % level
    td95 = fronts.touchdown_distance(s, w, s_f)
    x95 = 0.5 + math.cos((math.acos(1 - 2 * 0.95) + 4 * math.pi) / 3)  # 3x^2 - 2x^3 = 0.95
    assert td95 == pytest.approx(l * x95, abs=0.06)
    assert math.isnan(fronts.touchdown_distance(s, 0 * w, s_f))


def test_marker_displacements():
    x0 = np.array([[0.0, 0.5, 0.0], [1.0, 0.5, 0.0], [2.0, 0.5, 0.0]])
    frames = np.stack([x0, x0 + [0.0, -0.01, 0.0]])
    u = fronts.marker_displacements(frames, x0, [[1.1, 0.5], [1.9, 0.4]])
    assert u.shape == (2, 2, 3)
    assert u[1, :, 1] == pytest.approx([-0.01, -0.01])


# ----------------------------------------------------------------------------- bisection
def test_bisection_on_monotone_predicate():
    calls = []

    def pred(a):
        calls.append(a)
        return a >= 0.3137

    b = fronts.bisect_threshold(pred, 0.0, 1.0, 1e-3)
    assert b.lo < 0.3137 <= b.hi and b.hi - b.lo <= 1e-3
    assert b.value == pytest.approx(0.3137, abs=1e-3)
    assert len(calls) == len(b.evaluations) <= 2 + math.ceil(math.log2(1.0 / 1e-3))
    with pytest.raises(ValueError):
        fronts.bisect_threshold(pred, 0.5, 1.0, 1e-3)  # threshold below the bracket
    c = fronts.critical_cut_length(lambda a: a > 0.42, 0.0, 1.0, tol=0.01)
    assert c.value == pytest.approx(0.42, abs=0.01)


# ----------------------------------------------------------------------------- shear test
def test_shear_summary_on_synthetic_curve():
    tau_p, tau_r, u_p, delta = 800.0, 300.0, 0.5e-3, 2e-3
    u = np.linspace(0.0, 8e-3, 1601)
    tau = np.where(u < u_p, tau_p * u / u_p,
                   np.where(u < u_p + delta, tau_p - (tau_p - tau_r) * (u - u_p) / delta, tau_r))
    axial = 0.2 * np.clip((u - u_p) / delta, 0.0, 1.0)
    sm = shear_summary(u, tau, axial)
    assert sm.peak_stress == pytest.approx(tau_p, rel=1e-3)
    assert sm.peak_displacement == pytest.approx(u_p, abs=1e-5)
    assert sm.residual_stress == pytest.approx(tau_r, rel=1e-9)
    assert sm.softening_displacement == pytest.approx(0.9 * delta, rel=1e-3)  # into the 10 % band
    assert sm.drop_displacement == pytest.approx(0.9 * delta, rel=1e-3)
    assert sm.collapse_fraction == pytest.approx(0.2)
    # brittle drop below the residual, sliding at low stress, recovery to the residual (collapse)
    tau2 = np.where(u < u_p, tau_p * u / u_p, np.where(u < u_p + delta, 20.0, tau_r))
    sm2 = shear_summary(u, tau2, axial)
    assert sm2.drop_displacement == pytest.approx(u[1] - u[0], rel=1e-6)  # one sample after the peak
    assert sm2.softening_displacement == pytest.approx(delta, abs=2 * (u[1] - u[0]))
    # failure, collapse at a low stress, then a collapsed layer hardening above the intact peak
    tau3 = np.where(u < u_p, tau_p * u / u_p, np.where(u < u_p + delta, 20.0, 1.2 * tau_p))
    sm3 = shear_summary(u, tau3, axial)
    assert sm3.peak_stress == pytest.approx(tau_p, rel=0.02) and sm3.residual_stress == pytest.approx(1.2 * tau_p)
    assert sm3.softening_displacement == pytest.approx(delta, abs=2 * (u[1] - u[0]))
    # no softening: nan
    assert math.isnan(shear_summary(u, tau_p * u / u[-1], axial).softening_displacement)


# ----------------------------------------------------------------------------- PST summary
def _synthetic_pst(c=30.0, l_td=1.2, h=0.004, reverse=False, lead=0.0):
    """Parameters, frame series and bin arrival times of an ideal PST: the saw (1 m/s from t = 0.1 s) cuts
    0.4 m, the damage front runs at ``c`` from the cut once the blade stops (t0 = 0.5 s) and the slab
    deflects behind it (reaching the deflection threshold ``lead`` metres behind the damage)."""
    L, cut, bw, t0 = 6.0, 0.4, 0.02, 0.5
    scene = PSTParams(length=L, dx=0.005, settle=Settle(gravity_ramp=0.05, duration=0.1),
                      saw=Saw(speed=1.0, cut_length=cut, cut_from="upslope"), front=Front(bin=bw))
    assert scene.saw_end == pytest.approx(t0)
    t = np.arange(0.0, 0.8, 0.002)
    sb = (np.arange(int(L / bw)) + 0.5) * bw
    saw_t = 0.1 + sb / 1.0
    if reverse:  # everything beyond the cut fails from the far end towards the saw
        tb = np.where(sb <= cut, saw_t, t0 + (L - sb) / c)
    else:
        tb = np.where(sb <= cut, saw_t, t0 + (sb - cut) / c)
    td = tb + lead / c
    deflection = np.array([fronts.front_from_arrival(td, ti, bw) for ti in t])
    td_series = np.where(deflection > cut + 4 * bw, l_td, np.nan)
    series = {"front": np.array([fronts.front_from_arrival(tb, ti, bw) for ti in t]),
              "deflection_front": deflection, "touchdown": td_series, "collapse_height": np.full(t.size, h)}
    return scene, t, series, sb, tb, td


def test_pst_summary_on_ideal_front():
    scene, t, series, sb, tb, td = _synthetic_pst()
    out = pst_summary(scene, scene.calibrated(), t, series, sb, tb, td)
    assert out["damage_speed_mean"] == pytest.approx(30.0, rel=1e-3)
    assert out["deflection_speed_mean"] == pytest.approx(30.0, rel=1e-3)
    assert out["speed"] == out["damage_speed_mean"] and out["front_agreement"] == pytest.approx(1.0, rel=1e-3)
    assert out["damage_speed_mean_over"] == [0.4, 3.4]
    prof = out["damage_speed_profile"]
    assert np.allclose(prof["speed"], 30.0, rtol=1e-3) and prof["s"][0] == pytest.approx(0.4 + 0.25)
    assert out["damage_speed_max"] == pytest.approx(30.0, rel=1e-3)
    assert out["propagated"] and out["ran_to_end"]
    assert out["damage_front_final"] == pytest.approx(6.0)
    # the crack ran away from the blade as it stopped: the lead of 0.3 m was reached with the blade at 0.4 m
    assert out["runaway_cut"] == pytest.approx(0.4)
    assert out["max_damage_lead"] <= 0.02      # no bin damaged ahead of the contiguous front
    assert out["touchdown"] == pytest.approx(1.2) and out["collapse_height"] == 0.004
    assert out["heierli_speed_run"] == pytest.approx(
        references.heierli_speed(scene.slab.E, scene.slab_thickness, scene.slab.density, 0.004))


def test_pst_summary_lagging_deflection_and_an_arrest():
    scene, t, series, sb, tb, td = _synthetic_pst(lead=0.5)
    out = pst_summary(scene, scene.calibrated(), t, series, sb, tb, td)
    assert out["deflection_speed_mean"] == pytest.approx(30.0, rel=1e-3)   # a constant lag: the same speed
    tb2 = np.where(sb <= 1.5, tb, np.inf)                                   # arrested at 1.5 m
    out2 = pst_summary(scene, scene.calibrated(), t, series, sb, tb2, td)
    assert not out2["propagated"] and not out2["ran_to_end"]
    assert out2["damage_front_final"] == pytest.approx(1.5, abs=0.02) and math.isnan(out2["speed"])


def test_pst_summary_flags_a_crack_started_elsewhere():
    scene, t, series, sb, tb, td = _synthetic_pst(c=150.0, reverse=True)
    out = pst_summary(scene, scene.calibrated(), t, series, sb, tb, td)
    assert out["max_damage_lead"] > 4.0 and out["max_damage_lead_at"] > 5.0
