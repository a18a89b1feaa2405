"""A PST run in true 2D against the same PST run as the quasi-2D slab (``scene.plane_strain = "slab"``).

The slab is a 3D box one cell thick in z between slip walls (tests/test_plane_strain.py): every grid node
lies on or beyond a z wall, so v_z = 0 everywhere and each of its two particle layers is the 2D run, node
by node, up to the order of the floating-point sums (27 stencil nodes against 9). The bonded layer's kappa
is averaged per lattice column (x, z), so each z layer keeps its own column, the 2D one.

The scene: ``TINY_PST`` with a 30 cm slab on a layer of field-low toughness (w_f = 0.1 J/m^2) so that the
crack runs away from the saw in this 0.6 m column (measured in 2D: runaway cut 0.18 m, the damage and
deflection fronts at the far end by 0.23 s), float64. Measured (CPU): up to 0.15 s (saw at 11 cm) the slab's
first layer equals the 2D particles to round-off (positions 1e-16 m, log_jp 2e-17, kappa 7e-15 of 4.7);
then the softening layer amplifies round-off: at 0.16 s kappa differs by 4e-4, and by 0.23 s (crack run)
positions by 3e-7 m (3e-5 dx), log_jp by 5e-5 (of 0.14). The slab's own two layers, identical in exact
arithmetic, drift apart the same way (2e-8 m by 0.23 s): the difference is amplified round-off, not a
difference of model. Tolerances: before 0.15 s, round-off (1e-12 relative); after the crack ran, fronts
and saw identical (measured identical), runaway cut two time steps of saw travel (a bin's arrival is the
median of its particles' step times, which the amplified round-off moves by steps: measured 3e-9 m on one
build and 3.6e-5 m, 1.5 steps of 24.4 us at 1 m/s, after an ulp-level change of the calibration), collapse height 1e-3
relative (measured 2e-4 at most), touchdown one front bin (dx; measured 1.9 mm), positions 1e-3 dx and
log_jp 1e-3 of its range.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers_device import DEVICE
from helpers_scenes import TINY_PST

import mpm_warp as mw
from mpm_warp.errors import InvalidArgument, ScenarioError
from mpm_warp.loader import load_scenario
from mpm_warp.scenes.pst.monitor import attach

ROUNDOFF = 1e-12
#: TINY_PST whose crack runs away from the saw (see the module docstring)
RUNNING = TINY_PST + ["scene.slab_thickness=0.3", "scene.weak_layer.w_f=0.1", "scene.saw.cut_length=0.3",
                      "precision='float64'", "time.end=0.23"]


def test_slab_layout():
    """The slab: z in [0, dx] between slip walls, two particle layers, the 2D scene's x-y layout."""
    s2 = load_scenario("pst_demo", TINY_PST)
    s3 = load_scenario("pst_demo", TINY_PST + ["scene.plane_strain='slab'"])
    dx = s3.scene.dx
    assert s2.domain.dimension == 2 and s3.domain.dimension == 3
    assert s3.domain.lo[2] == 0.0 and s3.domain.hi[2] == dx
    assert s3.domain.lo[:2] == s2.domain.lo and s3.domain.hi[:2] == s2.domain.hi
    walls = {w.name: w for w in mw.Simulation(s3, device=DEVICE, n_threads=1).model.walls}
    assert walls["z_lo"].kind == walls["z_hi"].kind == "slip" and not {"x_lo", "y_lo"} & walls.keys()
    assert all(b.lo[2] == 0.0 and b.hi[2] == dx for b in s3.blocks)
    assert s3.time.gravity == s2.time.gravity + (0.0,)


@pytest.mark.parametrize("override, match", [
    ("scene.plane_strain='3d'", r"scene.plane_strain.*'2d', 'slab'"),
    ("scene.width=0.1 scene.plane_strain='slab'", r"scene.plane_strain.*slab.*width = 0.1"),
])
def test_slab_bad_input(override, match):
    with pytest.raises((ScenarioError, InvalidArgument), match=match):
        load_scenario("pst_demo", TINY_PST + override.split())


T_ROUNDOFF = 0.15  # s: the runs agree to round-off until then (see the module docstring)


def _run(mode: str):
    sim = mw.Simulation(load_scenario("pst_demo", RUNNING + [f"scene.plane_strain='{mode}'"]), device=DEVICE,
                        n_threads=1)
    mon = attach(sim)
    early = {}

    def keep(s, frame):
        if abs(s.time - T_ROUNDOFF) < 1e-9:
            early.update(x=s.state.x.numpy().copy(), log_jp=s.state.log_jp.numpy().copy(),
                         kappa=s.state.kappa.numpy().copy())

    sim.run(None, callback=keep)
    return sim, mon, early


@pytest.mark.slow
def test_pst_2d_equals_slab():
    """Fronts, collapse, touchdown, markers and the first particle layer of the slab against the 2D run's."""
    s2, m2, e2 = _run("2d")
    s3, m3, e3 = _run("slab")
    p = m2.params
    dx = p.dx
    assert s3.model.n_particles == 2 * s2.model.n_particles
    assert s3.stepper.clock()[2] == s2.stepper.clock()[2]  # the same steps
    # the bonded layer averages kappa per (x, z) lattice column: twice the 2D columns, one per z layer
    (w2,) = [g for g in s2.model.groups if g.columns is not None]
    (w3,) = [g for g in s3.model.groups if g.columns is not None]
    assert w3.n_columns == 2 * w2.n_columns
    np.testing.assert_array_equal(w3.columns[0::2] // 2, w2.columns)
    np.testing.assert_array_equal(w3.columns[0::2] + 1, w3.columns[1::2])
    # while the saw cuts (to 0.15 s): round-off
    np.testing.assert_allclose(e3["x"][0::2, :2], e2["x"], rtol=0, atol=ROUNDOFF * dx)
    np.testing.assert_allclose(e3["log_jp"][0::2], e2["log_jp"], rtol=0, atol=ROUNDOFF * np.abs(e2["log_jp"]).max())
    np.testing.assert_allclose(e3["kappa"][0::2], e2["kappa"], rtol=0, atol=ROUNDOFF * np.abs(e2["kappa"]).max())
    # the crack ran away from the saw to the far end, and the debonded layer collapsed
    r2, r3 = m2.result(), m3.result()
    print({k: (r2[k], r3[k]) for k in ("runaway_cut", "touchdown", "collapse_height", "damage_front_final")})
    assert r2["propagated"] and r2["ran_to_end"] and r2["runaway_cut"] < p.saw.cut_length
    assert r2["collapse_height"] > 0.1 * r2["collapse_height_calibrated"]  # measured 0.2 (still collapsing)
    assert r3["propagated"] and r3["ran_to_end"]
    # the same fronts; the collapse and touchdown within the stated tolerances
    assert m2.series.keys() == m3.series.keys()
    for k in ("front", "deflection_front", "saw"):
        np.testing.assert_array_equal(m3.series[k], m2.series[k], err_msg=k)
    np.testing.assert_array_equal(m3.damage_arrival() == np.inf, m2.damage_arrival() == np.inf)
    np.testing.assert_array_equal(m3.deflection_arrival() == np.inf, m2.deflection_arrival() == np.inf)
    c2, c3 = np.asarray(m2.series["collapse_height"]), np.asarray(m3.series["collapse_height"])
    np.testing.assert_allclose(c3, c2, rtol=0, atol=1e-3 * c2.max())
    dt = s2.stepper.clock()[0] / s2.stepper.clock()[2]
    assert abs(r3["runaway_cut"] - r2["runaway_cut"]) <= 2 * p.saw.speed * dt
    assert abs(r3["touchdown"] - r2["touchdown"]) <= p.bin_width
    # the slab's first particle layer (z fastest in the lattice) against the 2D run, and its two layers
    x2, x3 = s2.state.x.numpy(), s3.state.x.numpy()
    lj2, lj3 = s2.state.log_jp.numpy(), s3.state.log_jp.numpy()
    layers = np.abs(x3[0::2, :2] - x3[1::2, :2]).max()
    print(f"end: |x| diff {np.abs(x3[0::2, :2] - x2).max():.1e} m (layers {layers:.1e}),"
          f" |log_jp| diff {np.abs(lj3[0::2] - lj2).max():.1e} of {np.abs(lj2).max():.2f}")
    np.testing.assert_allclose(x3[0::2, :2], x2, rtol=0, atol=1e-3 * dx)
    np.testing.assert_allclose(x3[1::2, :2], x2, rtol=0, atol=1e-3 * dx)
    np.testing.assert_allclose(lj3[0::2], lj2, rtol=0, atol=1e-3 * np.abs(lj2).max())
