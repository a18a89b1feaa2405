"""The code paths that run only on CUDA, run on the CPU (docs/architecture.md, "CUDA-only code paths").

- The stepper's CUDA plan (one thread and grid copy, one grid node per grid-update thread, step batches
  captured as graphs), built on the CPU by a device stand-in (``tests/helpers_cuda_paths.py``), gives the
  CPU plan's particles bit for bit and its wall impulses to round-off.
- The captured body (``Stepper._launch_step`` with the monitors' actions), captured for real (Warp
  captures graphs on the CPU too, and as on CUDA runs nothing at capture time; on a GPU, with
  ``MPM_WARP_TEST_DEVICE``, the CUDA capture itself), makes no allocation,
  host read or write, copy or synchronisation; it records the eager step's operations, the same ones
  from any device state (no host branch on device values); replaying it gives the eager run bit for bit.
  The guard catches each forbidden call in a deliberately bad action, naming its line.
- The memory guard's device path, the thread and grid-copy choice on CUDA, the device resolution with
  CUDA present and the sweep's one worker per GPU, through stand-ins.
"""

from __future__ import annotations

import math
import os
from types import SimpleNamespace

import numpy as np
import pytest
import warp as wp
from helpers_cuda_paths import CaptureGuard, cuda_looking, recorded_ops
from helpers_device import DEVICE
from helpers_scenes import TINY_PST

import mpm_warp as mw
import mpm_warp.memory as memory_mod
import mpm_warp.step as step_mod
from mpm_warp import sweep
from mpm_warp.device import resolve_device
from mpm_warp.errors import InvalidArgument
from mpm_warp.scenes.pst.monitor import attach

BLOCK = ["time.end=0.05", "time.frame_interval=0.01"]
#: the PST until the saw has cut 2 cm (settled by 0.04 s), float32
PST = TINY_PST + ["time.end=0.06"]


def _standin_plan(monkeypatch, scenario, **kw) -> mw.Simulation:
    """The CUDA plan, built on the CPU through the device stand-in."""
    with monkeypatch.context() as mp:
        cuda_looking(mp, step_mod, memory_mod)
        return mw.Simulation(scenario, device="cpu", **kw)


def _cuda_plan(monkeypatch, scenario, **kw) -> mw.Simulation:
    """The CUDA plan on ``MPM_WARP_TEST_DEVICE`` if a GPU (benchmarks/perf/device_suite.py), else the stand-in."""
    if DEVICE != "cpu":
        return mw.Simulation(scenario, device=DEVICE, **kw)
    return _standin_plan(monkeypatch, scenario, **kw)


def _same(a: mw.Simulation, b: mw.Simulation, fields=("x", "v", "C", "H")) -> None:
    for f in fields:
        np.testing.assert_array_equal(getattr(a.state, f).numpy(), getattr(b.state, f).numpy(), err_msg=f)


def test_cuda_plan_on_the_cpu_equals_the_cpu_plan(monkeypatch):
    sc = mw.load_scenario("elastic_block", BLOCK)
    cpu = mw.Simulation(sc, device="cpu", n_threads=1)
    cuda = _standin_plan(monkeypatch, sc)
    st, gs = cuda.stepper, cuda.model.grid_shape
    assert st.n_threads == 1 and st._pool is None and st.use_graph and not cpu.stepper.use_graph
    assert [tuple(g.bounds.shape) for g in st._grid] == [(math.prod(gs),)]             # a node per thread
    assert [tuple(g.bounds.shape) for g in cpu.stepper._grid] == [(math.prod(gs[:-1]),)]   # a row per thread
    with CaptureGuard() as guard:
        r_cuda = cuda.run(None)
    r_cpu = cpu.run(None)
    assert guard.violations == [] and len(guard.captures) == 1     # one graph, captured once, replayed
    assert r_cuda.steps == r_cpu.steps > 400 and r_cuda.sim_time == r_cpu.sim_time
    _same(cuda, cpu)
    # the floor's impulse, summed node by node on CUDA and row by row on the CPU (float64)
    imp_cuda, imp_cpu = (s.stepper.wall_impulses.numpy().sum(axis=0) for s in (cuda, cpu))
    assert np.abs(imp_cpu).max() > 0
    np.testing.assert_allclose(imp_cuda, imp_cpu, rtol=1e-12, atol=1e-15 * np.abs(imp_cpu).max())


def _pst(monkeypatch, use_graph: bool):
    sim = _cuda_plan(monkeypatch, mw.load_scenario("pst_demo", PST), use_graph=use_graph)
    return sim, attach(sim)


@pytest.mark.slow
def test_captured_step_batch_is_pure_device_work(monkeypatch):
    """No allocation, host read or synchronisation inside the capture; the eager step's operations, graph_batch
    times; the same operations captured from another device state; replays equal the eager run bit for bit."""
    eager, m_eager = _pst(monkeypatch, use_graph=False)
    graph, m_graph = _pst(monkeypatch, use_graph=True)
    late, _ = _pst(monkeypatch, use_graph=False)
    assert len(graph.stepper.actions) >= 2            # the saw's and the deflection front's actions
    with CaptureGuard() as guard:
        r_graph = graph.run(None)
        with recorded_ops(guard):                     # one eager step of another simulation
            late.stepper.set_frame_end(1.0)
            late.stepper._launch_step()
        late.step_to(0.05)                            # settled, the saw cutting: another dt, clock, bond state
        late.stepper.use_graph = True
        late.step_to(0.055)
    r_eager = eager.run(None)
    assert guard.violations == []
    first, step, again = guard.captures
    batch = graph.stepper.graph_batch
    kernels = {op[1].split(".")[0] for op in step if op[0] == "launch"}
    assert {"begin_step_kernel", "p2g_kernel", "grid_update_kernel", "g2p_kernel", "weak_layer_kernel",
            "deflection_kernel", "kappa_column_mean_kernel", "end_step_kernel"} <= kernels
    assert first == step * batch and again == first
    assert r_graph.steps == r_eager.steps and r_graph.sim_time == r_eager.sim_time
    _same(graph, eager)
    np.testing.assert_array_equal(graph.state.kappa.numpy(), eager.state.kappa.numpy())
    np.testing.assert_equal(m_graph.result(), m_eager.result())     # the saw, the fronts (NaN where none yet)


class _BadAction:
    """An action that breaks every rule of a captured body (the guard's test)."""

    def __init__(self, clock: wp.array):
        self.clock = clock

    def launch(self):
        scratch = wp.zeros(4, dtype=wp.float64, device="cpu")      # an allocation
        if self.clock.numpy()[0] > 0.0:                             # a host read, and a branch on it
            self.clock.assign(self.clock.numpy())                   # a host write
        wp.copy(scratch, self.clock)
        wp.synchronize_device("cpu")


def test_guard_names_each_forbidden_call(monkeypatch):
    sim = _standin_plan(monkeypatch, mw.load_scenario("elastic_block", BLOCK))
    st = sim.stepper
    st.actions.append(_BadAction(sim.state.clock))
    st.set_frame_end(1.0)
    with CaptureGuard() as guard:
        st._launch_step()                       # eager: nothing is checked outside a capture
        assert guard.violations == []
        st.steps(st.graph_batch)
    here = os.path.basename(__file__)
    seen = {v.split(":")[0] for v in guard.violations}
    assert {"allocation", "host read (numpy)", "host write (assign)", "copy", "synchronisation"} <= seen
    assert all(f"tests/{here}:" in v and "in launch" in v for v in guard.violations)
    # one batch of steps, each with the bad action's calls
    assert sum(v.startswith("synchronisation") for v in guard.violations) == st.graph_batch


# ----------------------------------------------------------------------------- memory, threads, devices
def test_memory_guard_device_path(monkeypatch):
    sc = mw.load_scenario("pst_demo", PST)
    est_cpu = memory_mod.estimate_memory(sc, "cpu", n_threads=2)
    with monkeypatch.context() as mp:
        cuda_looking(mp, step_mod, memory_mod, free_memory=123456789)
        est = memory_mod.estimate_memory(sc, "cpu", n_threads=2)
        assert memory_mod.available_memory("cpu")[1] == 123456789
    assert est.grid_copies == 1 and est_cpu.grid_copies == 2 and est.grid == est_cpu.grid // 2
    assert memory_mod.available_memory("cpu")[1] is None
    host = est.host + est.staging
    with monkeypatch.context() as mp:
        cuda_looking(mp, step_mod, memory_mod)
        # on CUDA the device part is held against the device's free memory, the host part against MemAvailable
        mp.setattr(memory_mod, "available_memory", lambda d: (host, est.device))
        assert memory_mod.check_memory(sc, "cpu", n_threads=2) == est
        for have in ((host, est.device - 1), (host - 1, est.device)):
            mp.setattr(memory_mod, "available_memory", lambda d, have=have: have)
            with pytest.raises(InvalidArgument, match="MemAvailable" if have[0] < host else "free on cpu"):
                memory_mod.check_memory(sc, "cpu", n_threads=2)
    # on the CPU everything is held against MemAvailable
    monkeypatch.setattr(memory_mod, "available_memory", lambda d: (est_cpu.total - 1, None))
    with pytest.raises(InvalidArgument, match="MemAvailable"):
        memory_mod.check_memory(sc, "cpu", n_threads=2)


def test_one_thread_and_grid_copy_on_cuda(monkeypatch):
    monkeypatch.setenv("MPM_WARP_THREADS", "8")
    assert step_mod.default_threads("cpu", 10**6) == 8 and step_mod.grid_copies("cpu", 10**6, (100, 100)) == 8
    assert step_mod.grid_copies("cpu", 10**6, (100, 100), n_threads=2) == 2
    cuda_looking(monkeypatch, step_mod)
    assert step_mod.default_threads("cpu", 10**6) == 1 and step_mod.grid_copies("cpu", 10**6, (100, 100)) == 1
    assert step_mod.grid_copies("cpu", 10**6, (100, 100), n_threads=2) == 1   # n_threads is for the CPU step


def test_device_resolution_with_and_without_cuda(monkeypatch):
    monkeypatch.delenv("MPM_WARP_DEVICE", raising=False)
    monkeypatch.setattr(wp, "is_cuda_available", lambda: False)
    assert resolve_device(None) == "cpu"
    with pytest.raises(InvalidArgument, match="no CUDA device"):
        resolve_device("cuda")
    monkeypatch.setattr(wp, "is_cuda_available", lambda: True)
    monkeypatch.setattr(wp, "get_cuda_device_count", lambda: 2)
    assert [resolve_device(d) for d in (None, "cuda", "cuda:1", "cpu")] == ["cuda:0", "cuda:0", "cuda:1", "cpu"]
    with pytest.raises(InvalidArgument, match=r"N in \[0, 1\] \(this machine has 2 CUDA devices\)"):
        resolve_device("cuda:2")
    monkeypatch.setenv("MPM_WARP_DEVICE", "cpu")
    assert resolve_device(None) == "cpu"


def test_sweep_one_worker_per_gpu(monkeypatch):
    distributed = pytest.importorskip("distributed", reason="the sweep's Dask (distributed) is not installed")

    monkeypatch.delenv("MPM_WARP_DEVICE", raising=False)
    monkeypatch.setattr(sweep, "_n_gpus", lambda: 3)
    monkeypatch.setattr(distributed, "get_worker", lambda: SimpleNamespace(name="4"))
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    assert (sweep.default_workers(None), sweep.default_workers("cuda"), sweep.default_workers("cpu")) == (3, 3, cores)
    assert [sweep._worker_device(d) for d in (None, "cuda", "cuda:2", "cpu")] == ["cuda:1", "cuda:1", "cuda:2", "cpu"]
    monkeypatch.setattr(distributed, "get_worker", lambda: SimpleNamespace(name="tcp://worker-a"))
    assert sweep._worker_device(None) is None                  # a worker not named by a number
    monkeypatch.setattr(sweep, "_n_gpus", lambda: 1)
    assert sweep._worker_device(None) is None and sweep.default_workers(None) == 1
