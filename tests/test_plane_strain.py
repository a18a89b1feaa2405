"""True 2D plane-strain kernels (``domain.dimension = 2``) against the quasi-2D 3D slab and the closed forms.

A quasi-2D scene is a 3D slab one cell thick between slip z faces: every node
of its grid lies on or beyond a z wall, so v_z = 0 everywhere and the in-plane
fields of its two particle layers are those of the 2D scene, node by node (the
z weights of a particle sum to one). The 2D kernels must therefore reproduce the
slab to round-off, not just within discretisation error; measured (float64):
positions identical, velocities within 2e-15 relative, on an elastic bar with a
sticky end, a column under gravity, a block sliding on a Coulomb floor and a
Cam-Clay layer compacting under a slab. Tolerances: 1e-12 relative in float64.
Against the closed forms, the 2D runs meet the same bounds as the 3D tests.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from helpers_validation import DEVICE, apic_momenta, block_on_floor, slope_gravity

import mpm_warp as mw
from mpm_warp.errors import SimulationBlowUp
from mpm_warp.validation import axial_bar, fixed_free_bar, self_weight_column
from mpm_warp.validation.weak_layer import weak_layer_column

ROUNDOFF = 1e-12


def as_plane_strain(sc: mw.Scenario) -> mw.Scenario:
    """The 2D scene of a quasi-2D slab (z components dropped, z walls removed)."""
    d = sc.domain

    def v2(v):
        return None if v is None else tuple(v[:2])

    def block(b):
        vel = b.velocity
        if callable(vel):
            def vel(x, f=b.velocity):
                return np.asarray(f(np.pad(x, ((0, 0), (0, 1)))))[:, :2]
        return replace(b, lo=v2(b.lo), hi=v2(b.hi), velocity=vel if callable(vel) else v2(vel))

    walls = tuple(replace(w, point=v2(w.point), normal=v2(w.normal), velocity=v2(w.velocity))
                  for w in sc.walls if abs(w.normal[2]) < 1e-12)
    return replace(sc, domain=replace(d, lo=v2(d.lo), hi=v2(d.hi), dimension=2,
                                      boundary_faces=d.boundary_faces.replace("z", "")),
                   time=replace(sc.time, gravity=v2(sc.time.gravity)),
                   blocks=tuple(block(b) for b in sc.blocks), walls=walls).validate()


def _pair(sc3: mw.Scenario, t_end: float):
    """Run the slab and its 2D scene to ``t_end``; return both simulations (3D first)."""
    out = []
    for sc in (sc3, as_plane_strain(sc3)):
        sim = mw.Simulation(sc, device=DEVICE)
        sim.step_to(t_end)
        out.append(sim)
    return out


def _assert_same(s3: mw.Simulation, s2: mw.Simulation, tol: float = ROUNDOFF):
    """The slab's first particle layer (z fastest in the lattice) equals the 2D particles."""
    assert s3.model.n_particles == 2 * s2.model.n_particles
    assert s3.stepper.clock()[2] == s2.stepper.clock()[2]  # the same number of steps
    dx = s2.model.dx
    x3 = s3.state.x.numpy().astype(np.float64)
    np.testing.assert_allclose(x3[0::2, :2], x3[1::2, :2], rtol=0, atol=tol * dx)  # the two layers move together
    np.testing.assert_allclose(x3[0::2, :2], s2.state.x.numpy(), rtol=0, atol=tol * dx)
    v3 = s3.state.v.numpy().astype(np.float64)[0::2]
    v2 = s2.state.v.numpy().astype(np.float64)
    vs = max(np.abs(v2).max(), 1e-30)
    assert np.abs(v3[:, 2]).max() <= tol * vs
    np.testing.assert_allclose(v3[:, :2], v2, rtol=0, atol=tol * vs)
    _, _, sig3 = s3.stresses(cauchy=True)
    _, _, sig2 = s2.stresses(cauchy=True)
    ss = max(np.abs(sig2).max(), 1e-30)
    np.testing.assert_allclose(sig3[0::2], sig2, rtol=0, atol=tol * ss)
    if s2.state.log_jp is not None:
        lj3 = s3.state.log_jp.numpy().astype(np.float64)
        np.testing.assert_allclose(lj3[0::2], s2.state.log_jp.numpy(), rtol=0, atol=tol * max(np.abs(lj3).max(), 1))


def test_bar_2d_equals_slab():
    sc, T = fixed_free_bar(length=1.0, E=1e6, nu=0.3, density=250.0, v0=0.05, dx=1 / 32, precision="float64")
    s3, s2 = _pair(sc, 0.3 * T)
    _assert_same(s3, s2)


def test_column_under_gravity_2d_equals_slab():
    sc = mw.validation.elastic.column_scenario(1 / 16, precision="float64")[0]
    s3, s2 = _pair(sc, 0.05)
    _assert_same(s3, s2)
    assert s2.energies()["elastic_energy"] > 0


def test_coulomb_slide_2d_equals_slab():
    sc = block_on_floor(kind="separate", friction=0.3, gravity=slope_gravity(30.0), gravity_ramp=0.02,
                        end=0.1, precision="float64")
    s3, s2 = _pair(sc, 0.06)
    _assert_same(s3, s2)
    assert s2.state.v.numpy()[:, 0].mean() > 0.05  # it slides


def test_weak_layer_compaction_2d_equals_slab():
    """Cam-Clay layer compacting under a slab (the return active on the cap): 2D = slab to round-off."""
    sc, mat, info = weak_layer_column(dx=1.0 / 128.0, xi=0.01, rho_slab=2400.0, precision="float64")
    s3, s2 = _pair(sc, 0.12)
    _assert_same(s3, s2)
    lj = s2.state.log_jp.numpy()
    assert (lj < mat.initial_log_jp - 1e-3).all()  # every layer particle compacted (yielded)


# ---------------------------------------------------------------- closed forms in 2D
def test_axial_bar_period_2d():
    """Mode-1 period 4 L / c of the fixed-free bar in 2D: the 3D test's bound (0.5 % at dx = L/50)."""
    rec = axial_bar(0.5, dimension=2)
    print(f"2D axial bar period error {rec['error']:+.4f}")
    assert abs(rec["error"]) < 0.005


def test_p_wave_speed_2d():
    """c_p = sqrt((lam + 2 mu)/rho) from the bar period in plane strain (nu 0.3: 73.4 m/s) within 2 %."""
    mat = mw.Elastic(1.0e6, 0.3, 250.0)
    sc, _ = fixed_free_bar(length=1.0, E=mat.E, nu=mat.nu, density=mat.density, v0=0.05, dx=1 / 32,
                           width_cells=2, dimension=2)
    T, _, _, sim = mw.validation.bar_period(sc)
    err = 4.0 / T / mat.p_wave_speed - 1.0
    print(f"2D c_p error {err:+.4f}")
    assert abs(err) < 0.02
    F = sim.state.elastic_deformation_gradient()
    assert np.abs(F[:, 1, 1] - 1).max() < 1e-5 and np.abs(F[:, 2, 2] - 1).max() == 0.0  # elastic: F_zz = 1


@pytest.mark.slow
def test_self_weight_column_2d():
    """sigma_yy = -rho g (H - Y) at rest, 2D, within the 3D test's bound (1 % of rho g H at 16 cells)."""
    rec = self_weight_column(1.0 / 16.0, dimension=2)
    print(f"2D column: RMS error {rec['error']:.2e} of rho g H")
    assert rec["error"] < 0.01


def test_coulomb_slide_acceleration_2d():
    """a = g (sin 30 - 0.3 cos 30) on a separable Coulomb floor, 2D, within 2 %."""
    sc = as_plane_strain(block_on_floor(kind="separate", friction=0.3, gravity=slope_gravity(30.0),
                                        gravity_ramp=0.02, end=0.4, frame_interval=0.005))
    sim = mw.Simulation(sc, device=DEVICE)
    t, v = [], []

    def sample(s, frame):
        t.append(s.time)
        v.append(s.state.v.numpy()[:, 0].astype(np.float64).mean())

    sim.run(None, callback=sample)
    t, v = np.array(t), np.array(v)
    a = np.polyfit(t[t >= 0.1], v[t >= 0.1], 1)[0]
    a_exact = 9.81 * (math.sin(math.radians(30)) - 0.3 * math.cos(math.radians(30)))
    print(f"2D slide a = {a:.5f}, exact {a_exact:.5f}")
    assert a == pytest.approx(a_exact, rel=0.02)


# ---------------------------------------------------------------- identities in 2D
def _free_2d(velocity, dt=2e-4, E=2e4, precision="float64", gravity=(0.0, 0.0)):
    return mw.Scenario(
        name="free2d", domain=mw.Domain((0.0, 0.0), (1.0, 1.0), 0.05, boundary="none", dimension=2),
        time=mw.TimeControl(end=1.0, frame_interval=1.0, dt=dt, gravity=gravity),
        materials={"m": mw.Elastic(E, 0.25, 100.0)},
        blocks=(mw.Block("m", (0.3, 0.3), (0.7, 0.6), velocity=velocity),), precision=precision)


def test_momentum_conserved_2d():
    """Linear and angular momentum (with the APIC spin term) conserved to round-off in 2D, float64."""
    def vel(x):
        return np.stack([0.2 - 1.5 * (x[:, 1] - 0.5) + 0.05 * np.sin(7 * x[:, 1]),
                         -0.1 + 1.5 * (x[:, 0] - 0.5) + 0.05 * np.sin(11 * x[:, 0])], axis=1)

    sim = mw.Simulation(_free_2d(vel), device=DEVICE)
    P0, L0 = apic_momenta(sim)
    sim.stepper.set_frame_end(1.0)
    sim.stepper.steps(200)
    P1, L1 = apic_momenta(sim)
    assert sim.energies()["elastic_energy"] > 0.0
    np.testing.assert_allclose(P1, P0, rtol=0, atol=1e-12 * np.abs(P0).max())
    assert abs(L1 - L0) <= 1e-10 * abs(L0)


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_affine_field_survives_p2g_g2p_2d(precision):
    """APIC/MLS reproduce v = b + A x in 2D: after one step v_p = b + A x_p and C = A."""
    b = np.array([0.3, -0.2])
    A = np.array([[0.1, 0.4], [-0.3, 0.05]])
    sim = mw.Simulation(_free_2d(lambda x: b + x @ A.T, dt=1e-7, E=1e-3, precision=precision), device=DEVICE)
    sim.state.C.assign(np.broadcast_to(A, (sim.model.n_particles, 2, 2)).astype(sim.model.np_dtype))
    x_old = sim.state.x.numpy().astype(np.float64)
    sim.stepper.set_frame_end(1.0)
    sim.stepper.steps(1)
    tol = 2e-5 if precision == "float32" else 1e-10
    np.testing.assert_allclose(sim.state.v.numpy(), b + x_old @ A.T, atol=tol)
    np.testing.assert_allclose(sim.state.C.numpy(), np.broadcast_to(A, (sim.model.n_particles, 2, 2)), atol=20 * tol)


def test_free_fall_exact_2d():
    g = np.array([0.0, -9.81])
    dt = 1e-3
    sim = mw.Simulation(_free_2d(None, dt=dt, gravity=tuple(g)), device=DEVICE)
    x0 = sim.state.x.numpy().astype(np.float64)
    sim.step_to(50 * dt)
    np.testing.assert_allclose(sim.state.v.numpy(), np.broadcast_to(50 * g * dt, x0.shape), atol=1e-11)
    np.testing.assert_allclose(sim.state.x.numpy(), x0 + g * dt * dt * 50 * 51 / 2, atol=1e-11)
    p, q = sim.stress_invariants()
    assert np.abs(p).max() < 1e-8 and np.abs(q).max() < 1e-8


def test_health_check_stops_a_2d_run():
    """A non-finite velocity in a 2D run stops it naming the step, the particle and the field."""
    sim = mw.Simulation(_free_2d(None, precision="float32"), device=DEVICE)
    v = sim.state.v.numpy()
    v[7] = (np.nan, 0.0)
    sim.state.v.assign(v)
    with pytest.raises(SimulationBlowUp) as e:
        sim.run(None, end_time=0.01, frame_interval=0.005)
    # the NaN reaches the neighbours through the grid within the step: the smallest offending index is named
    assert 0 <= e.value.particle <= 7 and e.value.field == "x/v/F" and "non-finite" in str(e.value)
    assert e.value.step == 20  # the first health check (output.health_every = 20 steps)


def test_resume_2d_bit_for_bit(tmp_path):
    """A 2D Cam-Clay run interrupted at a frame and resumed equals the uninterrupted run bit for bit (CPU)."""
    sc, _, _ = weak_layer_column(dx=1.0 / 64.0, xi=0.01, rho_slab=2400.0, precision="float32")
    sc = replace(as_plane_strain(sc), time=replace(as_plane_strain(sc).time, end=0.06, frame_interval=0.01),
                 output=mw.Output(fields=("x", "v", "log_jp", "F"), checkpoint_every=1))
    full = tmp_path / "full.h5"
    mw.Simulation(sc, device=DEVICE).run(str(full))
    part = tmp_path / "part.h5"
    sim = mw.Simulation(sc, device=DEVICE)
    sim.run(str(part), callback=lambda s, frame: frame < 3)
    mw.resume(str(part), device=DEVICE)
    a, b = mw.read_run(str(full)), mw.read_run(str(part))
    assert a.n_frames == b.n_frames == 7
    for k in ("x", "v", "log_jp", "F"):
        np.testing.assert_array_equal(a.field(k), b.field(k))
    assert a.frame(-1)["x"].shape[1] == 2


def test_elastic_particles_store_no_out_of_plane_stretch():
    """Plane strain: an elastic particle's F_E,zz is the total, 1, and is not stored; a plastic one's is (hzz,
    indexed as log_jp). F_E round-trips through the state, and an elastic F_zz != 1 is refused by name."""
    sc, _, _ = weak_layer_column(dx=1.0 / 64.0, xi=0.01, rho_slab=2400.0, precision="float64")
    sim = mw.Simulation(as_plane_strain(sc), device=DEVICE)
    m = sim.model
    assert 0 < m.n_plastic < m.n_particles and sim.state.hzz.shape == (m.n_plastic,)
    assert mw.Simulation(_free_2d((0.1, 0.0)), device=DEVICE).state.hzz is None   # elastic only: none at all
    sim.step_to(0.05)                                                 # the layer compacts: F_E,zz moves
    F = sim.state.elastic_deformation_gradient()
    plastic = np.zeros(m.n_particles, bool)
    for g in m.groups:
        plastic[g.start:g.end] = g.plastic_start >= 0
    assert (F[~plastic, 2, 2] == 1.0).all() and (np.abs(F[plastic, 2, 2] - 1.0) > 1e-6).all()
    sim.state.set_elastic_deformation_gradient(F)
    np.testing.assert_array_equal(sim.state.elastic_deformation_gradient(), F)
    F[np.flatnonzero(~plastic)[3], 2, 2] = 1.01
    with pytest.raises(mw.InvalidArgument, match=r"F\[.*2, 2\].*elastic, plane strain.*1\.01"):
        sim.state.set_elastic_deformation_gradient(F)


def test_checkpoint_with_hzz_of_every_particle_loads():
    """A checkpoint of an earlier version holds hzz for every particle (zeros for the elastic ones): it loads."""
    sc, _, _ = weak_layer_column(dx=1.0 / 64.0, xi=0.01, rho_slab=2400.0, precision="float32")
    sim = mw.Simulation(as_plane_strain(sc), device=DEVICE)
    sim.step_to(0.03)
    now = sim.state.arrays()
    old = dict(now, hzz=np.zeros(sim.model.n_particles, now["hzz"].dtype))
    for g in sim.model.groups:
        if g.plastic_start >= 0:
            old["hzz"][g.start:g.end] = now["hzz"][g.plastic_start:g.plastic_start + g.count]
    fresh = mw.Simulation(as_plane_strain(sc), device=DEVICE)
    fresh.state.load_arrays(old)
    for k, a in fresh.state.arrays().items():
        np.testing.assert_array_equal(a, now[k], err_msg=k)
