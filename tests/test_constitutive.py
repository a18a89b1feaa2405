"""One constitutive update for the engine and the material-point driver (kernels/constitutive.py).

- The driver fed with the ``dt C`` a particle saw reproduces that particle's
  elastic state and hardening variable bit for bit over 1000 steps, in 2D and
  3D, float32 and float64, elastic and Cam-Clay (the two call the same Warp
  function on the same bits).
- Mixed control: a drained triaxial (constant cell pressure) ends on the
  critical-state line at the closed-form point ``p = 3 s_c / (3 - M)``,
  ``q = M p``; simple shear under a held normal stress keeps it to the
  tolerance; a plane-strain oedometer equals the 3D one.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers_validation import DEVICE

import mpm_warp as mw
from mpm_warp.material_point import drive_material_points

SNOW = mw.CamClaySnow(1.0e6, 0.3, 200.0, M=1.2, beta=0.3, xi=0.5, p0_ini=800.0)


def _sheared_block(dim: int, material, precision: str, dt: float) -> mw.Scenario:
    """A free block compressed and sheared by its initial velocity field (no walls, no gravity), fixed dt."""
    A = np.array([[-2.0, 3.0, 0.5], [1.0, -4.0, 0.0], [0.0, 0.5, -1.0]])[:dim, :dim]

    def vel(x):
        return (x - 0.5) @ A.T

    return mw.Scenario(
        name="sheared", domain=mw.Domain((0.0,) * dim, (1.0,) * dim, 0.1, boundary="none", dimension=dim),
        time=mw.TimeControl(end=1.0, frame_interval=1.0, dt=dt, gravity=(0.0,) * dim),
        materials={"m": material}, blocks=(mw.Block("m", (0.35,) * dim, (0.65,) * dim, velocity=vel),),
        precision=precision)


@pytest.mark.slow
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("model", ["elastic", "camclay"])
def test_driver_is_the_engine_update_bit_for_bit(dim, precision, model):
    mat = SNOW if model == "camclay" else mw.Elastic(SNOW.E, SNOW.nu, SNOW.density)
    dt = 2e-5
    sim = mw.Simulation(_sheared_block(dim, mat, precision, dt), device=DEVICE)
    sim.stepper.set_frame_end(1.0)
    n, picks = 1000, [0, sim.model.n_particles // 2 + 1, sim.model.n_particles - 1]
    np_t = sim.model.np_dtype
    L = np.zeros((len(picks), n, dim, dim), dtype=np_t)
    H = np.zeros((len(picks), n + 1, dim, dim), dtype=np_t)
    lj = np.zeros((len(picks), n + 1), dtype=np_t)
    H[:, 0] = sim.state.H.numpy()[picks]
    if model == "camclay":
        lj[:, 0] = sim.state.log_jp.numpy()[picks]
    for k in range(n):
        L[:, k] = np_t(dt) * sim.state.C.numpy()[picks]          # the engine forms dt C in the state's precision
        sim.stepper.steps(1)
        H[:, k + 1] = sim.state.H.numpy()[picks]
        if model == "camclay":
            lj[:, k + 1] = sim.state.log_jp.numpy()[picks]
    r = drive_material_points(L_path=L, material=mat, dtype=precision, device=DEVICE)
    np.testing.assert_array_equal(r["H"], H)
    if model == "camclay":
        np.testing.assert_array_equal(r["log_jp"], lj)
        assert r["yielded"].sum() > 100  # the return really worked
        assert np.abs(lj[:, -1] - lj[:, 0]).min() > 1e-3  # finite plastic volume change


def test_drained_triaxial_reaches_the_critical_state():
    """Axial compression at a held cell pressure s_c ends at the apex of the ellipse (the critical state).

    Cauchy stresses: the drained path is ``q = 3 (p - s_c)``; the apex of the
    cohesive ellipse has ``q / p = k = M (1 + beta) / ((1 - beta) sqrt(1 + 2 beta))``
    (docs/model.md §2), so the path ends at ``p = 3 s_c / (3 - k)``, ``q = k p``, where the
    plastic volume stops changing. Measured after 100 % axial strain: p and q/p
    within 7e-7 (0.5 % short after 30 %: the approach is asymptotic).
    """
    mat = mw.CamClaySnow(1.0e6, 0.3, 200.0, M=1.2, beta=0.3, xi=0.5, p0_ini=2000.0)
    s_c = 1000.0
    n = 8000
    L = np.zeros((n, 3, 3))
    L[:, 1, 1] = -1.0 / n                                   # axial (y) compression, 100 % logarithmic strain
    r = drive_material_points(L_path=L, material=mat, dtype="float64", device=DEVICE, stress_tol=1e-6,
                              stress_control={"axes": (True, False, True), "sigma": (-s_c, 0.0, -s_c)})
    sig = r["stress"][0]
    p = -np.trace(sig, axis1=1, axis2=2) / 3.0
    q = np.abs(sig[:, 1, 1] - sig[:, 0, 0])
    k = mat.M * (1 + mat.beta) / ((1 - mat.beta) * np.sqrt(1 + 2 * mat.beta))
    p_cs = 3.0 * s_c / (3.0 - k)
    print(f"triaxial end: p {p[-1]:.3f} Pa (closed form {p_cs:.3f}), q/p {q[-1] / p[-1]:.6f} (k = {k:.6f}), "
          f"largest control residual {r['control_residual'].max():.2e} Pa")
    assert r["control_residual"].max() <= 1e-6
    np.testing.assert_allclose(sig[1:, 0, 0], -s_c, rtol=0, atol=1e-6)
    axial = sig[:, 1, 1] < sig[:, 0, 0]   # once the axial stress passes the cell pressure: the drained stress path
    assert axial[-n // 2:].all()
    np.testing.assert_allclose(q[axial], 3.0 * (p[axial] - s_c), rtol=0, atol=1e-5)
    assert p[-1] == pytest.approx(p_cs, rel=1e-5)
    assert q[-1] / p[-1] == pytest.approx(k, rel=1e-5)
    assert abs(r["log_jp"][0, -1] - r["log_jp"][0, -2]) < 1e-9   # no more plastic volume change


def test_simple_shear_under_held_normal_stress():
    """Shear strain 5 % at sigma_yy = -1.5 kPa with no lateral strain (plane strain): the normal stress is held.

    The layer is consolidated above the load (p0_ini = 4 kPa), as a weak layer
    under its slab: the held stress lies inside the yield surface from the
    first increment (with explicit hardening, a target outside the current
    surface cannot be reached within one increment).
    """
    s_n = 1500.0
    n = 500
    mat = mw.CamClaySnow(1.0e6, 0.3, 200.0, M=1.2, beta=0.3, xi=0.5, p0_ini=4000.0)
    L = np.zeros((n, 2, 2))
    L[:, 0, 1] = 0.05 / n
    r = drive_material_points(L_path=L, material=mat, dtype="float64", device=DEVICE, stress_tol=1e-6,
                              stress_control={"axes": (False, True), "sigma": (0.0, -s_n)})
    np.testing.assert_allclose(r["stress"][0, 1:, 1, 1], -s_n, rtol=0, atol=1e-6)
    assert r["yielded"].sum() > 100 and r["q"][0, -1] > 0
    assert np.all(r["L"][0, :, 0, 0] == 0.0) and np.all(r["L"][0, :, 0, 1] == 0.05 / n)  # strain-controlled entries


def test_plane_strain_oedometer_equals_3d():
    """Uniaxial compression (strain control) of a point: the plane-strain update equals the 3D one."""
    n = 300
    L3 = np.zeros((n, 3, 3))
    L3[:, 1, 1] = -0.1 / n
    r3 = drive_material_points(L_path=L3, material=SNOW, dtype="float64", device=DEVICE)
    r2 = drive_material_points(L_path=L3[:, :2, :2], material=SNOW, dtype="float64", device=DEVICE)
    np.testing.assert_allclose(r2["log_jp"], r3["log_jp"], rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(r2["stress"], r3["stress"], rtol=1e-10, atol=1e-9)
    assert r3["yielded"].sum() > 100


def test_driver_takes_initial_states_and_reports_trial_strains():
    """A point started at a given F_E and log_Jp; eps_trial of an increment is ln of the trial stretches."""
    F0 = np.diag([1.001, 0.998, 1.0])
    L = np.zeros((1, 3, 3))
    L[0, 0, 0] = 1e-3
    r = drive_material_points(L_path=L, material=SNOW, F_E0=F0, log_jp0=-0.2, dtype="float64", device=DEVICE)
    np.testing.assert_allclose(r["F_E"][0, 0], F0, rtol=0, atol=1e-15)
    assert r["log_jp"][0, 0] == -0.2
    np.testing.assert_allclose(np.sort(r["eps_trial"][0, 1]), np.sort(np.log([1.001 * 1.001, 0.998, 1.0])),
                               rtol=0, atol=1e-13)


WL = mw.BondedCamClay(1.0e6, 0.3, 150.0, M=1.2, beta=0.3, xi=0.01, p_bond=1500.0, kappa_s=20.0)


@pytest.mark.slow
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_driver_is_the_engine_update_for_the_bonded_layer(dim, precision):
    """Bonded weak layer: with one particle per lattice column (a layer one particle thick) the column mean of
    kappa leaves it as the update made it, and the driver follows the particles bit for bit, kappa included."""
    dt = 2e-5
    A = np.array([[-2.0, 8.0, 0.0], [0.0, -6.0, 0.0], [0.0, 0.0, -1.0]])[:dim, :dim]
    sc = mw.Scenario(
        name="layer", domain=mw.Domain((0.0,) * dim, (1.0,) * dim, 0.1, boundary="none", dimension=dim),
        time=mw.TimeControl(end=1.0, frame_interval=1.0, dt=dt, gravity=(0.0,) * dim),
        materials={"wl": WL}, precision=precision,
        blocks=(mw.Block("wl", (0.3, 0.45, 0.3)[:dim], (0.7, 0.5, 0.7)[:dim], particles_per_cell=2,
                         velocity=lambda x: (x - 0.5) @ A.T),))
    sim = mw.Simulation(sc, device=DEVICE)
    assert sim.model.groups[0].n_columns == sim.model.n_particles    # one particle across the layer
    sim.stepper.set_frame_end(1.0)
    n, picks = 600, [0, 3, sim.model.n_particles - 1]
    np_t = sim.model.np_dtype
    L = np.zeros((len(picks), n, dim, dim), dtype=np_t)
    H = np.zeros((len(picks), n + 1, dim, dim), dtype=np_t)
    kap = np.zeros((len(picks), n + 1), dtype=np_t)
    for k in range(n):
        L[:, k] = np_t(dt) * sim.state.C.numpy()[picks]
        sim.stepper.steps(1)
        H[:, k + 1] = sim.state.H.numpy()[picks]
        kap[:, k + 1] = sim.state.kappa.numpy()[picks]
    r = drive_material_points(L_path=L, material=WL, dtype=precision, device=DEVICE)
    np.testing.assert_array_equal(r["H"][:, 1:], H[:, 1:])
    np.testing.assert_array_equal(r["kappa"][:, 1:], kap[:, 1:])
    assert kap[:, -1].min() > 0.2 * WL.kappa_s and r["yielded"].sum() > 50   # the bond really softened


def test_kappa_is_the_column_mean_across_the_layer():
    """A bonded layer four cells thick sheared in the engine: after every step each lattice column (one bed
    position across the layer) carries one kappa, the mean of what its particles' returns added."""
    dim = 2
    def shear(x):                                                    # simple shear with a little compaction
        return np.stack([50.0 * (x[:, 1] - 0.4), -2.0 * (x[:, 1] - 0.4)], axis=1)

    sc = mw.Scenario(
        name="layer", domain=mw.Domain((0.0, 0.0), (1.0, 1.0), 0.02, boundary="none", dimension=dim),
        time=mw.TimeControl(end=1.0, frame_interval=1.0, dt=1e-5, gravity=(0.0, 0.0)),
        materials={"wl": WL}, precision="float64",
        blocks=(mw.Block("wl", (0.3, 0.4), (0.7, 0.48), velocity=shear),))
    sim = mw.Simulation(sc, device=DEVICE)
    g = sim.model.groups[0]
    assert g.n_columns == 40 and g.count == 40 * 8                   # 0.4 m / 1 cm lattice, 8 particles across
    sim.stepper.set_frame_end(1.0)
    sim.stepper.steps(200)
    kappa = sim.state.kappa.numpy()
    per_column = [kappa[g.columns == c] for c in range(g.n_columns)]
    assert max(np.ptp(k) for k in per_column) == 0.0
    assert np.mean([k[0] > 0.0 for k in per_column]) > 0.9           # the layer yielded (not at its free ends)
