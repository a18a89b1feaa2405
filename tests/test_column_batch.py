"""Columns stepped together (mpm_warp.column_batch): each column as its run alone, a decided column stops.

The four field columns are made-up table rows of two outcomes (two cracks that run to the end, two columns the
saw cuts through without a runaway) on 0-35 degree slopes with 4-5 cm weak layers: different geometries, grids,
layers, slopes, saws and decision times. At one fixed step they must match their runs alone bit for bit.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import mpm_warp as mw
from mpm_warp.column_batch import run_columns
from mpm_warp.runner import simulation_for
from mpm_warp.shared_step import SharedStep

COLUMNS = """id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,column_ends
g,End,25,70,25,20,180,5,,0.15,
a,End,0,40,12,15,180,4,,0.3,
b,Arr,0,40,15,15,180,4,,0.5,vertical
e,End,0,60,20,30,200,4,,0.1,
"""


def _field_scenarios(tmp_path):
    from mpm_warp.field.batch import case_scenario, gather
    from mpm_warp.field.protocol import FieldProtocol

    table = tmp_path / "columns.csv"
    table.write_text(COLUMNS)
    cases, refused = gather([str(table)])
    assert not refused and len(cases) == 4
    return [case_scenario(c, FieldProtocol())[0] for c in cases]


def _outcome(res):
    o = res.scene_result.get("outcome", {})
    return (o.get("class"), res.scene_result.get("runaway_cut"), res.scene_result.get("damage_speed_mean"), res.steps,
            res.sim_time)


@pytest.mark.slow
def test_four_field_columns_stepped_together_match_their_runs_alone_at_one_step(tmp_path):
    pytest.importorskip("weac")
    from mpm_warp.field.protocol import decided

    scenarios = _field_scenarios(tmp_path)
    assert len({round(s.scene.dx, 6) for s in scenarios}) == 2           # two grids among the four
    dt = min(simulation_for(s, "cpu", 1)._first_dt() for s in scenarios)  # the stiffest column's step
    scenarios = [dataclasses.replace(s, time=dataclasses.replace(s.time, dt=dt)) for s in scenarios]
    alone = []
    for k, s in enumerate(scenarios):
        sim = simulation_for(s, "cpu", 1)
        res = sim.run(str(tmp_path / f"alone{k}.h5"), callback=lambda sim, f: not decided(sim))
        alone.append((_outcome(res), sim.state.x.numpy().copy()))
    sims = [simulation_for(s, "cpu", 1) for s in scenarios]
    frames_seen = [[] for _ in sims]

    def until_decided(k, sim, frame):
        frames_seen[k].append(frame)
        return not decided(sim)

    together = run_columns(sims, [str(tmp_path / f"together{k}.h5") for k in range(4)], until_decided)
    classes = [o[0][0] for o in alone]
    assert classes == ["END", "NP", "NP", "END"]                      # two outcomes, decided at four times
    assert len({o[0][4] for o in alone}) == 4
    for k, (res, sim) in enumerate(zip(together, sims, strict=True)):
        # class, runaway cut, front speed and steps: the same (NaN where a run has none)
        np.testing.assert_equal(_outcome(res)[:4], alone[k][0][:4])
        assert res.sim_time == pytest.approx(alone[k][0][4], abs=1e-12)
        # a decided column stopped where its run alone stopped: not one step further, bit for bit the same state
        np.testing.assert_array_equal(sim.state.x.numpy(), alone[k][1])
        assert frames_seen[k] == list(range(1, len(frames_seen[k]) + 1))
        assert mw.read_run(res.output).n_frames == len(frames_seen[k]) + 1
    # the END columns' cracks ran away at the cuts of their runs alone (finite, inside the column), at a speed
    assert all(0.0 < together[k].scene_result["runaway_cut"] < scenarios[k].scene.length for k in (0, 3))
    assert all(together[k].scene_result["damage_speed_mean"] > 1.0 for k in (0, 3))


def _block(tmp_path, speed: float, threads: int = 1):
    s = mw.load_scenario("elastic_block", ["time.end=0.004", "time.frame_interval=0.002",
                                           f"blocks.0.velocity=[0.0, {-speed}, 0.0]"])
    return simulation_for(s, "cpu", threads)


def test_a_batch_takes_new_one_thread_columns_on_one_device_and_says_so_in_one_line(tmp_path):
    with pytest.raises(mw.InvalidArgument, match=r"sims\[0\]\.stepper\.n_threads.*1 \(make the Simulation"):
        SharedStep([_block(tmp_path, 0.0, threads=2)])
    with pytest.raises(mw.InvalidArgument, match="sims"):
        SharedStep([])
    a = _block(tmp_path, 0.0)
    with pytest.raises(mw.InvalidArgument, match=r"outputs.*one per simulation \(1\)"):
        run_columns([a], [None, None])
    a.run(end_time=0.002)
    with pytest.raises(mw.InvalidArgument, match=r"sims\[0\].*a new Simulation"):
        run_columns([a])


def test_columns_of_different_speeds_share_the_least_step_and_keep_their_own_clocks_equal(tmp_path):
    """Two blocks, one at rest and one falling at 5 m/s: the batch steps both with the falling one's step, so the
    block at rest takes as many steps as the falling one, more than alone, and ends at the same time."""
    alone = [_block(tmp_path, v).run() for v in (0.0, 5.0)]
    sims = [_block(tmp_path, v) for v in (0.0, 5.0)]
    res = run_columns(sims)
    assert alone[1].steps > alone[0].steps
    assert [r.steps for r in res] == [alone[1].steps, alone[1].steps]
    assert [r.sim_time for r in res] == [pytest.approx(0.004, abs=1e-15)] * 2
    # the column that sets the step runs as alone, bit for bit
    np.testing.assert_array_equal(sims[1].state.x.numpy(), alone_state(tmp_path, 5.0))


def alone_state(tmp_path, speed: float) -> np.ndarray:
    sim = _block(tmp_path, speed)
    sim.run()
    return sim.state.x.numpy()
