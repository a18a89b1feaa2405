"""The memory estimate equals what Model, State, Stepper and Simulation really allocate, and the guard refuses a
scene before anything is allocated (CPU only)."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import pytest
import warp as wp
from helpers_scenes import TINY_PST

import mpm_warp as mw
from mpm_warp.memory import available_memory, check_memory, estimate_memory, format_bytes, parse_bytes, particle_bytes

PST = TINY_PST + ["time.end=0.01", 'output.fields=["x", "log_jp", "yielded"]']


def _plane_block(precision: str) -> mw.Scenario:
    return mw.Scenario(name="plane", domain=mw.Domain((0.0, 0.0), (0.6, 0.4), 0.02, dimension=2),
                       time=mw.TimeControl(end=0.01, frame_interval=0.01),
                       materials={"snow": mw.Elastic(1e6, 0.3, 250.0),
                                  "weak": mw.CamClaySnow(1e6, 0.3, 200.0, p0_ini=1e3)},
                       blocks=(mw.Block("snow", (0.1, 0.1), (0.5, 0.2), particles_per_cell=4),
                               mw.Block("weak", (0.1, 0.2), (0.5, 0.25), particles_per_cell=4)),
                       precision=precision)


def _bonded_layer(dim: int, precision: str) -> mw.Scenario:
    """A slab on a bonded weak layer (kappa and lattice columns) on Cam-Clay, with yield flags in the output."""
    lo, hi = (0.0, 0.0, 0.0)[:dim], (0.6, 0.3, 0.1)[:dim]
    box = lambda y0, y1: ((0.1, y0, 0.0)[:dim], (0.5, y1, 0.1)[:dim])        # noqa: E731
    return mw.Scenario(name="bonded", domain=mw.Domain(lo, hi, 0.02, dimension=dim),
                       time=mw.TimeControl(end=0.01, frame_interval=0.01),
                       materials={"slab": mw.Elastic(1e6, 0.3, 250.0), "base": mw.CamClaySnow(1e6, 0.3, 200.0),
                                  "weak": mw.BondedCamClay(1e6, 0.3, 150.0, p_bond=1e3)},
                       blocks=(mw.Block("slab", *box(0.14, 0.24)), mw.Block("weak", *box(0.1, 0.14), name="weak"),
                               mw.Block("base", *box(0.02, 0.1))),
                       output=mw.Output(fields=("x", "yielded")), precision=precision)


SCENES = {
    "block-float32": lambda: (mw.load_scenario("elastic_block"), 1),
    "block-float64-2-threads": lambda: (mw.load_scenario("elastic_block", ['precision="float64"']), 2),
    "plane-strain-float32": lambda: (_plane_block("float32"), 1),
    "plane-strain-float64-camclay": lambda: (_plane_block("float64"), 2),
    "bonded-pst-yielded": lambda: (mw.load_scenario("pst_demo", PST), 1),
    "bonded-3d-float32-2-threads": lambda: (_bonded_layer(3, "float32"), 2),
    "bonded-2d-float64": lambda: (_bonded_layer(2, "float64"), 1),
}


def _particle_arrays(state, *counts: int) -> int:
    """Bytes of every per-particle Warp array the state holds (a new field counts here without being listed)."""
    return sum(a.capacity for k, a in vars(state).items()
               if isinstance(a, wp.array) and k not in ("clock", "steps") and a.shape[0] in counts)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SCENES))
def test_estimate_equals_the_allocation(name):
    sc, threads = SCENES[name]()
    sim = mw.Simulation(sc, device="cpu", n_threads=threads)
    est = estimate_memory(sim.scenario, "cpu", threads)
    m, st = sim.model, sim.stepper
    assert est.n_particles == m.n_particles
    assert est.particles == _particle_arrays(sim.state, m.n_particles, m.n_plastic, m.n_bonded) == \
        sim.state.particle_bytes()
    assert est.columns == sum(col.capacity + sums.capacity for col, sums in st.column_sums)
    assert (est.columns > 0) == name.startswith("bonded")
    assert est.grid_copies == st.n_threads == threads
    assert est.grid_nodes == int(np.prod(m.grid_shape))
    assert est.grid == st.grid_m_all.capacity + st.grid_p_all.capacity
    others = sum(a.capacity for k, a in vars(st).items() if isinstance(a, wp.array)
                 and k not in ("grid_m_all", "grid_p_all", "grid_m", "grid_p"))
    assert others < 4096                                   # dt, speed bounds, counters, wall impulses
    assert est.host == sim.x0.nbytes + sum(x.nbytes for _, x in m._seed) + \
        sum(g.columns.nbytes for g in m.groups if g.columns is not None)
    s = 8 if sc.precision == "float64" else 4
    d = m.dim
    assert est.staging == m.n_particles * (2 * d + d * d) * s
    assert sim.memory == est


def test_bytes_per_particle():
    """x, v: d s; C, H: d^2 s; Cam-Clay log_jp: s, in plane strain also hzz: s (+ 1 byte yielded); bonded kappa: s.
    An elastic particle in plane strain stores no hzz (its F_E,zz is 1)."""
    assert particle_bytes(3, "float32") == 96 and particle_bytes(3, "float32", plastic=True) == 100
    assert particle_bytes(2, "float32") == 48 and particle_bytes(2, "float32", plastic=True) == 56
    assert particle_bytes(2, "float64", plastic=True, yielded=True) == 113
    assert particle_bytes(3, "float32", plastic=True, bonded=True) == 104


def test_guard_refuses_with_needed_available_and_the_key():
    sc = mw.load_scenario("elastic_block")
    est = estimate_memory(sc, "cpu")
    check_memory(sc, "cpu", max_memory=est.total)         # exactly enough
    with pytest.raises(mw.InvalidArgument) as info:
        mw.Simulation(sc, device="cpu", max_memory=est.total - 1)
    msg = str(info.value)
    assert info.value.field == "domain.dx" and "\n" not in msg
    assert f"{format_bytes(est.total)} needed" in msg and f"{format_bytes(est.total - 1)} available (max_memory)" in msg
    assert "raise domain.dx" in msg


def test_guard_refuses_before_allocating():
    """1.5e10 particles (1.3 TiB) and a 40 m domain (1 TiB of grid) are refused in well under a second."""
    sc = mw.load_scenario("elastic_block")
    huge = [replace(sc, domain=replace(sc.domain, dx=2e-4), blocks=(replace(sc.blocks[0], particles_per_cell=8),)),
            replace(sc, domain=replace(sc.domain, hi=(40.0, 40.0, 40.0), dx=0.01))]
    host, _ = available_memory("cpu")
    assert host is not None and host > 0
    for s, key in zip(huge, ("domain.dx", "domain.lo/hi"), strict=True):
        t0 = time.perf_counter()
        with pytest.raises(mw.InvalidArgument) as info:
            mw.Simulation(s, device="cpu")
        assert time.perf_counter() - t0 < 1.0
        assert info.value.field == key and f"{format_bytes(host)} available (MemAvailable)"[:6] in str(info.value)
        assert estimate_memory(s.validate(), "cpu").total > host


@pytest.mark.parametrize("text, n", [("16G", 16e9), ("500 MB", 5e8), ("2GiB", 2**31), ("8e9", 8e9), (1024, 1024),
                                     ("1.5k", 1500)])
def test_parse_bytes(text, n):
    assert parse_bytes(text) == n


@pytest.mark.parametrize("bad", ["lots", "16Q", "-1G", 0, "0"])
def test_parse_bytes_refuses(bad):
    with pytest.raises(mw.InvalidArgument, match="max_memory"):
        parse_bytes(bad)
