"""Derived fields of run files (mpm_warp.post.fields) and their reference states; the device stress field."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers_scenes import TINY_PST

import mpm_warp as mw
from mpm_warp.io import RunWriter, read_run
from mpm_warp.post.fields import FIELDS, FieldReader
from mpm_warp.stress import cauchy_stress, kirchhoff_stress, pressure_and_mises, traction


def _synthetic(path, with_ref: bool) -> str:
    """Three particles over two frames; log_jp starts consolidated at -0.4 (and -0.1 for the third)."""
    lj = np.array([[-0.4, -0.4, -0.1], [-0.5, 0.0, -0.1]])
    ref = np.array([[-0.4, -0.4, -0.1], [-0.4, 0.0, -0.1]])      # the second failed: reference reset to 0
    fields = {"x": ((3,), "float64", "m"), "log_jp": ((), "float64", "1")}
    if with_ref:
        fields["log_jp_ref"] = ((), "float64", "1")
    x0 = np.zeros((3, 3))
    with RunWriter(path, n_particles=3, particle_fields=fields, static_fields={"x0": (x0, "m")}) as w:
        for k in range(2):
            parts = {"x": x0 + [0.0, -0.001 * k, 0.0], "log_jp": lj[k]}
            if with_ref:
                parts["log_jp_ref"] = ref[k]
            w.write_frame(0.1 * k, k, parts)
    return str(path)


def test_collapse_is_relative_to_the_stored_reference_or_to_the_initial_state(tmp_path):
    run = read_run(_synthetic(tmp_path / "ref.h5", True))
    r = FieldReader(run)
    np.testing.assert_allclose(r.values("collapse", run.frame(1)), [1 - math.exp(-0.1), 0.0, 0.0], rtol=1e-14)
    run = read_run(_synthetic(tmp_path / "noref.h5", False))
    r = FieldReader(run)   # no reference stored: the initial state (frame 0) is the reference
    np.testing.assert_allclose(r.values("collapse", run.frame(1)), [1 - math.exp(-0.1), 1 - math.exp(0.4), 0.0],
                               rtol=1e-14)
    assert r.values("collapse", run.frame(0)) == pytest.approx([0.0, 0.0, 0.0], abs=0.0)
    np.testing.assert_allclose(r.values("displacement", run.frame(1)), [0.001] * 3, rtol=1e-12)
    assert r.missing("velocity") == ["v"] and r.missing("collapse") == []
    assert {f.unit for f in FIELDS.values()} <= {"-", "m", "m/s", "Pa"}


#: a small PST: settled at 0.04 s, sawn from then on at 1 m/s, to 0.1 s (log_jp in the output)
PST = TINY_PST + ["time.end=0.1", 'output.fields=["x", "log_jp"]']


@pytest.fixture(scope="module")
def pst_run(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("fields") / "pst.h5")
    res = mw.run("pst_demo", out, "cpu", PST, n_threads=1)
    return read_run(out), res


@pytest.mark.slow
def test_pst_collapse_is_measured_from_the_settled_layer(pst_run):
    """The settled, intact layer has collapse ~0 (not its consolidation 1 - exp(log_jp(0))); the sawn,
    debonded layer collapses under the slab; the monitor's collapse height is the same field."""
    run, res = pst_run
    assert "log_jp_ref" in run.particle_fields and run.units["log_jp_ref"] == "1"
    reader = FieldReader(run)
    wl = run.static["group"] == [g["name"] for g in run.attrs["groups"]].index("weak_layer")
    mon = res.monitor
    params = mon.params
    k_settled = int(np.searchsorted(run.times, params.saw_start - 1e-12))      # the frame at the end of settling
    fr = run.frame(k_settled)
    c = reader.values("collapse", fr)[wl]
    assert np.abs(c).max() < 1e-3
    # 1 - exp(log_jp) is the layer's initial intrinsic consolidation, not a collapse
    mat = params.calibrated().material
    consolidation = 1.0 - math.exp(mat.initial_log_jp)
    np.testing.assert_allclose(1.0 - np.exp(fr["log_jp"][wl].astype(float)), consolidation, atol=2e-3)
    last = run.frame(-1)
    c = reader.values("collapse", last)[wl]
    sawn = mon.weak.sawn.numpy() == 1                                            # behind the blade: debonded
    assert sawn.sum() > 0 and np.all(mon.weak.bond()[sawn] == 0.0)
    assert np.abs(c[~sawn]).max() < 0.01                                          # ahead: still intact
    # the reader's field is the monitor's collapse (what its collapse height averages)
    np.testing.assert_allclose(c, mon.weak.collapse()[0], rtol=1e-5, atol=1e-7)
    assert (reader.values("collapse", last)[~wl] == 0.0).all()                   # the elastic slab: none


# ------------------------------------------------------------------------------- the stress field
def test_device_stress_field_equals_the_host_mirror_and_the_closed_form():
    """The ``stress`` output field (Cauchy, device) against mpm_warp.stress (float64) and a uniaxial stretch."""
    snow = mw.Elastic(1.0e6, 0.3, 250.0)
    sc = mw.Scenario(name="s", domain=mw.Domain((0, 0, 0), (0.1, 0.1, 0.1), 0.05),
                     time=mw.TimeControl(end=0.01, frame_interval=0.01), materials={"snow": snow},
                     blocks=(mw.Block("snow", (0.0, 0.0, 0.0), (0.1, 0.1, 0.1), particles_per_cell=1),),
                     output=mw.Output(fields=("x", "stress")), precision="float64")
    sim = mw.Simulation(sc, device="cpu")
    n = sim.model.n_particles
    rng = np.random.default_rng(3)
    F = np.eye(3) + 0.05 * rng.normal(size=(n, 3, 3))
    a = 1.02
    F[0] = np.diag([a, 1.0, 1.0])
    sim.state.set_elastic_deformation_gradient(F)
    sigma = sim.particle_field("stress")
    assert sigma.shape == (n, 3, 3)
    ref = cauchy_stress(F, snow.mu, snow.lam)
    np.testing.assert_allclose(sigma, ref, atol=1e-9 * np.abs(ref).max())
    e = math.log(a)
    np.testing.assert_allclose(sigma[0], np.diag([(2 * snow.mu + snow.lam) * e, snow.lam * e, snow.lam * e]) / a,
                               rtol=1e-12, atol=1e-9)
    # the Kirchhoff invariants of the engine are J times the Cauchy ones
    p, q = sim.stress_invariants()
    pk, qk = pressure_and_mises(kirchhoff_stress(F, snow.mu, snow.lam))
    np.testing.assert_allclose(p, pk, rtol=1e-10, atol=1e-6)
    np.testing.assert_allclose(q, qk, rtol=1e-9, atol=1e-6)
    ps, _ = pressure_and_mises(sigma)
    np.testing.assert_allclose(ps * np.linalg.det(F), p, rtol=1e-10, atol=1e-6)
    # normal and shear stress on a plane read from the tensor: on the bed plane (normal y) of a simple shear
    sn, tau = traction(sigma[:1], (0.0, 1.0, 0.0))
    assert sn[0] == pytest.approx(sigma[0, 1, 1]) and tau[0] == pytest.approx(0.0, abs=1e-9)


def test_stress_field_in_a_run_file(tmp_path):
    out = str(tmp_path / "block.h5")
    mw.run("elastic_block", out, "cpu", ["time.end=0.06", "time.frame_interval=0.03", 'output.fields=["x", "stress"]'])
    run = read_run(out)
    assert run.units["stress"] == "Pa" and run.frame(-1)["stress"].shape == (run.n_particles, 3, 3)
    s = run.frame(-1)["stress"]
    np.testing.assert_allclose(s, np.transpose(s, (0, 2, 1)), atol=1e-6 * np.abs(s).max())    # symmetric
    reader = FieldReader(run)
    np.testing.assert_array_equal(reader.values("sigma_yy", run.frame(-1)), s[:, 1, 1].astype(float))
    # at t = 0.06 s the block (released 0.1 m above the floor) is still falling: a free fall carries no stress
    assert np.abs(s).max() < 0.01 * 250.0 * 9.81 * 0.1
