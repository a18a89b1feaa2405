"""The CUDA-graph driver path gives the same answer as eager launches.

Warp cannot capture graphs on the CPU, so a stand-in capture records how many
steps a graph holds and replays them eagerly: this checks the batching logic
(whole graphs, eager remainder, no-op steps past a frame end) bit for bit.
"""

import numpy as np
import warp as wp
from helpers_device import DEVICE  # MPM_WARP_TEST_DEVICE

import mpm_warp as mw


class _FakeGraphs:
    def __init__(self, stepper):
        self.stepper = stepper
        self.real_step = stepper._launch_step
        self.captures = 0
        self.replays = 0

    def capture(self, device=None):
        fake = self

        class Capture:
            graph = None

            def __enter__(self):
                self.n = 0

                def count():
                    self.n += 1

                fake.stepper._launch_step = count
                return self

            def __exit__(self, *exc):
                fake.stepper._launch_step = fake.real_step
                self.graph = self.n
                fake.captures += 1

        return Capture()

    def launch(self, graph):
        self.replays += 1
        for _ in range(graph):
            self.real_step()


def _run(use_graph, monkeypatch=None):
    sc = mw.load_scenario("elastic_block", ["time.end=0.05", "time.frame_interval=0.01"])
    sim = mw.Simulation(sc, device=DEVICE, use_graph=use_graph)
    fake = None
    if use_graph:
        fake = _FakeGraphs(sim.stepper)
        monkeypatch.setattr(wp, "ScopedCapture", fake.capture)
        monkeypatch.setattr(wp, "capture_launch", fake.launch)
    res = sim.run(None)
    return sim, res, fake


def test_graph_batches_match_eager_bit_for_bit(monkeypatch):
    eager, r_e, _ = _run(False)
    graph, r_g, fake = _run(True, monkeypatch)
    assert fake.captures == 1 and fake.replays > 0
    assert r_g.steps == r_e.steps and r_g.sim_time == r_e.sim_time
    np.testing.assert_array_equal(graph.state.x.numpy(), eager.state.x.numpy())
    np.testing.assert_array_equal(graph.state.v.numpy(), eager.state.v.numpy())


def test_exact_step_counts_with_graphs(monkeypatch):
    """steps(n) runs exactly n steps: whole graphs plus an eager remainder."""
    sc = mw.load_scenario("elastic_block", ["time.end=1.0"])
    sim = mw.Simulation(sc, device=DEVICE, use_graph=True)
    fake = _FakeGraphs(sim.stepper)
    monkeypatch.setattr(wp, "ScopedCapture", fake.capture)
    monkeypatch.setattr(wp, "capture_launch", fake.launch)
    sim.stepper.set_frame_end(1.0)
    sim.stepper.steps(2 * sim.stepper.graph_batch + 3)
    assert sim.stepper.clock()[2] == 2 * sim.stepper.graph_batch + 3
    assert fake.replays == 2
