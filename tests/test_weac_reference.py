"""weac's static answer for a PST (mpm_warp.scenes.weac_reference) against direct weac calls, statics and physics.

The direct calls build the same column in weac by hand, mirrored (weac's ``phi > 0`` with the cut at the other
end), so that they do not repeat the module's mapping; the convention itself is proven by statics at the crack
tip and by the direction in which the downslope weight changes the energy release rate (docs/weac.md §2).
"""

from __future__ import annotations

import importlib.metadata
import math
import subprocess
import sys

import numpy as np
import pytest

from mpm_warp.errors import InvalidArgument
from mpm_warp.scenes import weac_reference as wr
from mpm_warp.scenes.snow import GRAVITY

W_F = 0.79                                     # J/m^2: the ladder PST's fracture energy, G_c of the energy criterion


def column(theta=0.0, cut_from="upslope", ends="slope_normal", h=0.3, L=2.2, slab=None):
    """The error ladder's PST (mpm_warp.studies.snow.ladder_pst over pst_flat.toml's snow)."""
    return wr.StaticColumn(slab=slab or [(h, 250.0, 5.0e6, 0.3)], weak_layer_thickness=0.06, weak_layer_E=1.0e6,
                           weak_layer_nu=0.3, length=L, slope_angle=theta, cut_from=cut_from, column_ends=ends)


def direct(system, phi, a_mm, layers=((250.0, 300.0, 5.0),), L=2200.0):
    """weac by hand (mm, MPa): layers (density, thickness mm, E MPa), nu 0.3, weak layer 60 mm, 1 MPa, 0.3."""
    import weac

    m = weac.Layered(system=system, layers=[[rho, h] for rho, h, _ in layers])
    m.set_foundation_properties(t=60.0, E=1.0, nu=0.3)
    E = np.array([ly[2] for ly in layers])
    m.slab[:, 2], m.slab[:, 3], m.slab[:, 4] = E, E / 2.6, 0.3
    m.calc_fundamental_system()
    seg = m.calc_segments(L=L, a=a_mm, phi=phi)["crack"]
    return m, seg, m.assemble_and_solve(phi=phi, **seg)


def direct_G(system, phi, a_mm, **kw):
    m, seg, C = direct(system, phi, a_mm, **kw)
    return m.gdif(C, phi, **seg, unit="J/m^2")


# ours (theta, cut_from, ends) -> weac mirrored: its phi = +theta puts the upslope end at its right (x = L)
MIRRORED = [((0.0, "upslope", "slope_normal"), ("pst-", 0.0)), ((30.0, "upslope", "slope_normal"), ("pst-", 30.0)),
            ((30.0, "downslope", "slope_normal"), ("-pst", 30.0)), ((35.0, "upslope", "vertical"), ("vpst-", 35.0)),
            ((35.0, "downslope", "vertical"), ("-vpst", 35.0))]


@pytest.mark.parametrize("ours, theirs", MIRRORED)
def test_energy_release_rate_is_a_direct_weac_call(ours, theirs):
    got = wr.energy_release_rate(column(*ours), 0.31)
    want = direct_G(*theirs, 310.0)
    assert np.allclose(got, want, rtol=1e-6, atol=0.0)
    assert got[0] == pytest.approx(got[1] + got[2], rel=1e-12)


@pytest.mark.parametrize("ours, theirs", MIRRORED[:3])
def test_critical_cut_is_the_root_of_a_direct_weac_call(ours, theirs):
    from scipy.optimize import brentq

    want = brentq(lambda a: direct_G(*theirs, a)[0] - W_F, 100.0, 1000.0, xtol=1e-9) / 1e3
    assert wr.critical_cut(column(*ours), W_F) == pytest.approx(want, rel=1e-6)


def arr_column():
    """pst_outcomes.py's ARR column: pst_demo's 2.5 m, 0.3 m slab on a 3 cm weak layer."""
    return wr.StaticColumn(slab=[(0.3, 250.0, 5.0e6, 0.3)], weak_layer_thickness=0.03, weak_layer_E=1.0e6,
                           weak_layer_nu=0.3, length=2.5)


def test_touchdown_caps_G_of_a_long_crack():
    """weac with touchdown (the cut slab's end rests on the collapsed layer): below the cut at which the end
    touches, the same G as without; past it G stops growing. Values of weac 2.6.4's touchdown=True, which weac
    3.3.1 repeats to 1e-4 (checked by hand at 0.8-2.4 m)."""
    col = arr_column()
    for a in (0.3, 0.5, 0.7):                 # free-hanging: touchdown changes nothing
        assert wr.energy_release_rate(col, a, touchdown=True) == pytest.approx(wr.energy_release_rate(col, a),
                                                                               rel=1e-9)
    free = [wr.energy_release_rate(col, a)[0] for a in (0.8, 0.95, 1.5)]
    capped = [wr.energy_release_rate(col, a, touchdown=True)[0] for a in (0.8, 0.95, 1.5)]
    assert free == pytest.approx([5.633, 9.840, 47.40], rel=1e-3)       # grows without bound as the slab hangs
    assert capped == pytest.approx([2.897, 2.700, 3.525], rel=1e-3)     # rests on the layer: about 3 G_c
    G, G_I, G_II = wr.energy_release_rate(col, 0.8, touchdown=True)
    assert G == pytest.approx(G_I + G_II, rel=1e-12) and (G_I, G_II) == pytest.approx((2.240, 0.6573), rel=1e-3)


def test_touchdown_of_a_vertical_ended_column_is_capped_too():
    """weac 2.6 leaves a vertical-ended column's touchdown half done (its G grew to 324 J/m^2 at a 1 m cut of a
    10 m column where the slope-normal one rests at 3.9): on a flat column the two ends are the same column, so
    their G with touchdown must agree; on a slope the vertical-ended G rests above the slope-normal one by the end
    wedge's weight, a share that shrinks as the cut grows, far below the free slab's (the rested slab's axial
    load keeps G_II growing slowly in both)."""
    from dataclasses import replace

    flat = replace(arr_column(), length=10.0)
    for a in (0.5, 1.0, 2.0, 4.0):
        normal = wr.energy_release_rate(flat, a, touchdown=True)
        assert wr.energy_release_rate(replace(flat, column_ends="vertical"), a, touchdown=True) == pytest.approx(
            normal, rel=1e-9)
    steep = replace(flat, slope_angle=30.0, column_ends="vertical")
    G = [wr.energy_release_rate(steep, a, touchdown=True)[0] for a in (0.3, 2.0, 6.0)]
    assert G[0] == pytest.approx(wr.energy_release_rate(steep, 0.3)[0], rel=1e-9)    # hangs free: untouched
    normal = [wr.energy_release_rate(replace(steep, column_ends="slope_normal"), a, touchdown=True)[0]
              for a in (2.0, 6.0)]
    excess = [g / n - 1.0 for g, n in zip(G[1:], normal, strict=True)]
    assert 0.0 < excess[1] < excess[0] < 0.25                  # 0.17 at 2 m, 0.06 at 6 m
    assert G[2] < 0.01 * wr.energy_release_rate(steep, 6.0)[0]


def test_installed_weac_rounds_to_the_values_recorded_from_weac_3_3_1():
    """The installed weac (2.6 here) computes the ladder PST's critical cuts; they round to the values recorded
    from weac 3.3.1 (``WEAC_3_3_1_RECORDED`` of ``benchmarks/snow/weac_static_pst.py``: computed outside this
    project, quoted in issue 21; weac 3 needs Python >= 3.12): flat 0.380 m, 30 deg from downslope 0.382 m,
    from upslope 0.452 m."""
    assert round(wr.critical_cut(column(0.0), W_F), 3) == 0.380
    assert round(wr.critical_cut(column(30.0, "downslope"), W_F), 3) == 0.382
    assert round(wr.critical_cut(column(30.0, "upslope"), W_F), 3) == 0.452


def _tip(col, cut):
    """Section forces (N/mm, N/mm, N mm/mm) of the slab at the crack tip, from the cut side."""
    s = wr._solve(col, cut)
    f = int(np.flatnonzero(~np.asarray(s.seg["ki"]))[0])
    length = s.seg["li"][f]
    z = s.model.z(length if s.left else 0.0, s.C[:, [f]], length, s.phi, bed=False)
    return s.model.N(z)[0], s.model.V(z)[0], s.model.M(z)[0]


@pytest.mark.parametrize("theta", [20.0, 30.0])
def test_the_cut_slab_carries_its_own_weight_downslope(theta):
    """Statics of the free slab over the cut: its downslope weight ``q a sin(theta)`` pushes on the intact slab when
    the cut starts at the upslope end (compression) and hangs from it when it starts at the downslope end (tension).
    A sign error in the slope or cut-end mapping flips N."""
    a, th = 0.4, math.radians(theta)
    q = 250.0e-12 * GRAVITY * 1e3 * 300.0                         # N/mm^2 x mm: weight per mm of slab
    for cut_from, sign in (("upslope", -1.0), ("downslope", +1.0)):
        N, V, M = _tip(column(theta, cut_from), a)
        assert N == pytest.approx(sign * q * a * 1e3 * math.sin(th), rel=1e-6)
        assert abs(V) == pytest.approx(q * a * 1e3 * math.cos(th), rel=1e-6)
        assert abs(M) == pytest.approx(q * math.cos(th) * (a * 1e3) ** 2 / 2.0, rel=1e-6)


def test_vertical_ends_add_the_upslope_wedge_and_remove_the_downslope_one():
    """Plumb ends on a slope: the slab overhangs the upslope end by a wedge of weight ``rho g H^2 tan(theta) / 2``
    and lacks that wedge at the downslope end; the cut slab's section force at the tip says so."""
    a, th, H = 0.6, math.radians(35.0), 0.5
    q = 250.0 * GRAVITY * H                                       # N/m^2 x m
    wedge = 250.0 * GRAVITY * H**2 * math.tan(th) / 2.0           # N per m of width
    assert a > H * math.tan(th)                                   # the missing wedge lies over the cut
    N_up = _tip(column(35.0, "upslope", "vertical", h=H), a)[0]
    N_down = _tip(column(35.0, "downslope", "vertical", h=H), a)[0]
    assert N_up == pytest.approx(-(q * a + wedge) * math.sin(th) * 1e-3, rel=1e-6)
    assert N_down == pytest.approx((q * a - wedge) * math.sin(th) * 1e-3, rel=1e-6)
    g_up_v, g_up_n = (wr.energy_release_rate(column(35.0, "upslope", e, h=H), a)[0]
                      for e in ("vertical", "slope_normal"))
    g_dn_v, g_dn_n = (wr.energy_release_rate(column(35.0, "downslope", e, h=H), a)[0]
                      for e in ("vertical", "slope_normal"))
    assert g_up_v > g_up_n and g_dn_v < g_dn_n


def test_the_downslope_weight_opens_a_cut_from_the_downslope_end():
    """The downslope pull ``N`` on the cut slab acts at its mid-plane, above the weak layer that holds it: from the
    downslope end it bends the free slab further down (more mode I than the slope-normal load alone, which is the
    flat value times cos^2), from the upslope end it lifts it (less)."""
    flat = wr.energy_release_rate(column(0.0), 0.3)[1]
    down = wr.energy_release_rate(column(30.0, "downslope"), 0.3)[1]
    up = wr.energy_release_rate(column(30.0, "upslope"), 0.3)[1]
    assert down > 1.1 * flat * math.cos(math.radians(30.0)) ** 2 > 1.1 * up


def test_mirror_and_flat_symmetries():
    for ends in ("slope_normal", "vertical"):
        for cut_from in ("upslope", "downslope"):
            assert wr.energy_release_rate(column(-25.0, cut_from, ends), 0.3) == pytest.approx(
                wr.energy_release_rate(column(25.0, cut_from, ends), 0.3), rel=1e-12)
    flat = wr.energy_release_rate(column(0.0), 0.3)
    for cut_from, ends in (("downslope", "slope_normal"), ("upslope", "vertical"), ("downslope", "vertical")):
        assert wr.energy_release_rate(column(0.0, cut_from, ends), 0.3) == pytest.approx(flat, rel=1e-9)


def test_weac_uses_the_given_E_and_nu_not_its_density_law():
    slab = [(0.1, 150.0, 1.0e6, 0.2), (0.15, 250.0, 8.0e6, 0.3), (0.05, 300.0, 20.0e6, 0.25)]
    m = wr._model(column(slab=slab))
    assert np.allclose(m.slab[:, 2], [1.0, 8.0, 20.0]) and np.allclose(m.slab[:, 4], [0.2, 0.3, 0.25])
    z = np.array([-150.0, -50.0, 100.0, 150.0])                   # ply faces (mm) about the mid-plane, z down
    Ep = np.array([1.0 / 0.96, 8.0 / 0.91, 20.0 / 0.9375])
    assert m.D11 == pytest.approx(sum(Ep * np.diff(z**3)) / 3.0, rel=1e-12)
    hom = wr._model(column())
    Ep = 5.0 / 0.91
    assert (hom.A11, hom.D11, hom.kA55) == pytest.approx((Ep * 300.0, Ep * 300.0**3 / 12.0, 5 / 6 * 5.0 / 2.6 * 300.0))
    assert hom.B11 == pytest.approx(0.0, abs=1e-9) and hom.g == pytest.approx(GRAVITY * 1e3)


def _direct_field(theirs, a_mm, x_cut_m, normalize=False):
    """weac's principal_stress_slab (kPa) at distances ``x_cut_m`` from the cut end, by hand; and its model and Z."""
    system, phi = theirs
    m, seg, C = direct(system, phi, a_mm)
    li, ki, L = seg["li"], seg["ki"], 2200.0
    xw = np.asarray(x_cut_m) * 1e3 if system.startswith("-") else L - np.asarray(x_cut_m) * 1e3
    tip = li[0]
    cols = []
    for x in xw:
        j = (0 if x <= tip else 1) if ki[0] else (0 if x < tip else 1)       # the crack tip: its bedded side
        cols.append(m.z(x - (0.0 if j == 0 else tip), C[:, [j]], li[j], phi, bed=bool(ki[j])))
    Z = np.concatenate(cols, axis=1)
    return m, Z, m.principal_stress_slab(Z, phi, dz=2.0, unit="kPa", val="max", normalize=normalize)


# weac's Sxx adds rho g sin(phi) dz per mesh row (2.5 Pa here), odd in phi: on a slope the direct call is unmirrored
FIELDS = [((0.0, "upslope", "slope_normal"), ("pst-", 0.0)), ((30.0, "upslope", "slope_normal"), ("-pst", -30.0)),
          ((30.0, "downslope", "slope_normal"), ("pst-", -30.0))]


@pytest.mark.parametrize("ours, theirs", FIELDS)
def test_slab_stress_raw_is_weacs_principal_stress(ours, theirs):
    st = wr.slab_stress(column(*ours), 0.452, strengths=[wr.sigrist_tensile_strength(250.0)], raw_weac=True)
    _, _, want = _direct_field(theirs, 452.0, st["x"])
    assert st["sigma_1"].shape == want.shape
    assert np.allclose(st["sigma_1"], want * 1e3, rtol=1e-6, atol=1e-6 * np.abs(want).max() * 1e3)
    _, _, ratio = _direct_field(theirs, 452.0, st["x"], normalize=True)
    assert np.allclose(st["ratio"], ratio, rtol=1e-6, atol=1e-6 * np.abs(ratio).max())
    r, c = np.unravel_index(np.argmax(want), want.shape)
    assert (st["peak_sigma_1"], st["peak_x"], st["peak_depth"]) == pytest.approx(
        (want[r, c] * 1e3, st["x"][c], st["depth"][r]), rel=1e-6)
    assert st["depth"][0] == 0.0 and st["depth"][-1] == pytest.approx(0.3)


def test_slab_stress_over_the_cut_has_a_free_base():
    """Over the cut nothing holds the slab's base: there ``tau_xz = sigma_zz = 0`` and the tensile principal stress
    is the axial stress where that pulls. weac 2.6's raw field (weak-layer equations there too) is not."""
    ours, theirs = FIELDS[1]
    st = wr.slab_stress(column(*ours), 0.452)
    raw = wr.slab_stress(column(*ours), 0.452, raw_weac=True)
    free = st["cracked"]
    m, Z, _ = _direct_field(theirs, 452.0, st["x"][free])
    sxx_base = m.Sxx(Z, theirs[1], dz=2.0, unit="kPa")[-1] * 1e3
    scale = np.abs(st["sigma_1"]).max()
    # sigma_zz there is weac's z-trapezoid residual over 2 mm rows: -0.03 Pa, 7e-6 of the peak
    assert np.allclose(st["sigma_1"][-1, free], np.maximum(sxx_base, 0.0), atol=1e-5 * scale)
    assert np.abs(raw["sigma_1"][-1, free] - np.maximum(sxx_base, 0.0)).max() > 0.1 * scale
    assert np.array_equal(st["sigma_1"][:, ~free], raw["sigma_1"][:, ~free])


def test_slab_stress_layers_and_strengths():
    slab = [(0.1, 150.0, 1.0e6, 0.25), (0.2, 300.0, 10.0e6, 0.25)]
    st = wr.slab_stress(column(slab=slab), 0.3, strengths=[1.0e3, 2.0e3])
    assert list(np.unique(st["layer"])) == [0, 1]
    assert np.all(st["depth"][st["layer"] == 0] <= 0.1 + 1e-12) and np.all(st["depth"][st["layer"] == 1] >= 0.1 - 1e-12)
    top = st["layer"] == 0
    assert np.allclose(st["ratio"][top], st["sigma_1"][top] / 1.0e3)
    assert np.allclose(st["ratio"][~top], st["sigma_1"][~top] / 2.0e3)
    assert st["peak_ratio"] == pytest.approx(st["ratio"].max())


BAD = [(dict(slab=[]), "column.slab"), (dict(slab=[(0.3, 250.0, 5e6)]), "column.slab[0]"),
       (dict(slab=[(0.0, 250.0, 5e6, 0.3)]), "column.slab[0].thickness"),
       (dict(slab=[(0.3, 250.0, 5e6, 0.3), (0.1, 1000.0, 5e6, 0.3)]), "column.slab[1].density"),
       (dict(slab=[(0.3, 250.0, -1.0, 0.3)]), "column.slab[0].E"),
       (dict(slab=[(0.3, 250.0, 5e6, 0.5)]), "column.slab[0].nu"),
       (dict(weak_layer_thickness=0.0), "column.weak_layer_thickness"), (dict(weak_layer_E=0.0), "column.weak_layer_E"),
       (dict(weak_layer_nu=0.7), "column.weak_layer_nu"), (dict(length=0.0), "column.length"),
       (dict(slope_angle=70.0), "column.slope_angle"), (dict(cut_from="left"), "column.cut_from"),
       (dict(column_ends="plumb"), "column.column_ends"),
       (dict(column_ends="vertical", slope_angle=45.0, length=0.25), "column.column_ends")]


@pytest.mark.parametrize("change, field", BAD)
def test_a_bad_column_is_refused_in_one_line_naming_the_field(change, field):
    kw = dict(slab=[(0.3, 250.0, 5e6, 0.3)], weak_layer_thickness=0.06, weak_layer_E=1e6, weak_layer_nu=0.3,
              length=2.2) | change
    with pytest.raises(InvalidArgument) as err:
        wr.StaticColumn(**kw)
    assert err.value.field == field and "\n" not in str(err.value)


def test_bad_arguments_are_refused_in_one_line():
    for call, field in ((lambda: wr.energy_release_rate(column(), 2.2), "cut"),
                        (lambda: wr.energy_release_rate(column(), -0.1), "cut"),
                        (lambda: wr.critical_cut(column(), 0.0), "G_c"),
                        (lambda: wr.slab_stress(column(), 0.3, strengths=[1e3, 2e3]), "strengths"),
                        (lambda: wr.slab_stress(column(), 0.3, strengths=1e3), "strengths"),
                        (lambda: wr.slab_stress(column(), 0.3, dx=0.0), "dx")):
        with pytest.raises(InvalidArgument) as err:
            call()
        assert err.value.field == field


def test_critical_cut_none_when_G_stays_below_G_c():
    res = wr.critical_cut_search(column(), W_F, max_cut=0.3)      # a_c = 0.380 m lies beyond the saw
    assert res.value is None and "G < G_c" in res.reason and wr.critical_cut(column(), W_F, max_cut=0.3) is None
    assert wr.critical_cut_search(column(), 1.0e-6).value == 0.0


def test_without_weac_every_call_says_so_in_one_line(monkeypatch):
    def missing(name):
        raise importlib.metadata.PackageNotFoundError(name)

    monkeypatch.setattr(wr._md, "version", missing)
    monkeypatch.setitem(sys.modules, "weac", None)                # and importing it fails
    assert wr.weac_version() is None
    assert wr.weac_unavailable() == wr.NOT_INSTALLED
    assert wr.NOT_INSTALLED == "weac is not installed: pip install 'mpm-warp[weac]' (weac 2.6.x, Python >= 3.10)"
    with pytest.raises(wr.WeacUnavailable) as err:
        wr.energy_release_rate(column(), 0.3)
    assert str(err.value) == wr.NOT_INSTALLED


@pytest.mark.parametrize("version", ["3.3.1", "2.5.0", "3"])
def test_another_weac_api_is_refused_in_one_line(monkeypatch, version):
    monkeypatch.setattr(wr._md, "version", lambda name: version)
    why = wr.weac_unavailable()
    assert f"weac {version} is installed" in why and "weac>=2.6,<3" in why and "\n" not in why
    with pytest.raises(wr.WeacUnavailable):
        wr.critical_cut(column(), W_F)


def test_importing_the_module_does_not_import_weac():
    code = "import sys, mpm_warp.scenes.weac_reference; print('weac' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
