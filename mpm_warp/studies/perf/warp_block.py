"""The mpm_warp side of the block benchmarks: build, warm up, snapshot, time, diagnose.

Both engines follow one protocol (:func:`.taichi_peer.run_taichi_block` is the
Taichi side): build the scene and compile its kernels; step ``warmup`` steps
untimed; take a snapshot of the state; for each of ``repeats`` repeats restore
the snapshot and time ``steps`` steps (device synchronised before and after);
report the median. The observables are those of the state after the last
repeat, i.e. after ``warmup + steps`` steps from the start. Cam-Clay runs also
record, for every timed step (replayed from the snapshot with the ``yielded``
output on), the fractions of particles whose return was active and of cap and
dry-side returns (:func:`mpm_warp.studies.plastic_block.return_kinds`). The scenes are
:mod:`mpm_warp.studies.blocks`; the scripts ``benchmarks/perf/throughput.py`` and ``plastic_step.py`` time them.
"""

from __future__ import annotations

import statistics
import time

import numpy as np
import warp as wp

from ...simulation import Simulation
from .. import plastic_block as pb
from ..blocks import block_simulation, default_warmup
from ..timing import stage_times


def _timed(sim: Simulation, snap: dict, steps: int, repeats: int) -> tuple[list[float], list[float]]:
    """Wall seconds and process CPU seconds per step of ``repeats`` batches of ``steps`` steps, each from the
    snapshot (CPU time below wall time times the thread count: the cores were shared)."""
    st = sim.stepper
    wall, cpu = [], []
    for _ in range(repeats):
        sim.state.load_arrays(snap)
        st.set_frame_end(1e9)
        wp.synchronize_device(sim.device)
        c0 = time.process_time()
        t0 = time.perf_counter()
        st.steps(steps)
        wp.synchronize_device(sim.device)
        wall.append((time.perf_counter() - t0) / steps)
        cpu.append((time.process_time() - c0) / steps)
    return wall, cpu


def return_kinds_per_step(dim: int, n_grid: int, snap: dict, steps: int, device: str, n_threads: int | None):
    """Per-step ``plastic_block.return_kinds`` of ``steps`` steps replayed from ``snap`` with yield tracking.

    ``snap`` holds the state's arrays (``State.arrays()``); ``n_threads`` as :func:`run_block`. Returns one dict a
    step (fractions of the particles).
    """
    sim = block_simulation(dim, "plastic", n_grid, device, n_threads, track_yield=True)
    sim.state.load_arrays(snap)
    st = sim.stepper
    st.set_frame_end(1e9)
    sim.particle_field("yielded")  # clears the flags
    out = []
    before = sim.state.log_jp.numpy().copy()
    for _ in range(steps):
        st.steps(1)
        yielded = sim.particle_field("yielded")
        after = sim.state.log_jp.numpy().copy()
        out.append(pb.return_kinds(before, after, yielded))
        before = after
    return out


def run_block(dim: int, material: str, n_grid: int, steps: int, device: str = "cpu", n_threads: int | None = 1,
              repeats: int = 3, warmup: int | None = None, stages: bool = False, diagnostics: bool = False,
              return_share: bool = False) -> dict:
    """Time the block in mpm_warp (protocol in the module docstring).

    Parameters
    ----------
    dim : {2, 3}
        2 is plane strain.
    material : {"elastic", "plastic"}
        The elastic block or the struck Cam-Clay block (:func:`mpm_warp.studies.blocks.block_simulation`).
    n_grid : int
        Cells per axis of the unit box; ``n_grid**dim`` particles.
    steps, repeats : int
        Timed steps per repeat and repeats, each from the snapshot (the median is reported).
    device : str
        Warp device.
    n_threads : int or None
        CPU threads (None: all).
    warmup : int or None
        Untimed steps before the snapshot (default :func:`mpm_warp.studies.blocks.default_warmup`).
    stages, diagnostics, return_share : bool
        What else to record (below).

    Returns
    -------
    dict
        ``engine``, ``dim``, ``material``, ``n_grid``, ``n_particles``,
        ``threads``, ``warmup``, ``steps``, ``dt``, ``s_per_step`` (median),
        ``times_s_per_step``, ``cpu_s_per_step`` (median process CPU time per
        step), ``cpu_utilisation`` (median CPU time over wall time; on the CPU
        well below ``threads`` means the cores were shared),
        ``particle_steps_per_s``, ``bytes_per_particle``
        (particle state), ``grid_bytes_per_particle`` (all grid copies), and
        ``com_y`` (elastic) or ``observables`` (Cam-Clay, see
        ``plastic_block.observables``); with ``stages`` the per-stage seconds
        per step (one thread), with ``diagnostics`` ``return_kinds`` per timed
        step and ``return_kind_problems``, with ``return_share`` the same
        steps with plasticity compiled out (``no_plasticity_s_per_step``, and
        its CPU time) and ``plasticity_share = 1 - that / this`` (CPU times on the CPU).
    """
    sim = block_simulation(dim, material, n_grid, device, n_threads)
    W = default_warmup(material, n_grid) if warmup is None else warmup
    st = sim.stepper
    st.set_frame_end(1e9)
    st.steps(W)  # compiles every kernel of the plan
    wp.synchronize_device(sim.device)
    snap = {k: np.array(a, copy=True) for k, a in sim.state.arrays().items()}  # on the CPU .numpy() is a view
    ts, cpu = _timed(sim, snap, steps, repeats)
    med = statistics.median(ts)
    N = sim.model.n_particles
    row = {"engine": "mpm_warp", "dim": dim, "material": material, "n_grid": n_grid, "n_particles": N,
           "threads": st.n_threads, "device": sim.device, "warmup": W, "steps": steps,
           "dt": float(sim.scenario.time.dt), "s_per_step": med, "times_s_per_step": ts,
           "cpu_s_per_step": statistics.median(cpu),
           "cpu_utilisation": statistics.median(c / w for c, w in zip(cpu, ts, strict=True)),
           "particle_steps_per_s": N / med, "bytes_per_particle": sim.model.bytes_per_particle(sim.state),
           "grid_bytes_per_particle": (st.grid_m_all.capacity + st.grid_p_all.capacity) / N}
    if material == "plastic":
        row["observables"] = pb.observables(sim.state.elastic_deformation_gradient(), sim.state.log_jp.numpy())
    else:
        row["com_y"] = float(sim.state.x.numpy()[:, 1].astype(np.float64).mean())
    if stages and st.n_threads == 1:
        sim.state.load_arrays(snap)
        row["stages_s"] = stage_times(sim, steps=min(steps, 10))
    if material == "plastic" and diagnostics:
        kinds = return_kinds_per_step(dim, n_grid, snap, steps, device, n_threads)
        row["return_kinds"] = kinds
        row["return_kind_problems"] = pb.check_return_kinds(kinds)
    if material == "plastic" and return_share:
        twin = block_simulation(dim, material, n_grid, device, n_threads, elastic_twin=True)
        twin_snap = {k: v for k, v in snap.items() if k != "log_jp"}
        twin.stepper.set_frame_end(1e9)
        twin.stepper.steps(1)  # compile
        wall_el, cpu_el = _timed(twin, twin_snap, steps, repeats)
        row["no_plasticity_s_per_step"] = statistics.median(wall_el)
        row["no_plasticity_cpu_s_per_step"] = statistics.median(cpu_el)
        on_cpu = not wp.get_device(sim.device).is_cuda  # shares from CPU time on the (shared) CPU
        row["plasticity_share"] = (1.0 - row["no_plasticity_cpu_s_per_step"] / row["cpu_s_per_step"] if on_cpu
                                   else 1.0 - row["no_plasticity_s_per_step"] / med)
    return row
