"""Stability of the explicit time step: the CFL limit, blow-ups and the health check.

A free 20 x 20 cm elastic block in a breathing mode (plane strain, dx = 2 cm,
float32) runs with the automatic step (C = 0.4 and 1: energy bounded) and
with fixed steps dt = k dx / c_p: measured stability limit dt ~ 1.11 dx / c_p
(k = 1.10 runs 2000 steps, k = 1.12 blows up by step 60); above it the health
check stops the run naming step, particle and cause, keeps the complete frames
and points to the last good checkpoint, also when frames are shorter than
``output.health_every`` steps. docs/validation.md "Stability and extreme inputs".
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE
from helpers_stability import check_blowup

import mpm_warp as mw
from mpm_warp.io import checkpoint_path_for, read_checkpoint

# ---------------------------------------------------------------- CFL sweep
BREATHING_MAT = mw.Elastic(1.0e6, 0.3, 250.0)   # c_p = 73.4 m/s
BREATHING_DX = 0.02


def _breathing_block(*, cfl: float = 0.4, dt: float = 0.0, end: float, frame_interval: float,
                     output: mw.Output | None = None) -> mw.Scenario:
    """A free 20 x 20 cm block (one 4 cm layer, plane strain) in a breathing mode, no gravity.

    Initial velocity ``(10 (x - 0.2), -10 (y - 0.2), 0)`` m/s: at most 1 m/s,
    strains about 1 %; 1600 particles.
    """
    def breathing(x):
        v = np.zeros_like(x)
        v[:, 0] = 10.0 * (x[:, 0] - 0.2)
        v[:, 1] = -10.0 * (x[:, 1] - 0.2)
        return v

    dx = BREATHING_DX
    return mw.Scenario(
        name="breathing_block",
        domain=mw.Domain((0.0, 0.0, 0.0), (0.4, 0.4, 2 * dx), dx, boundary="slip", boundary_faces="z"),
        time=mw.TimeControl(end=end, frame_interval=frame_interval, cfl=cfl, dt=dt, gravity=(0.0, 0.0, 0.0),
                            allow_unstable_dt=True),           # the steps beyond the limit are measured here
        materials={"snow": BREATHING_MAT},
        blocks=(mw.Block("snow", (0.1, 0.1, 0.0), (0.3, 0.3, 2 * dx), velocity=breathing),),
        output=output or mw.Output(health_every=10),
    )


def _energy_history(sim: mw.Simulation) -> tuple[np.ndarray, mw.RunResult]:
    """Run; return kinetic + elastic energy at t = 0 and after every frame (J), and the result."""
    e = [sum(sim.energies().values())]
    res = sim.run(None, callback=lambda s, f: e.append(sum(s.energies().values())))
    return np.asarray(e), res


@pytest.mark.parametrize("cfl, bound", [(0.4, 1.10), (1.0, 1.25)])
def test_cfl_automatic_step_energy_bounded(cfl, bound):
    """Automatic step (default C = 0.4, and the largest allowed C = 1): energy stays bounded.

    600 steps (about 20 breathing periods), energy sampled every 10 steps.
    Measured max E / E0: 1.045 (C = 0.4), 1.135 (C = 1), in the first 20 steps
    (the sampled energy, particle kinetic + elastic, is not the quantity the
    symplectic step conserves, and leaves out the APIC affine part); the energy
    then decays (APIC dissipation) to 0.54 E0 (C = 0.4), 0.31 E0 (C = 1); no blow-up.
    """
    c_p = BREATHING_MAT.p_wave_speed
    dt_est = cfl * BREATHING_DX / (c_p + 1.0)
    end = 600 * dt_est
    sim = mw.Simulation(_breathing_block(cfl=cfl, end=end, frame_interval=10 * dt_est), device=DEVICE)
    e, res = _energy_history(sim)
    print(f"cfl {cfl}: {res.steps} steps, max E/E0 {e.max() / e[0]:.4f}, end E/E0 {e[-1] / e[0]:.4f}")
    assert res.steps == pytest.approx(600, rel=0.02)
    assert np.isfinite(e).all()
    assert e.max() <= bound * e[0]
    assert e[-10:].max() <= e[0]
    sim.health()


def test_cfl_sweep_fixed_step_never_silent():
    """Fixed steps dt = k dx / c_p: each run either ends with bounded energy or stops with a clear error.

    300 steps per factor. Measured limit: k = 1.10 runs (2000 steps too,
    max E/E0 1.12), k = 1.12 blows up (energy x42 by step 60, caught at step 60),
    so the stability limit of this MLS-MPM step is dt ~ 1.11 dx / c_p: every
    allowed ``time.cfl`` (<= 1) is stable here, the default 0.4 has a margin of
    2.8. Above the limit the health check stops the run within 10-60 steps
    naming step, particle and cause (|v| dt > dx, or NaN for k = 4).
    """
    c_p = BREATHING_MAT.p_wave_speed
    n_steps = 300
    outcome = {}
    for k in (0.5, 1.0, 1.1, 1.2, 1.5, 2.0, 4.0):
        dt = k * BREATHING_DX / c_p
        sim = mw.Simulation(_breathing_block(dt=dt, end=n_steps * dt, frame_interval=10 * dt), device=DEVICE)
        try:
            e, res = _energy_history(sim)
        except mw.SimulationBlowUp as err:
            check_blowup(err, sim.model.n_particles)
            assert err.step <= n_steps
            outcome[k] = f"blow-up at step {err.step} (particle {err.particle}, {err.field})"
            continue
        # completed: never a silent growth
        assert res.steps == n_steps
        assert np.isfinite(e).all()
        assert e.max() <= 1.25 * e[0], f"k = {k}: energy grew to {e.max() / e[0]:.3f} E0 without an error"
        outcome[k] = f"ok, max E/E0 {e.max() / e[0]:.3f}"
    print("fixed dt = k dx / c_p:", outcome)
    assert all(outcome[k].startswith("ok") for k in (0.5, 1.0, 1.1))
    assert all(outcome[k].startswith("blow-up") for k in (1.2, 1.5, 2.0, 4.0))


def test_blowup_in_run_keeps_frames_and_points_to_checkpoint(tmp_path):
    """run() with dt = 1.2 dx / c_p: SimulationBlowUp names the complete frames and the last good checkpoint.

    Frames of 10 steps, a checkpoint every frame, health check every 10 steps.
    Measured: stopped at step 30 (particle 0, |v| dt > dx); frames 0-2 kept,
    checkpoint of frame 2.
    """
    c_p = BREATHING_MAT.p_wave_speed
    dt = 1.2 * BREATHING_DX / c_p
    sc = _breathing_block(dt=dt, end=100 * dt, frame_interval=10 * dt,
                          output=mw.Output(fields=("x", "v"), checkpoint_every=1, health_every=10))
    out = str(tmp_path / "blow.h5")
    sim = mw.Simulation(sc, device=DEVICE)
    with pytest.raises(mw.SimulationBlowUp) as info:
        sim.run(out)
    err = info.value
    check_blowup(err, sim.model.n_particles)
    print(f"run stopped: {err}")
    assert err.output == out
    assert err.checkpoint == checkpoint_path_for(out)
    assert out in str(err) and err.checkpoint in str(err)
    run = mw.read_run(out)
    assert run.n_frames == err.step // 10 >= 1   # the frames before the failing batch, complete
    arrays, meta = read_checkpoint(err.checkpoint)
    assert meta["frame_index"] == run.n_frames - 1
    for name in ("x", "v", "H"):
        assert np.isfinite(arrays[name]).all()


def test_health_check_runs_when_frames_are_shorter_than_health_every():
    """Frames of 2 steps, health check every 10 steps, dt = 4 dx / c_p (NaN within 10 steps): must stop.

    FAILS until fixed: ``Simulation.step_to`` restarts its steps-since-check
    counter at every call (every frame) and ``run()`` does no check of its own,
    so with frames shorter than ``output.health_every`` steps the check never
    runs: the run "completes" with every particle NaN, writing NaN frames and
    checkpoints.
    """
    c_p = BREATHING_MAT.p_wave_speed
    dt = 4.0 * BREATHING_DX / c_p
    sc = _breathing_block(dt=dt, end=100 * dt, frame_interval=2 * dt, output=mw.Output(health_every=10))
    sim = mw.Simulation(sc, device=DEVICE)
    with pytest.raises(mw.SimulationBlowUp) as info:
        sim.run(None)
    check_blowup(info.value, sim.model.n_particles)
    assert info.value.step <= 20
