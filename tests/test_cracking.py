"""Tensile cracking of the slab (kernels/cracking.py, docs/model.md §9): onset, softening, energy, leave-out."""

import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp.errors import InvalidArgument
from mpm_warp.material_point import drive_material_points

E, NU, RHO = 5e6, 0.25, 200.0
ST, GF, H = 5e3, 0.2, 0.01          # Pa, J/m^2, m: failure stress 2 E G_f / (st h) = 40 kPa


def cracking(**kw):
    return mw.CrackingSnow(**{"E": E, "nu": NU, "density": RHO, "tensile_strength": ST, "fracture_energy": GF,
                              "band_width": H, **kw})


def uniaxial_tension(mat, eps_max, n=400, dtype="float64", rotation=None):
    """Uniaxial stress along x (y and z stress-free) to ``eps_max``; optionally in a rotated frame."""
    F = np.tile(np.eye(3), (n, 1, 1))
    F[:, 0, 0] = np.exp(np.linspace(eps_max / n, eps_max, n))
    if rotation is not None:
        F = rotation @ F @ rotation.T
        return drive_material_points(F_total=F, material=mat, dtype=dtype)
    # lateral stresses held to 0.01 Pa: the softened axial stress is then free of the control's error
    return drive_material_points(F_total=F, material=mat, dtype=dtype, stress_tol=0.01,
                                 stress_control={"axes": (False, True, True), "sigma": (0.0, 0.0, 0.0)})


@pytest.mark.slow
@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_uniaxial_tension_softens_linearly_and_spends_the_fracture_energy(dtype):
    mat = cracking()
    assert mat.failure_stress == pytest.approx(2 * E * GF / (ST * H))
    eps_f = mat.failure_stress / E
    r = uniaxial_tension(mat, 1.25 * eps_f, dtype=dtype)
    s = r["stress"][0, :, 0, 0].astype(float)
    e = np.log(r["F"][0, :, 0, 0])
    # elastic to the strength (within one increment), then the linear softening law, then traction-free
    assert s.max() == pytest.approx(ST, rel=5e-3)
    soft = (e > 1.05 * ST / E) & (e < 0.95 * eps_f)
    want = ST * (eps_f - e[soft]) / (eps_f - ST / E)
    np.testing.assert_allclose(s[soft], want, rtol=2e-3, atol=2e-3 * ST)
    assert np.all(np.abs(s[e > 1.01 * eps_f]) < 1e-6 * ST) and r["damage"][0, -1] == 1.0
    # the work per unit volume is G_f / h: the fracture energy spent over the band
    assert np.trapezoid(s, e) == pytest.approx(GF / H, rel=5e-3)
    # the kernel's damage is the host formula of the material
    np.testing.assert_allclose(r["damage"][0], mat.damage(r["kappa"][0]), rtol=1e-6)


def test_a_crack_closes_in_compression_and_keeps_its_damage():
    mat = cracking()
    n = 200
    eps = np.concatenate([np.linspace(0, 0.5 * mat.failure_stress / E, n), np.linspace(0.5 * mat.failure_stress / E,
                                                                                        -2e-3, n)])[1:]
    F = np.tile(np.eye(3), (len(eps), 1, 1))
    F[:, 0, 0] = np.exp(eps)
    r = drive_material_points(F_total=F, material=mat, dtype="float64",
                              stress_control={"axes": (False, True, True), "sigma": (0.0, 0.0, 0.0)})
    s = r["tau"][0, 1:, 0, 0]                     # Kirchhoff: uniaxial Hencky gives tau = E eps exactly
    d = r["damage"][0, 1:]
    back = np.arange(len(eps)) >= n
    assert d[n] > 0.3 and np.all(np.diff(d) >= -1e-15)          # damage never heals
    # unloading in tension follows the secant (1 - d) E eps; in compression the full stiffness returns
    comp = back & (eps < -1e-4)
    np.testing.assert_allclose(s[comp], E * eps[comp], rtol=1e-3)
    ten = back & (eps > 1e-4)
    np.testing.assert_allclose(s[ten], (1 - d[ten]) * E * eps[ten], rtol=1e-3)


def test_the_criterion_is_objective_in_3d():
    # the same tension along a rotated axis (uniaxial strain, no control): the same principal stresses
    mat = cracking()
    c, s = np.cos(0.7), np.sin(0.7)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    a = uniaxial_tension(mat, 5e-3, rotation=np.eye(3))
    b = uniaxial_tension(mat, 5e-3, rotation=R)
    sa = np.linalg.eigvalsh(a["stress"][0])
    sb = np.linalg.eigvalsh(b["stress"][0])
    np.testing.assert_allclose(sb, sa, rtol=1e-9, atol=1e-9 * ST)
    assert a["damage"][0, -1] > 0.0
    np.testing.assert_allclose(b["damage"][0], a["damage"][0], rtol=1e-9, atol=1e-12)


def test_below_its_strength_a_cracking_slab_is_the_elastic_slab_bit_for_bit():
    # the driver: stresses below the strength are the elastic ones to the last bit
    el = mw.Elastic(E, NU, RHO)
    for dtype in ("float32", "float64"):
        a = uniaxial_tension(cracking(), 0.8 * ST / E, n=50, dtype=dtype)
        b = uniaxial_tension(el, 0.8 * ST / E, n=50, dtype=dtype)
        np.testing.assert_array_equal(a["stress"], b["stress"])
        assert np.all(a["kappa"] == 0.0)


@pytest.mark.slow
@pytest.mark.parametrize("dim", [2, 3])
def test_engine_block_below_its_strength_matches_the_elastic_block(dim):
    def block(mat):
        lo, hi = (0.0,) * dim, (0.2, 0.1) + (0.04,) * (dim - 2)
        # a block resting on a slip floor and sliding along it: self-weight stresses, far below the strength
        sc = mw.Scenario(name="b", domain=mw.Domain(lo=(-0.05, 0.0) + (-0.05,) * (dim - 2),
                                                     hi=(0.25, 0.15) + (0.09,) * (dim - 2), dx=0.01,
                                                     boundary="slip", dimension=dim),
                         time=mw.TimeControl(end=0.02, frame_interval=0.02), materials={"m": mat},
                         blocks=(mw.Block("m", lo, hi, velocity=(0.3,) + (0.0,) * (dim - 1)),))
        sim = mw.Simulation(sc, device="cpu")
        sim.step_to(0.02)
        return sim
    a, b = block(cracking(tensile_strength=1e6, fracture_energy=1e3, band_width=1e-3)), block(mw.Elastic(E, NU, RHO))
    assert np.abs(a.particle_field("stress")).max() > 50.0        # it is loaded
    np.testing.assert_array_equal(a.state.x.numpy(), b.state.x.numpy())
    np.testing.assert_array_equal(a.state.H.numpy(), b.state.H.numpy())
    assert np.all(a.state.kappa.numpy() == 0.0) and b.state.kappa is None


def test_a_band_wider_than_the_snap_back_limit_is_refused():
    mat = cracking()
    limit = 2 * E * GF / ST**2
    assert mat.max_band_width == pytest.approx(limit)
    with pytest.raises(InvalidArgument, match=r"band_width = 0.1 .*narrower than 2 E G_f / sigma_t\^2 = 0.08 m"):
        cracking(band_width=0.1).validate("slab")
    with pytest.raises(InvalidArgument, match="tensile_strength"):
        cracking(tensile_strength=0.0).validate()


@pytest.mark.slow
def test_plane_strain_softens_the_in_plane_stress_as_3d_does():
    # stretch along x with y stress-free and z fixed: the 2D kernels against the 3D ones (the out-of-plane stress
    # tau_zz = lam tr(eps) is not softened in 2D, where it does not act on the grid; the in-plane path is the same)
    mat = cracking()
    n = 300
    ex = np.linspace(1.2 * mat.failure_stress / E / n, 1.2 * mat.failure_stress / E, n)
    F3 = np.tile(np.eye(3), (n, 1, 1))
    F3[:, 0, 0] = np.exp(ex)
    F2 = F3[:, :2, :2].copy()
    a = drive_material_points(F_total=F3, material=mat, dtype="float64", stress_tol=1e-6,
                              stress_control={"axes": (False, True, False), "sigma": (0.0, 0.0, 0.0)})
    b = drive_material_points(F_total=F2, material=mat, dtype="float64", stress_tol=1e-6,
                              stress_control={"axes": (False, True), "sigma": (0.0, 0.0)})
    assert a["damage"][0, -1] == 1.0 and b["damage"][0, -1] == 1.0
    np.testing.assert_allclose(b["stress"][0, :, 0, 0], a["stress"][0, :, 0, 0], rtol=1e-6, atol=1e-6 * ST)
    np.testing.assert_allclose(b["damage"][0], a["damage"][0], rtol=1e-9, atol=1e-12)


def test_a_slab_that_cannot_break_launches_and_allocates_nothing_of_cracking():
    """Leave-out: the homogeneous PST without ``slab_fracture`` launches the same kernels as before the
    feature existed (no P2G kernel of the cracking model), holds kappa for the weak layer only and writes no
    damage field; with it, the slab's P2G launches are the cracking ones and nothing else changes."""
    from helpers_scenes import TINY_PST

    from mpm_warp.loader import load_scenario

    def sim(extra):
        return mw.Simulation(load_scenario("pst_demo", TINY_PST + extra), device="cpu", n_threads=1)

    off, on = sim([]), sim(["scene.slab_fracture=true"])
    models = {g.name: g.material.model for g in off.model.groups}
    assert "tensile_cracking" not in models.values() and models["slab"] == "elastic"
    assert {g.name: g.material.model for g in on.model.groups}["slab"] == "tensile_cracking"
    weak = [g for g in off.model.groups if g.material.model == "bonded_camclay"]
    assert off.state.kappa.shape[0] == sum(g.count for g in weak) < off.model.n_particles
    assert "damage" not in off.scenario.output.fields
    k_off = [launch.kernel for launch in off.stepper.launches]
    k_on = [launch.kernel for launch in on.stepper.launches]
    assert len(k_off) == len(k_on)
    differ = [(a, b) for a, b in zip(k_off, k_on, strict=True) if a is not b]
    assert len(differ) == 1 and differ[0][0].key == differ[0][1].key == "p2g_kernel__locals__p2g"  # the slab's P2G
    cracking_kernels = {b for _, b in differ}
    assert not cracking_kernels & set(k_off)


def notched_bar_dissipation(dx, band_width, v=0.02):
    """A plane-strain bar 8 x 4 cm (E 1 MPa, nu 0, sigma_t 2 kPa, G_f 0.2 J/m^2, 2 particles per cell) with two
    90-degree V notches 1 cm deep, clamped at one end and pulled at ``v`` at the other until it is in two.
    Returns the energy the damage spent, in the ligament's rows and in the whole bar, over G_f x ligament:
    each particle's from its ``kappa`` by the uniaxial closed form (the area under the softening law to
    ``kappa`` less the secant unloading), and the wall's work less the elastic and kinetic energy left."""
    E_, ST_, GF_, L, W, n = 1e6, 2e3, 0.2, 0.08, 0.04, 0.01
    mat = mw.CrackingSnow(E_, 0.0, RHO, tensile_strength=ST_, fracture_energy=GF_, band_width=band_width)
    xm = 0.04
    blocks = (mw.Block("m", (0.0, 0.0), (xm, W), name="a", halfspaces=((1.0, 1.0, xm + W - n), (1.0, -1.0, xm - n))),
              mw.Block("m", (xm, 0.0), (L, W), name="b", halfspaces=((-1.0, 1.0, W - n - xm), (-1.0, -1.0, -n - xm))))
    ramp = 0.002
    walls = (mw.Wall((0.5 * dx, 0.0), (1.0, 0.0), kind="sticky", name="l"),
             mw.Wall((L - 0.5 * dx, 0.0), (-1.0, 0.0), kind="sticky", velocity=(v, 0.0), ramp_time=ramp, name="r"))
    t_end = (2 * ST_ / E_ * L + 6 * 2 * GF_ / ST_) / v + ramp / 2     # twice the elastic stretch + 6 crack openings
    sc = mw.Scenario(name="notched", domain=mw.Domain(lo=(-0.02, -0.02), hi=(L + 0.03, W + 0.02), dx=dx,
                                                      boundary="slip", dimension=2),
                     time=mw.TimeControl(end=t_end, frame_interval=t_end, gravity=(0.0, 0.0)),
                     materials={"m": mat}, walls=walls, precision="float64", blocks=blocks)
    sim = mw.Simulation(sc, device="cpu", n_threads=1)
    right = sim.model.wall_names.index("r")
    work, tp = 0.0, 0.0
    for t in np.linspace(0.0, t_end, 201)[1:]:
        sim.step_to(t)
        work -= sim.stepper.take_wall_impulse()[right, 0] * v * min(0.5 * (t + tp) / ramp, 1.0)
        tp = t
    en = sim.energies()
    kap = np.concatenate([sim.group_state(g).kappa.numpy() for g in "ab"]).astype(float)
    y0 = np.concatenate([sim.group_state(g).x0 for g in "ab"])[:, 1]
    et, ef = ST_ / E_, mat.failure_stress / E_
    e = np.clip(kap / E_, et, ef)
    s = ST_ * (ef - e) / (ef - et)
    vol = sim.group_state("a").vol0
    spent = np.where(kap > ST_, 0.5 * ST_ * et + 0.5 * (ST_ + s) * (e - et) - 0.5 * s * e, 0.0) * vol
    gfa = GF_ * (W - 2 * n)
    lig = (y0 > n) & (y0 < W - n)
    return spent[lig].sum() / gfa, spent.sum() / gfa, (work - en["kinetic_energy"] - en["elastic_energy"]) / gfa


@pytest.mark.slow
def test_a_notched_bar_spends_the_fracture_energy_over_its_ligament():
    """The crack band of the PST (docs/model.md §9): with ``h = 1.5 dx`` a notched bar, whose crack starts at the
    notch tips as a slab's does at its surface, spends G_f over the ligament at two cell sizes. The crack
    breaks three particle columns and a fourth in part: measured 1.12 and 1.07 G_f x ligament in the ligament's
    rows at dx = 5 and 2.5 mm, 1.45 and 1.26 in the whole bar (the particles beside the notch tips, one row
    each, a share that halves with dx). The tolerance, 15 %, is the fourth column's part. With one particle
    spacing as the band (``h = dx / 2``, the PST's band before) the same bar spent 2.7 G_f x ligament."""
    from mpm_warp.scenes.pst.params import CRACK_BAND_CELLS
    got = {dx: notched_bar_dissipation(dx, CRACK_BAND_CELLS * dx) for dx in (0.005, 0.0025)}
    for dx, (lig, whole, balance) in got.items():
        assert lig == pytest.approx(1.0, abs=0.15), (dx, lig)
        assert lig < whole < 1.5 and balance > 0.95 * whole, (dx, whole, balance)
    assert got[0.0025][1] < got[0.005][1]          # the excess beside the notch tips shrinks with the cell
