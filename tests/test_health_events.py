"""Health checks that can fire: singular-value floor events and inverted elements (``det F_tr <= 0``) counted by
P2G are reported in the RunResult and the CLI summary, and stop the run when ``output.on_inversion = "stop"``."""

from __future__ import annotations

import io as _io

import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp.cli import _summary
from mpm_warp.loader import resolved_scenario


def _crushed(mode: str) -> mw.Simulation:
    """An elastic block whose particle 0 starts with C = -3/dt I: its first trial state is (1 - 3)^3 = -8, inverted."""
    sc = mw.load_scenario("elastic_block", ["time.end=0.03", "time.frame_interval=0.01", "output.health_every=5",
                                            f'output.on_inversion="{mode}"'])
    sim = mw.Simulation(sc, device="cpu")
    C = sim.state.C.numpy()
    C[0] = -3.0 / sim._first_dt() * np.eye(3)
    sim.state.C.assign(C)
    return sim


def test_undisturbed_run_has_no_events():
    res = mw.run("elastic_block", None, "cpu", ["time.end=0.03", "time.frame_interval=0.01"])
    assert (res.floor_events, res.inversions) == (0, 0)
    out = _io.StringIO()
    _summary(res, out)
    assert "inversion" not in out.getvalue()


def test_events_are_reported_and_the_run_goes_on():
    res = _crushed("report").run(None)
    assert res.inversions >= 1 and res.floor_events >= 1 and res.sim_time == pytest.approx(0.03)
    out = _io.StringIO()
    _summary(res, out)
    assert f"; {res.inversions} inversions (det F_tr <= 0) and {res.floor_events} singular-value floor events" \
        in out.getvalue()


def test_events_stop_the_run_when_asked():
    with pytest.raises(mw.SimulationBlowUp) as info:
        _crushed("stop").run(None)
    e = info.value
    assert e.step == 5 and e.particle == -1 and e.field == "F"           # the first health check, after 5 steps
    msg = str(e)
    assert msg.startswith("simulation stopped at step 5: field 'F': 1 inversion (det F_tr <= 0) and ")
    assert "output.on_inversion = 'stop'" in msg


def test_on_inversion_travels_with_the_scenario():
    sc = mw.load_scenario("elastic_block", ['output.on_inversion="stop"'])
    assert sc.output.on_inversion == "stop"
    assert resolved_scenario(sc.to_dict()).output.on_inversion == "stop"
    assert mw.load_scenario("elastic_block").output.on_inversion == "report"


@pytest.mark.parametrize("speed", [float("inf"), float("nan")])
def test_a_step_size_that_falls_to_zero_stops_the_run_instead_of_hanging(speed):
    """A nodal speed that overflows (a diverged field column did) makes the automatic step 0: every later step was a
    no-op and the run never ended (this test hung before). Now it stops at once with one line."""
    sc = mw.load_scenario("elastic_block", ["time.end=0.03", "time.frame_interval=0.01", "output.health_every=5"])
    sim = mw.Simulation(sc, device="cpu")
    sim.stepper.vmax.fill_(speed)                   # the largest nodal speed of the previous step
    with pytest.raises(mw.SimulationBlowUp) as info:
        sim.run(None)
    e = info.value
    assert (e.field, e.step, e.particle) == ("dt", 0, -1)
    assert str(e).startswith("simulation stopped at step 0: field 'dt': the time step fell to ")
    assert "below 1e-06 of the elastic step (0.000109 s): the largest nodal speed is not finite" in str(e)


def test_a_fast_first_step_that_recovers_is_not_stopped():
    """A huge speed bound makes one tiny step; the next takes the real nodal speeds again, and the run goes on."""
    sc = mw.load_scenario("elastic_block", ["time.end=0.03", "time.frame_interval=0.01", "output.health_every=5"])
    sim = mw.Simulation(sc, device="cpu")
    sim.stepper.vmax.fill_(1.0e12)
    assert sim.run(None).sim_time == pytest.approx(0.03)
