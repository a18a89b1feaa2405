"""A PST's outcome as the field writes it: END / SF / ARR and the observer's line (mpm_warp.scenes.pst.outcome)."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp.errors import InvalidArgument
from mpm_warp.scenes import fronts, pst
from mpm_warp.scenes.pst import pst_summary
from mpm_warp.scenes.pst.outcome import SlabCrackDetector, classify, field_line
from mpm_warp.scenes.snow import Settle

#: a soft, thin slab that breaks over the cut: 12 cm of new snow (120 kg/m^3, E 0.85 MPa, Bergfeld et al. 2023;
#: tensile strength 1.7 kPa, Sigrist 2006) on a 4 cm weak layer that collapses by a fifth (8 mm, the "about 20 %" of
#: Gaume et al. 2018's shear test), a 0.8 m column sawn to 0.5 m at 1 m/s. With the WEAC fit's 4.7 mm of collapse
#: the same slab breaks or not as E moves by 1 % (0.846 MPa: no, 0.85: yes): the slab breaks where it bends most,
#: over the collapsed cut, and 8 mm bends it well past its strength (E 0.80-0.90 MPa all break, 3-4 cm behind the
#: blade)
SOFT_THIN = ["scene.dx=0.01", "scene.weak_layer_thickness=0.04", "scene.substratum_thickness=0.05",
             "scene.slab.density=120", "scene.slab.E=0.85e6", "scene.slab_thickness=0.12", "scene.slab_fracture=true",
             "scene.length=0.8", "scene.saw.cut_length=0.5", "time.end=0.7", "scene.weak_layer.h_c=0.008"]


def test_the_observers_line():
    assert field_line("END", 0.32, 1.0, 0.5) == "PST 32/100 (END) down 50 cm"
    assert field_line("SF", 0.504, 2.0, 0.2) == "PST 50/200 (SF) down 20 cm"
    assert field_line(None, 0.3, 1.5, 0.3) == "PST 30/150 (running) down 30 cm"


def _series(front_at, t_end=0.8, dt=0.005):
    t = np.arange(0.0, t_end + 1e-9, dt)
    return t, np.array([front_at(ti) for ti in t])


def test_classes_from_the_series():
    p = pst.PSTParams(length=2.0, slab_thickness=0.3, saw=pst.Saw(cut_length=0.4))   # saw stops at 0.5 s

    def run(ti):                     # the blade at 1 m/s, then a crack at 20 m/s from 0.45 s on
        return 0.0 if ti < 0.1 else min(ti - 0.1, 0.4) + max(0.0, ti - 0.45) * 20.0
    t, fr = _series(lambda ti: min(run(ti), 2.0))
    end = classify(p, t, fr, None, saw_cut=0.35)
    assert end["class"] == "END" and end["field_line"] == "PST 35/200 (END) down 30 cm"
    assert end["end_time"] == pytest.approx(0.45 + (2.0 - 0.3 - 0.35) / 20.0, abs=0.006)
    # the slab breaks before the front reaches the end zone: SF, where it broke; after it: still END
    sc = np.where(t >= 0.5, 0.8, np.nan)
    sf = classify(p, t, fr, sc, saw_cut=0.35)
    assert sf["class"] == "SF" and sf["slab_fracture_at"] == 0.8 and sf["slab_fracture_time"] == pytest.approx(0.5)
    late = classify(p, t, fr, np.where(t >= 0.6, 0.8, np.nan), saw_cut=0.35)
    assert late["class"] == "END" and math.isnan(late["slab_fracture_at"])
    # a front that stops at 1.2 m and stands still for the last STALL_TIME: ARR there
    t, fr = _series(lambda ti: min(run(ti), 1.2))
    arr = classify(p, t, fr, np.full(len(t), np.nan))
    assert arr["class"] == "ARR" and arr["arrest_at"] == pytest.approx(1.2)
    assert arr["note"] == "the crack ran 0.80 m beyond the saw and stopped"
    assert arr["cut"] == 0.4            # no runaway: the line quotes the cut made
    # a crack that never left the saw is an arrest at the blade, said so
    t, fr = _series(lambda ti: 0.0 if ti < 0.1 else min(ti - 0.1, 0.4))
    stuck = classify(p, t, fr)
    assert stuck["class"] == "ARR" and "did not run beyond the saw" in stuck["note"]
    # a front still moving when the series ends: no class, and why
    t, fr = _series(lambda ti: min(run(ti), 2.0), t_end=0.47)
    open_ = classify(p, t, fr)
    assert open_["class"] is None and "still running" in open_["note"] and "(running)" in open_["field_line"]


def test_the_slab_crack_detector_finds_a_through_crack_and_not_a_partial_one():
    sc = mw.load_scenario("pst_demo", SOFT_THIN)
    sim = mw.Simulation(sc, device="cpu")
    mon = pst.attach(sim)
    det = mon.slab_crack
    # it watches the slab and nothing else: 0.8 m x 12 cm at 2 x 2 particles per 1 cm cell = 3840 particles in
    # 24 rows and 80 bins of 1 cm, and a through-crack may lean over one slab thickness (12 bins)
    assert type(det) is SlabCrackDetector and [g.name for g in det.groups] == ["slab"]
    assert det.groups[0].count == 3840 and det.n_rows == 24 and det.window == 12
    assert (det.bins.min(), det.bins.max()) == (0, 79) and np.bincount(det.bins).tolist() == [48] * 80
    g = det.groups[0]
    x0 = g.x0
    kappa = np.zeros(g.count)
    y_lo, y_hi = x0[:, 1].min(), x0[:, 1].max()
    fail = g.material.failure_stress * 1.01
    # a crack from the top down to 40 % of the slab: not through
    band = (np.abs(x0[:, 0] - 0.42) < 0.006) & (x0[:, 1] > y_lo + 0.6 * (y_hi - y_lo))
    kappa[band] = fail
    g.kappa.assign(kappa.astype(np.float32))
    assert math.isnan(det.through_crack())
    assert det.crack_cover() == pytest.approx(10 / 24)    # rows 14-23 of 24: y above 60 % of the slab's height
    # through the whole slab, leaning by 3 cm from top to bottom: found at its median position
    lean = 0.42 + 0.03 * (x0[:, 1] - y_lo) / (y_hi - y_lo)
    band = np.abs(x0[:, 0] - lean) < 0.006
    kappa[:] = 0.0
    kappa[band] = fail
    g.kappa.assign(kappa.astype(np.float32))
    assert det.through_crack() == pytest.approx(np.median(x0[band, 0]), abs=0.005)
    assert det.crack_cover() == 1.0
    assert mon.units()["slab_crack"] == "m"
    # a slab that cannot break records no slab-crack series
    plain = pst.attach(mw.Simulation(mw.load_scenario("pst_demo", [o for o in SOFT_THIN if "fracture" not in o]),
                                     device="cpu"))
    assert plain.slab_crack is None and "slab_crack" not in plain.units()


class _Host:
    """A host array standing in for a device view (``.numpy()``)."""

    def __init__(self, a):
        self.a = np.asarray(a)

    def numpy(self):
        return self.a


def test_the_slab_stress_ratio_is_the_stress_the_slab_carries():
    """By hand, plane strain: E 5 MPa, nu 0.25 (mu = lam = 2 MPa), strength 5 kPa, G_f 0.2 J/m^2 over 1 cm: the
    stress at full damage is 2 E G_f / (sigma_t h) = 40 kPa. A stretch e along a principal axis carries
    tau_1 = (2 mu + lam) e = 6 MPa e and tau_2 = lam e."""
    mat = mw.CrackingSnow(E=5e6, nu=0.25, density=200.0, tensile_strength=5e3, fracture_energy=0.2, band_width=0.01)
    c, s = np.cos(0.6), np.sin(0.6)
    R = np.array([[c, -s], [s, c]])

    def ratio(*parts):
        """``parts``: (principal Hencky strains (e1, e2), kappa Pa), each particle stretched in a rotated frame."""
        H = np.array([R @ np.diag(np.exp(e)) @ R.T - np.eye(2) for e, _ in parts])
        g = SimpleNamespace(material=mat, H=_Host(H), kappa=_Host([k for _, k in parts]))
        det = SimpleNamespace(groups=[g], body=[np.zeros(len(parts), dtype=bool)])
        return SlabCrackDetector.stress_ratios(det)[0]

    # intact: tau_1 = 6 MPa x 1e-4 = 600 Pa = 0.12 of the strength; a squeezed particle carries no tension
    assert ratio(((1e-4, 0.0), 0.0)) == pytest.approx(0.12, rel=1e-6)
    assert ratio(((-1e-3, -1e-3), 0.0), ((1e-4, 0.0), 0.0)) == pytest.approx(0.12, rel=1e-6)
    # on its softening branch at kappa = tau_1 = 22.5 kPa (e = 3.75e-3), d = 1 - (5/22.5)(40 - 22.5)/35 = 8/9: it
    # carries (1 - d) 22.5 kPa = 2.5 kPa, half its strength, and counts 1, having cracked (the unsoftened
    # stress, 4.5 times the strength, is what the monitor read before)
    e = 3.75e-3
    assert mat.damage(22.5e3) == pytest.approx(8 / 9)
    assert ratio(((e, 0.0), 22.5e3)) == 1.0
    # an open crack stretched to e = 0.05: its unsoftened stress is 300 kPa, 60 times the strength; it carries none
    assert ratio(((0.05, 0.0), 6e6 * 0.05), ((1e-4, 0.0), 0.0)) == 1.0
    # the body: a cracked base row (y = 0) below an intact body (y = 0.05 m, 600 Pa) reads 1 over the whole slab
    # and 0.12 over the body above 0.03 m; a slab all below it has no body
    parts = (((e, 0.0), 22.5e3), ((1e-4, 0.0), 0.0))
    H = np.array([R @ np.diag(np.exp(p)) @ R.T - np.eye(2) for p, _ in parts])
    g = SimpleNamespace(material=mat, H=_Host(H), kappa=_Host([k for _, k in parts]),
                        x0=np.array([[0.1, 0.0], [0.1, 0.05]]))
    params = pst.PSTParams()
    det = SlabCrackDetector(params, [g], body_above=0.03)
    assert det.stress_ratio() == 1.0 and det.body_stress_ratio() == pytest.approx(0.12, rel=1e-6)
    assert math.isnan(SlabCrackDetector(params, [g], body_above=0.06).body_stress_ratio())


@pytest.mark.slow
def test_a_soft_thin_slab_breaks_over_the_cut(tmp_path):
    out = tmp_path / "sf.h5"
    res = mw.run("pst_demo", output=str(out), overrides=SOFT_THIN + ["output.fields=['x','damage']"])
    o = res.scene_result["outcome"]
    assert o["class"] == "SF" and o["field_line"] == "PST 50/80 (SF) down 12 cm"
    # it breaks while the saw cuts (the saw starts at 0.1 s and stops at 0.6 s), behind the blade, within one slab
    # thickness of it
    t_sf, at = o["slab_fracture_time"], o["slab_fracture_at"]
    assert 0.1 < t_sf < 0.6 and 0.0 < (t_sf - 0.1) * 1.0 - at < 0.12
    run = mw.read_run(str(out))
    assert run.attrs["outcome"]["pst"] == pytest.approx(o, nan_ok=True)
    d = run.frame(-1)["damage"]
    slab = run.static["group"] == [g["name"] for g in run.attrs["groups"]].index("slab")
    assert (d[slab] >= 0.95).sum() >= 20                     # a crack across the slab's 24 particle rows


def test_pst_outcome_needs_the_crack_to_run_beyond_the_saw():
    BW = 0.02  # m: bin width
    # a column whose saw cuts into the far end zone (one slab depth, 0.5 m): the saw alone is no END
    p = pst.PSTParams(length=1.0, dx=0.005, settle=Settle(gravity_ramp=0.05, duration=0.1),
                  saw=pst.Saw(speed=1.0, cut_length=0.6, cut_from="upslope"), front=pst.Front(bin=BW))
    s = (np.arange(50) + 0.5) * BW
    t = np.where(s <= 0.6, 0.1 + s, np.inf)                   # sawn bins only
    times = np.arange(0.0, 0.9, 0.01)
    series = {"front": np.array([fronts.front_from_arrival(t, ti, BW) for ti in times])}
    out = pst_summary(p, p.calibrated(), times, series, s, t, t)
    assert out["damage_front_final"] == pytest.approx(0.6) and not out["propagated"] and not out["ran_to_end"]
    cls = classify(p, times, series["front"])
    assert cls["class"] == "ARR" and math.isnan(cls["end_time"])
    t3 = np.where(s <= 0.6, 0.1 + s, 0.7 + (s - 0.6) / 30.0)    # the crack runs on from the cut: END
    series3 = {"front": np.array([fronts.front_from_arrival(t3, ti, BW) for ti in times])}
    assert classify(p, times, series3["front"])["class"] == "END"
    assert pst_summary(p, p.calibrated(), times, series3, s, t3, t3)["ran_to_end"]


def test_a_column_no_longer_than_its_slab_is_refused_and_a_short_run_has_no_outcome():
    # the command of issue 37: mpm-warp run pst_demo --set scene.length=0.3 --set scene.saw.cut_length=0.1 ...
    sets = ["scene.saw.cut_length=0.1", "time.end=0.005"]
    refused = r"scene.length = 0.3 is invalid: expected a number in \(0.3, inf\) with a saw cut"
    with pytest.raises(InvalidArgument, match=refused):
        mw.load_scenario("pst_demo", ["scene.length=0.3", *sets])
    # just longer than the 0.3 m slab: runs, and 5 ms (before the saw starts at 0.1 s) give no outcome
    rr = mw.run("pst_demo", overrides=["scene.length=0.45", *sets])
    r = rr.scene_result
    assert not r["propagated"] and not r["ran_to_end"] and r["damage_front_final"] == 0.0
    assert r["outcome"]["class"] is None and r["outcome"]["field_line"] == "PST 10/45 (running) down 30 cm"
    assert r["outcome"]["note"].startswith("the saw had not started") and math.isnan(r["outcome"]["end_time"])
    assert r["outcome"]["end_time_null"] == "the crack did not reach the far end zone, having run beyond the cut"
    assert math.isnan(r["speed"]) and "did not reach 0.15 m" in r["speed_null"]
