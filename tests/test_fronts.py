"""Crack-front and shear-test analyses on synthetic data with known answers (fronts, PST, shear test)."""

import math

import numpy as np
import pytest

from mpm_warp.materials import Elastic, hardening_collapse
from mpm_warp.scenes import fronts
from mpm_warp.scenes.pst import PSTParams, Saw, pst_summary, references
from mpm_warp.scenes.pst.params import Front
from mpm_warp.scenes.shear_test import shear_summary
from mpm_warp.scenes.snow import Settle


# ----------------------------------------------------------------------------- references
def test_heierli_reproduces_model_example():
    # MODEL.md 6: E = 5 MPa, h = 0.5 m, h_f = 2 mm, rho = 200 gives about 34 m/s and 1.6 m
    assert references.heierli_speed(5e6, 0.5, 200.0, 0.002) == pytest.approx(33.6, abs=0.5)
    assert references.heierli_touchdown(5e6, 0.5, 200.0, 0.002) == pytest.approx(1.59, abs=0.05)
    # c^4 h_f = const and l^4 / h_f = const
    c1, c2 = references.heierli_speed(5e6, 0.5, 200.0, 0.002), references.heierli_speed(5e6, 0.5, 200.0, 0.032)
    assert c1 / c2 == pytest.approx(2.0, rel=1e-12)
    assert references.heierli_speed(5e6, 0.5, 200.0, 0.0) == math.inf


def test_rayleigh_speed_model_example():
    # MODEL.md 7: E = 5 MPa, nu = 0.3, rho = 250: c_s 88, c_R 81 m/s
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
def _synthetic_pst(c=30.0, l_td=1.2, h=0.004, reverse=False):
    """Parameters, frame series and bin arrival times of an ideal PST (front at speed c from t0)."""
    L, cut, bw, t0 = 5.0, 0.4, 0.02, 0.2
    # the saw runs from t = 0.1 s at 4 m/s: it stops at t0 = 0.2 s; markers every 0.1 m from 0.05 m
    scene = PSTParams(length=L, dx=0.01, marker_spacing=0.1, settle=Settle(gravity_ramp=0.05, duration=0.1),
                      saw=Saw(speed=4.0, cut_length=cut, from_end="left"), front=Front(bin=bw))
    markers = scene.markers()
    assert scene.saw_end == pytest.approx(t0) and markers[0] == pytest.approx(0.05)
    t = np.arange(0.0, 0.5, 0.002)
    sb = (np.arange(int(L / bw)) + 0.5) * bw
    if reverse:  # everything beyond the cut fails from the far end towards the saw
        tb = np.where(sb <= cut, 0.1 + sb / 4.0, t0 + (L - sb) / c)
    else:
        tb = np.where(sb <= cut, 0.1 + sb / 4.0, t0 + (sb - cut) / c)
    front = np.array([fronts.front_from_arrival(tb, ti, bw) for ti in t])
    series = {"front": front, "collapse_height": np.full(t.size, h)}
    for k, m in enumerate(markers):  # slab base: 0 ahead of the front, h behind the touchdown point
        x = np.clip((front - m) / l_td, 0.0, 1.0) * (m < front)
        series[f"marker{k}_uy"] = -h * (3 * x**2 - 2 * x**3)
    return scene, t, series, (sb, tb)


def test_pst_summary_on_ideal_front():
    scene, t, series, arrival = _synthetic_pst()
    out = pst_summary(scene, t, series, arrival=arrival)
    assert out["speed"] == pytest.approx(30.0, rel=1e-6)
    assert out["speed_frames"] == pytest.approx(30.0, rel=0.05)
    assert out["propagated"] and out["ran_to_end"] and out["initiated_at_saw"]
    x95 = 0.5 + math.cos((math.acos(1 - 2 * 0.95) + 4 * math.pi) / 3)
    assert out["touchdown"] == pytest.approx(1.2 * x95, abs=0.1)
    assert out["collapse_height"] == 0.004


def test_pst_summary_flags_a_crack_started_elsewhere():
    scene, t, series, arrival = _synthetic_pst(c=150.0, reverse=True)
    out = pst_summary(scene, t, series, arrival=arrival)
    assert not out["initiated_at_saw"]
    assert out["initiation_position"] > 4.5
    assert out["apparent_speed"] == pytest.approx(150.0, rel=1e-6)
    assert math.isnan(out["speed"])
