"""Memory a scenario needs, estimated before anything is allocated, and the guard that refuses too much.

Per particle on the device, with ``s`` = 4 bytes (float32) or 8 (float64) and ``d`` the dimension:
``x``, ``v`` (``d s`` each), ``C``, ``H = F_E - I`` (``d^2 s`` each), for plastic (Cam-Clay) particles
``log_jp`` (``s``) and in plane strain ``hzz`` (``s``; an elastic particle's ``F_E,zz`` is 1, not
stored), for bonded and cracking ones ``kappa`` (``s``) and, when the output asks for it, ``yielded`` (1 byte). A
bonded weak layer also has its lattice columns: a column index per particle (int32, on the device and on
the host) and a float64 pair per column. The grid is ``n_copies x nodes x (1 + d)`` scalars (mass and
momentum; one copy per CPU thread, :func:`mpm_warp.step.grid_copies`). The host keeps the seeded
positions and the initial positions ``x0`` in float64 (``2 d 8`` bytes per particle) and builds the
initial ``x``, ``v``, ``C`` before uploading them. Frames and checkpoints add host copies of the fields
they write (not counted). ``tests/test_memory.py`` checks these numbers against what
:class:`~mpm_warp.state.State`, :class:`~mpm_warp.step.Stepper` and :class:`~mpm_warp.Simulation` really
allocate.

The guard (:func:`check_memory`) compares the estimate with the memory available (Linux
``MemAvailable``; on CUDA the device's free memory for the device part) and with an optional
user limit (``max_memory=``, ``--max-memory``) and refuses with one line: needed, available and
the key to change.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import warp as wp

from .config import Scenario
from .errors import InvalidArgument
from .lattice import grid_shape, lattice_counts
from .step import grid_copies

__all__ = ["MemoryEstimate", "estimate_memory", "available_memory", "check_memory", "parse_bytes",
           "particle_bytes", "format_bytes"]

_UNITS = {"": 1, "b": 1, "k": 1e3, "kb": 1e3, "m": 1e6, "mb": 1e6, "g": 1e9, "gb": 1e9, "t": 1e12, "tb": 1e12,
          "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}


def parse_bytes(value, field: str = "max_memory") -> int:
    """Bytes of ``value``: a number, or text such as ``"16G"``, ``"500 MB"``, ``"2GiB"`` (k/M/G/T: powers of 1000)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        n = float(value)
    else:
        m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([A-Za-z]*)\s*", str(value))
        if not m or m.group(2).lower() not in _UNITS:
            raise InvalidArgument(field, value, "a size in bytes, e.g. 16G, 500MB, 2GiB or 8e9")
        n = float(m.group(1)) * _UNITS[m.group(2).lower()]
    if not n > 0 or n == float("inf"):
        raise InvalidArgument(field, value, "a size > 0 bytes")
    return int(n)


def format_bytes(n: float) -> str:
    """``n`` bytes in binary units, e.g. ``"1.5 GiB"``."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024 or unit == "PiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    raise AssertionError  # pragma: no cover


def particle_bytes(dim: int, precision: str, *, plastic: bool = False, bonded: bool = False,
                   yielded: bool = False, cracking: bool = False) -> int:
    """Device bytes of one particle (see the module docstring)."""
    s = 8 if precision == "float64" else 4
    b = (2 * dim + 2 * dim * dim) * s
    if plastic:
        b += s + (s if dim == 2 else 0) + (s if bonded else 0) + (1 if yielded else 0)
    if cracking:
        b += s
    return b


@dataclass(frozen=True)
class MemoryEstimate:
    """Memory of a scenario (bytes).

    Attributes
    ----------
    n_particles : int
    particles : int
        Device bytes of the particle state.
    columns : int
        Device bytes of the bonded weak layers' lattice columns (index per particle, sums per column).
    grid_nodes, grid_copies : int
    grid : int
        Device bytes of the grid copies.
    host : int
        Host bytes kept beside the state for the whole run: the seeded and the initial positions,
        the bonded layers' column indices.
    staging : int
        Host bytes of the initial ``x``, ``v``, ``C`` built before their upload (freed after).
    """

    n_particles: int
    particles: int
    columns: int
    grid_nodes: int
    grid_copies: int
    grid: int
    host: int
    staging: int

    @property
    def device(self) -> int:
        """Device bytes: particles, bonded columns and grid."""
        return self.particles + self.columns + self.grid

    @property
    def total(self) -> int:
        """Everything: device, host and staging bytes (all host memory on the CPU)."""
        return self.device + self.host + self.staging


def estimate_memory(scenario: Scenario, device: str, n_threads: int | None = None) -> MemoryEstimate:
    """Estimate the memory of a validated ``scenario`` on ``device`` without allocating anything."""
    dom, dim, prec = scenario.domain, scenario.domain.dimension, scenario.precision
    s = 8 if prec == "float64" else 4
    yielded = "yielded" in scenario.output.fields
    n, part, bonded_n, columns = 0, 0, 0, 0
    for b in scenario.blocks:
        counts = lattice_counts(b.lo, b.hi, dom.dx, b.particles_per_cell)
        count = math.prod(counts)
        mat = scenario.materials[b.material]
        bonded = mat.model == "bonded_camclay"
        n += count
        part += count * particle_bytes(dim, prec, plastic=mat.plastic, bonded=bonded, yielded=yielded,
                                       cracking=mat.model == "tensile_cracking")
        if bonded:                 # column index (int32) per particle, a vec2d of sums per column (all but y)
            bonded_n += count
            columns += count * 4 + (count // counts[1]) * 16
    shape = grid_shape(dom.lo, dom.hi, dom.dx)
    nodes = 1
    for c in shape:
        nodes *= c
    copies = grid_copies(device, n, shape, n_threads)
    return MemoryEstimate(n, part, columns, nodes, copies, copies * nodes * (1 + dim) * s,
                          n * 2 * dim * 8 + bonded_n * 4, n * (2 * dim + dim * dim) * s)


def available_memory(device: str) -> tuple[int | None, int | None]:
    """``(host bytes available, device bytes free)``: Linux ``MemAvailable`` (None elsewhere) and, on CUDA,
    the device's free memory (None on the CPU)."""
    host = None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    host = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError, IndexError):
        pass
    dev = wp.get_device(device)
    return host, (int(dev.free_memory) if dev.is_cuda else None)


def check_memory(scenario: Scenario, device: str, n_threads: int | None = None, max_memory=None) -> MemoryEstimate:
    """Refuse (:class:`InvalidArgument`, one line) a scenario whose estimate exceeds the available memory or
    ``max_memory`` (bytes, or text such as ``"16G"``); return the estimate."""
    est = estimate_memory(scenario, device, n_threads)
    limit = None if max_memory is None else parse_bytes(max_memory)
    host_free, dev_free = available_memory(device)
    on_cpu = dev_free is None
    checks = [(est.total if on_cpu else est.host + est.staging, host_free, "MemAvailable"),
              (est.device, dev_free, f"free on {device}"),
              (est.total, limit, "max_memory")]
    for need, have, what in checks:
        if have is not None and need > have:
            grid_heavy = est.grid > est.particles
            key, value = ("domain.lo/hi", (scenario.domain.lo, scenario.domain.hi)) if grid_heavy else \
                ("domain.dx", scenario.domain.dx)
            raise InvalidArgument(key, value, (
                f"a scene that fits in memory: {format_bytes(need)} needed ({est.n_particles:.3g} particles "
                f"{format_bytes(est.particles)}, grid {est.grid_copies} x {est.grid_nodes:.3g} nodes "
                f"{format_bytes(est.grid)}, host {format_bytes(est.host + est.staging)}), {format_bytes(have)} "
                f"available "
                f"({what}); " + ("shrink the domain or raise domain.dx" if grid_heavy else
                                 "raise domain.dx or shrink the blocks (or their particles_per_cell)")))
    return est
