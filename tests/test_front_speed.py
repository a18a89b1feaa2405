"""Front speeds that cannot outrun sound, on synthetic front histories with known answers
(mpm_warp.scenes.front_speed, the PST summary) and the results files' JSON writer."""

import io
import json
import math

import numpy as np
import pytest

from mpm_warp.finite_json import dump_finite, finite_json
from mpm_warp.scenes import fronts
from mpm_warp.scenes.front_speed import (
    CONTIGUOUS,
    NOT_CROSSED,
    NUCLEATION,
    bounded_mean_speed,
    damage_ahead,
    path_jumps,
    window_speeds,
)
from mpm_warp.scenes.pst import Front, PSTParams, Saw, pst_summary
from mpm_warp.scenes.pst.analysis import slab_p_wave_speed
from mpm_warp.scenes.snow import Settle

BW = 0.02            # m: bin width
CUT, L, T0 = 0.4, 6.0, 0.5
C_P = 164.08         # m/s: P-wave speed of the default slab (E 5 MPa, nu 0.3, 250 kg/m^3)
S = (np.arange(int(L / BW)) + 0.5) * BW


def _steady(c=30.0):
    """Arrival times of a front running at ``c`` (m/s) from the cut from T0 (the saw's bins before)."""
    return np.where(S <= CUT, 0.1 + S, T0 + (S - CUT) / c)


def _nucleated(c=30.0, block=(5.0, 5.6), t_nuc=None):
    """The steady front, with the bins of ``block`` (m) damaged at once at ``t_nuc`` (default: the front at 3 m)."""
    t = _steady(c)
    t_nuc = T0 + (3.0 - CUT) / c if t_nuc is None else t_nuc
    inside = (S > block[0]) & (S < block[1])
    return np.where(inside, t_nuc, t), t_nuc


def test_steady_front_speed_is_its_speed():
    t = _steady(30.0)
    sp, T = fronts.front_trajectory(S, t)
    assert damage_ahead(S, t, BW) == [] and path_jumps(sp, T, C_P, 0.05) == []
    w = window_speeds(sp, T, 0.5, CUT, C_P)
    assert set(w.status) == {CONTIGUOUS} and len(w.s) == 21
    assert np.allclose(w.speed, 30.0, rtol=1e-9) and w.largest() == pytest.approx(30.0, rel=1e-9)
    v, why = bounded_mean_speed(sp, T, CUT, CUT + 3.0, C_P)
    assert v == pytest.approx(30.0, rel=1e-6) and why is None


def test_a_front_that_jumps_because_damage_nucleates_ahead():
    t, t_nuc = _nucleated(30.0, (5.0, 5.6))
    sp, T = fronts.front_trajectory(S, t)
    # the old profile read the jump as a speed far above c_p
    _, old = fronts.speed_profile(sp, T, 0.5, start=CUT)
    assert np.nanmax(old) > 2 * C_P
    (b,) = damage_ahead(S, t, BW)
    assert (b.start, b.end) == pytest.approx((5.0, 5.6)) and b.extent == pytest.approx(0.6)
    assert b.time == pytest.approx(t_nuc) and b.front == pytest.approx(3.0, abs=BW) and b.lead == pytest.approx(2.0,
                                                                                                             abs=BW)
    assert b.crossed_in == pytest.approx(0.0, abs=1e-12)       # the front connected to it at once
    (j,) = path_jumps(sp, T, C_P, 0.05)
    assert (j.start, j.end) == pytest.approx((4.99, 5.59)) and j.time == pytest.approx(T0 + (4.99 - CUT) / 30.0)
    w = window_speeds(sp, T, 0.5, CUT, C_P, [b, j])
    for s, v, st in zip(w.s, w.speed, w.status, strict=True):
        if s - 0.25 < 5.6 and s + 0.25 > 4.99:                # windows holding the jump: no speed
            assert st == NUCLEATION and math.isnan(v)
        else:
            assert st == CONTIGUOUS and v == pytest.approx(30.0, rel=1e-9)
    assert sum(st == NUCLEATION for st in w.status) == 4       # centres 4.9, 5.15, 5.4, 5.65
    assert np.nanmax(w.speed) <= C_P
    d = w.to_dict()
    assert None in d["speed"] and all(v is None or v <= C_P for v in d["speed"])
    assert d["nucleation_apparent_speed"]["note"].startswith(NUCLEATION)
    # the mean over the jump is not a speed; before it, it is
    assert bounded_mean_speed(sp, T, CUT, 5.9, C_P, [b])[1].startswith(NUCLEATION)
    assert bounded_mean_speed(sp, T, CUT, 3.4, C_P, [b])[0] == pytest.approx(30.0, rel=1e-6)


def test_a_front_that_stops_has_no_speed_beyond():
    t = np.where(S < 2.0, _steady(30.0), np.inf)               # arrested at 2.0 m
    sp, T = fronts.front_trajectory(S, t)
    w = window_speeds(sp, T, 0.5, CUT, C_P)
    assert w.s[-1] + 0.25 <= 2.0 + 1e-9 and np.allclose(w.speed, 30.0, rtol=1e-9)
    v, why = bounded_mean_speed(sp, T, CUT, CUT + 3.0, C_P)
    assert math.isnan(v) and "did not reach 3.4 m" in why and "1.99 m" in why
    # a front that stands still inside a window: the window holds no line, no speed (never inf)
    t2 = np.where(S <= CUT, 0.1 + S, np.inf)
    sp2, T2 = fronts.front_trajectory(S, t2)
    assert len(window_speeds(sp2, T2, 0.5, CUT, C_P).s) == 0
    w3 = window_speeds(np.array([0.5, 0.6, 0.7, 1.0]), np.array([1.0, 1.0, 1.0, 1.0]), 0.5, 0.5, C_P)
    assert w3.status == [NUCLEATION]                          # crossed in no time: faster than c_p, not a speed
    w4 = window_speeds(np.array([0.5, 1.0]), np.array([1.0, 1.1]), 0.5, 0.5, C_P)
    assert w4.status == [NOT_CROSSED] and math.isnan(w4.speed[0]) and w4.to_dict()["speed"] == [None]


def test_fast_contiguous_front_and_noise():
    # a layer failing at once bin after bin (1000 m/s, in order): no bin ahead, but the path crosses it above c_p
    t = np.where(S < 4.0, _steady(30.0), T0 + 3.6 / 30.0 + (S - 4.0) / 1000.0)
    sp, T = fronts.front_trajectory(S, t)
    assert damage_ahead(S, t, BW) == []
    (j,) = path_jumps(sp, T, C_P, 0.05)
    assert j.start == pytest.approx(4.01) and j.end == pytest.approx(5.99)
    w = window_speeds(sp, T, 0.5, CUT, C_P, [j])
    assert all(st == NUCLEATION for s, st in zip(w.s, w.status, strict=True) if s + 0.25 > 4.01)
    assert np.nanmax(w.speed) == pytest.approx(30.0, rel=1e-9)
    # one bin damaged a moment before its neighbour (the bins' median times): noise, not a nucleation
    t4 = _steady(30.0)
    t4[150] = t4[149] - 1e-4
    sp4, T4 = fronts.front_trajectory(S, t4)
    assert damage_ahead(S, t4, BW, min_extent=0.05) == [] and len(damage_ahead(S, t4, BW)) == 1
    assert path_jumps(sp4, T4, C_P, 0.05) == []
    assert set(window_speeds(sp4, T4, 0.5, CUT, C_P).status) == {CONTIGUOUS}


def _pst():
    return PSTParams(length=L, dx=0.005, settle=Settle(gravity_ramp=0.05, duration=0.1),
                     saw=Saw(speed=1.0, cut_length=CUT, cut_from="upslope"), front=Front(bin=BW))


def test_pst_summary_never_reports_a_speed_above_c_p():
    p = _pst()
    assert slab_p_wave_speed(p) == pytest.approx(C_P, rel=1e-3)
    t, _ = _nucleated(30.0, (5.0, 5.6))
    times = np.arange(0.0, 0.8, 0.002)
    series = {"front": np.array([fronts.front_from_arrival(t, ti, BW) for ti in times])}
    out = pst_summary(p, p.calibrated(), times, series, S, t, t)
    assert out["p_wave_speed"] == pytest.approx(C_P, rel=1e-3)
    prof = out["damage_speed_profile"]
    assert max(v for v in prof["speed"] if v is not None) == pytest.approx(30.0, rel=1e-9)
    assert prof["status"].count(NUCLEATION) == 4
    (a,) = out["damage_ahead"]
    assert (a["start"], a["end"], a["front"]) == pytest.approx((5.0, 5.6, 3.0), abs=BW)
    assert out["damage_speed_mean"] == pytest.approx(30.0, rel=1e-6) and out["propagated"] and out["ran_to_end"]
    # arrested at 1.5 m: no mean speed, with the reason, and null in the results file
    t2 = np.where(S <= 1.5, t, np.inf)
    out2 = pst_summary(p, p.calibrated(), times, series, S, t2, t2)
    assert math.isnan(out2["speed"]) and "did not reach 3.4 m" in out2["speed_null"]
    fh = io.StringIO()
    dump_finite(out2, fh)
    back = json.loads(fh.getvalue())
    assert back["speed"] is None and "did not reach" in back["speed_null"]
    assert back["damage_speed_mean"] is None and back["touchdown"] is None and "30-85 %" in back["touchdown_null"]


def test_finite_json_writes_null_with_a_reason():
    data = {"a": math.nan, "a_null": "given reason", "b": math.inf, "c": [1.0, math.nan, np.float32("nan")],
            "d": np.array([2.0, np.inf]), "e": {"f": np.float64(3.5), "g": -math.inf}, "n": 7, "ok": True}
    out = finite_json(data)
    assert out["a"] is None and out["a_null"] == "given reason"
    assert out["b"] is None and "inf" in out["b_null"]
    assert out["c"] == [1.0, None, None] and out["c_null"].startswith("null entries (2 of 3)")
    assert out["d"] == [2.0, None]
    assert out["e"] == {"f": 3.5, "g": None, "g_null": "no value: the computation gave -inf"}
    assert out["n"] == 7 and out["ok"] is True and "n_null" not in out
    fh = io.StringIO()
    dump_finite(data, fh)
    assert "NaN" not in fh.getvalue() and "Infinity" not in fh.getvalue()


def test_rederive_speeds_of_a_stored_result():
    from mpm_warp.scenes.pst.analysis import rederive_speeds
    p = _pst()
    t, _ = _nucleated(30.0, (5.0, 5.6))
    times = np.arange(0.0, 0.8, 0.002)
    series = {"front": np.array([fronts.front_from_arrival(t, ti, BW) for ti in times])}
    out = pst_summary(p, p.calibrated(), times, series, S, t, t)
    stored = json.loads(json.dumps(finite_json(out)))
    # as an older release stored it: the old profile (a speed far above c_p), no jumps
    sp, T = fronts.front_trajectory(S, t)
    mids, old = fronts.speed_profile(sp, T, 0.5, start=CUT)
    for key in ("damage_ahead", "damage_jumps", "p_wave_speed"):
        stored.pop(key)
    stored["damage_speed_profile"] = {"s": mids.tolist(), "speed": old.tolist()}
    again = rederive_speeds(p, stored)
    assert list(again)[:5] == list(stored)[:5]                  # the stored order kept
    prof = again["damage_speed_profile"]
    assert prof["status"].count(NUCLEATION) == 4 and max(v for v in prof["speed"] if v is not None) <= 30.0 + 1e-6
    (j,) = again["damage_jumps"]
    assert (j["start"], j["end"]) == pytest.approx((4.99, 5.59)) and again["damage_ahead"] is None
    assert "not stored" in again["damage_ahead_null"] and again["p_wave_speed"] == pytest.approx(C_P, rel=1e-3)
    assert again["damage_speed_mean"] == pytest.approx(30.0, rel=1e-6) and again["ran_to_end"]


def test_load_json_reads_back_nan_where_the_writer_put_null():
    from mpm_warp.finite_json import load_json
    data = {"a": math.nan, "b": None, "c": [1.0, math.inf], "d": {"e": math.nan, "f": "x"}, "g": [None, 2.0]}
    fh = io.StringIO()
    dump_finite(data, fh)
    fh.seek(0)
    back = load_json(fh)
    assert math.isnan(back["a"]) and back["b"] is None and back["c"][0] == 1.0 and math.isnan(back["c"][1])
    assert math.isnan(back["d"]["e"]) and back["d"]["f"] == "x" and back["g"] == [None, 2.0]
