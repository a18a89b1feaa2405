"""Timers of the benchmarks: steps and kernel launches with the kernels compiled, medians.

On the CPU the timers read the process's CPU time: a one-thread launch's CPU time is its own work,
while its wall time grows with other users' load on a shared machine. On CUDA the host only waits,
so they read wall time.
"""

from __future__ import annotations

import statistics
import time

import warp as wp

from ..simulation import Simulation

__all__ = ["clock_for", "time_steps", "stage_times", "median_launch_time"]


def clock_for(device: str):
    """The timer of a benchmark on ``device``: ``time.process_time`` on the CPU, ``time.perf_counter`` on CUDA."""
    return time.perf_counter if wp.get_device(device).is_cuda else time.process_time


def time_steps(sim: Simulation, steps: int, repeats: int = 3, warmup: int = 3) -> list[float]:
    """Wall seconds per step of ``repeats`` timed batches of ``steps`` steps, after ``warmup`` untimed steps.

    The warm-up compiles (or loads) every kernel of the step; the device is synchronised around each batch.
    """
    st = sim.stepper
    st.set_frame_end(1e9)
    st.steps(warmup)
    wp.synchronize_device(sim.device)
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        st.steps(steps)
        wp.synchronize_device(sim.device)
        out.append((time.perf_counter() - t0) / steps)
    return out


def stage_times(sim: Simulation, steps: int = 10) -> dict[str, float]:
    """Median seconds per step of P2G, the grid update and G2P, launched one stage at a time (:func:`clock_for`)."""
    st = sim.stepper
    st.set_frame_end(1e9)
    acc = {"p2g": [], "grid_update": [], "g2p": []}
    dev = sim.device
    clock = clock_for(dev)
    with st.flushed(0):  # the step's floating-point mode (one thread runs every copy's launches here)
        for _ in range(steps):
            st._begin.launch()
            if getattr(st, "_wall_state", None) is not None:
                st._wall_state.launch()
            wp.synchronize_device(dev)
            t0 = clock()
            for k in range(st.n_threads):
                st._scatter(k)
            wp.synchronize_device(dev)
            t1 = clock()
            for g in st._grid:
                g.launch()
            wp.synchronize_device(dev)
            t2 = clock()
            for g in st._g2p:
                g.launch()
            wp.synchronize_device(dev)
            t3 = clock()
            st._end.launch()
            acc["p2g"].append(t1 - t0)
            acc["grid_update"].append(t2 - t1)
            acc["g2p"].append(t3 - t2)
    return {k: statistics.median(v) for k, v in acc.items()}


def median_launch_time(launch, device: str, repeats: int = 5) -> float:
    """Median seconds of ``launch()`` (a callable that launches kernels) after one untimed call (:func:`clock_for`)."""
    clock = clock_for(device)
    launch()  # compile / load
    wp.synchronize_device(device)
    ts = []
    for _ in range(repeats):
        t0 = clock()
        launch()
        wp.synchronize_device(device)
        ts.append(clock() - t0)
    return statistics.median(ts)
