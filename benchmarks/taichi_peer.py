"""Taichi peer of the elastic MLS-MPM block throughput benchmark.

This module simulates the same scene as the Warp throughput benchmark, written
the way an experienced Taichi user would write it (one fused ``ti.kernel`` per
step whose top-level loops are parallel, ``ti.static`` stencil loops,
``ti.svd`` for the 3x3 SVD, dense fields), so that the benchmark can report
Warp/Taichi throughput ratios in the same run. P2G comes in two variants,
atomic scatter (mpm88 style) and parallel stress + serialized scatter (atomics
demoted to plain adds, much faster on few-core CPUs); by default the faster one
is picked at run time (see :func:`_build_block`).

Taichi is an optional extra (``pip install mpm-warp[bench]``): it is imported
lazily, only by this benchmark, never by the library.

Scene
-----
* Unit box ``[0, 1]^3``, ``n_grid^3`` grid nodes at ``x_i = i * dx``,
  ``dx = 1 / n_grid``; quadratic B-spline weights, MLS-MPM (Hu et al. 2018).
* Block ``[0.25, 0.75]^3`` with 2 particles per cell per axis on a regular
  lattice, ``x = 0.25 + (i + 0.5) * dx / 2``, hence ``n_particles = n_grid^3``.
* Elastic St Venant-Kirchhoff in Hencky strain, ``E = 1e5`` Pa, ``nu = 0.3``,
  ``rho = 1000`` kg/m^3, ``V0 = (dx / 2)^3``, ``m = rho V0``.
* Grid nodes with mass ``> 1e-12`` (absolute threshold, kg) get
  ``v = p / m + dt g``; slip walls on nodes with ``i < 3`` or ``i > n_grid - 3``
  (exactly Taichi's ``bound = 3`` test in mpm88/mpm128).
* ``dt = 1e-4`` s, float32 throughout, zero initial velocity, ``F = I``,
  ``C = 0``.

Command line
------------
``python benchmarks/taichi_peer.py --n-grid 32 --steps 50 --arch cpu --threads 1 --json``
prints the result dict of :func:`run_taichi_block` as one JSON line on stdout
(Taichi's own log lines go to stderr). Without ``--json`` a short table is
printed. ``--table`` runs the default sweep (n_grid 24, 32, 48, 64 at 1 thread
and all cores), each configuration in its own subprocess.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import json
import math
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Iterator
from types import SimpleNamespace
from typing import Any

#: Young's modulus (Pa).
YOUNG_E = 1.0e5
#: Poisson ratio.
POISSON_NU = 0.3
#: Density (kg/m^3).
DENSITY = 1000.0
#: Fixed time step (s).
DT = 1.0e-4
#: Gravity (m/s^2).
GRAVITY = (0.0, -9.81, 0.0)
#: Width (in cells) of the slip boundary layer, Taichi style.
BOUND = 3
#: Absolute grid-mass threshold (kg) below which a node is treated as empty.
MASS_EPS = 1.0e-12

_ARCH_NAMES = ("cpu", "cuda", "gpu", "vulkan", "metal", "opengl")


def taichi_available() -> bool:
    """Tell whether the optional ``taichi`` package can be imported.

    Returns
    -------
    bool
        ``True`` if ``import taichi`` would find a module, without importing it.
    """
    return importlib.util.find_spec("taichi") is not None


def block_positions(n_grid: int):
    """Initial particle lattice of the benchmark block.

    Parameters
    ----------
    n_grid : int
        Grid resolution per axis; must be a positive multiple of 2.

    Returns
    -------
    numpy.ndarray
        ``(n_grid**3, 3)`` float32 positions, ``x = 0.25 + (i + 0.5) * dx / 2``
        per axis, computed in float64 and rounded once to float32. Ordering is
        C order over ``(i, j, k)``.
    """
    import numpy as np

    if n_grid <= 0 or n_grid % 2:
        raise ValueError(f"n_grid must be a positive even integer, got {n_grid}")
    dx = 1.0 / n_grid
    axis = 0.25 + (np.arange(n_grid, dtype=np.float64) + 0.5) * (0.5 * dx)
    gx, gy, gz = np.meshgrid(axis, axis, axis, indexing="ij")
    return np.stack([gx.ravel(), gy.ravel(), gz.ravel()], axis=1).astype(np.float32)


def expected_com_y(steps: int, dt: float = DT, y0: float = 0.5) -> float:
    """Centre-of-mass height of the freely falling block after ``steps`` steps.

    MLS-MPM with APIC transfers conserves linear momentum, internal forces
    cancel, and the block never reaches the walls in a short run, so the
    symplectic-Euler free fall gives ``y = y0 + g dt^2 steps (steps + 1) / 2``.

    Parameters
    ----------
    steps : int
        Number of steps from rest.
    dt : float, optional
        Time step (s).
    y0 : float, optional
        Initial centre-of-mass height.

    Returns
    -------
    float
        Expected centre-of-mass height (float64 arithmetic).
    """
    return y0 + GRAVITY[1] * dt * dt * steps * (steps + 1) / 2.0


def _arch_from_name(ti: Any, arch: str) -> Any:
    if arch not in _ARCH_NAMES:
        raise ValueError(f"arch must be one of {_ARCH_NAMES}, got {arch!r}")
    return getattr(ti, arch)


def _build_block(ti: Any, n_grid: int) -> tuple[Any, Any, Any, Any]:
    """Allocate fields and compile-time-specialised kernels for one scene.

    Must be called after ``ti.init``. All scene constants are Python floats
    captured by the kernels, so Taichi folds them into the generated code.

    Two step kernels share the fields; they differ only in how P2G scatters:

    ``"atomic"``
        mpm88/mpm128 style: one parallel particle loop computes the stress and
        scatters with atomic adds. Best on GPUs and many-core CPUs.
    ``"serial"``
        A parallel particle loop computes the stress (the SVD dominates) into a
        per-particle affine field, then a serialized loop scatters; Taichi
        demotes the atomics of a serial task to plain adds. On x64 a float
        atomic add is a ``lock cmpxchg`` loop, roughly 20x the cost of a plain
        add, so this is faster on CPUs with few cores.

    Parameters
    ----------
    ti : module
        The initialised ``taichi`` module.
    n_grid : int
        Grid nodes per axis.

    Returns
    -------
    tuple
        ``(fields, reset, substeps, n_particles)`` where ``fields`` is a
        namespace of the Taichi fields ``x, v, C, F, grid_v, grid_m``,
        ``reset(x0)`` restores the initial state from a float32 array and
        ``substeps`` maps ``"atomic"`` and ``"serial"`` to kernels that advance
        one time step.
    """
    import numpy as np

    f32 = ti.f32
    n_particles = n_grid**3
    dx = 1.0 / n_grid
    inv_dx = float(n_grid)
    dt = DT
    p_vol = (0.5 * dx) ** 3
    p_mass = DENSITY * p_vol
    mu = YOUNG_E / (2.0 * (1.0 + POISSON_NU))
    lam = YOUNG_E * POISSON_NU / ((1.0 + POISSON_NU) * (1.0 - 2.0 * POISSON_NU))
    stress_scale = -dt * p_vol * 4.0 * inv_dx * inv_dx
    gx, gy, gz = GRAVITY
    bound = BOUND
    mass_eps = MASS_EPS

    x = ti.Vector.field(3, dtype=f32, shape=n_particles)
    v = ti.Vector.field(3, dtype=f32, shape=n_particles)
    C = ti.Matrix.field(3, 3, dtype=f32, shape=n_particles)
    F = ti.Matrix.field(3, 3, dtype=f32, shape=n_particles)
    grid_v = ti.Vector.field(3, dtype=f32, shape=(n_grid, n_grid, n_grid))
    grid_m = ti.field(dtype=f32, shape=(n_grid, n_grid, n_grid))
    affine_f = ti.Matrix.field(3, 3, dtype=f32, shape=n_particles)

    @ti.kernel
    def _reset_state():
        for p in x:
            v[p] = ti.Vector.zero(f32, 3)
            C[p] = ti.Matrix.zero(f32, 3, 3)
            F[p] = ti.Matrix.identity(f32, 3)

    def reset(x0: np.ndarray) -> None:
        x.from_numpy(x0)
        _reset_state()

    @ti.func
    def _stencil(xp):
        """Base node, fractional offset and quadratic B-spline weights of a particle."""
        Xp = xp * inv_dx
        base = ti.cast(Xp - 0.5, ti.i32)
        fx = Xp - ti.cast(base, f32)
        w = ti.Matrix.rows([0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1.0) ** 2, 0.5 * (fx - 0.5) ** 2])
        return base, fx, w

    @ti.func
    def _affine(p):
        """Update F of particle ``p``; return its MLS-MPM affine momentum matrix."""
        F_p = (ti.Matrix.identity(f32, 3) + dt * C[p]) @ F[p]
        F[p] = F_p
        U, sig, _V = ti.svd(F_p)
        e0 = ti.log(sig[0, 0])
        e1 = ti.log(sig[1, 1])
        e2 = ti.log(sig[2, 2])
        tr = e0 + e1 + e2
        t = ti.Vector([2.0 * mu * e0 + lam * tr, 2.0 * mu * e1 + lam * tr, 2.0 * mu * e2 + lam * tr])
        # Kirchhoff tau = U diag(t) U^T, with the P2G factor -dt V0 4/dx^2 folded into the columns
        U_t = ti.Matrix([[U[i, d] * (t[d] * stress_scale) for d in ti.static(range(3))] for i in ti.static(range(3))])
        return U_t @ U.transpose() + p_mass * C[p]

    @ti.func
    def _scatter(p, affine):
        """P2G scatter of particle ``p``; ``+=`` is atomic in parallel loops, plain when serialized."""
        base, fx, w = _stencil(x[p])
        mv = p_mass * v[p]
        for i, j, k in ti.static(ti.ndrange(3, 3, 3)):
            offset = ti.Vector([i, j, k])
            dpos = (ti.cast(offset, f32) - fx) * dx
            weight = w[i, 0] * w[j, 1] * w[k, 2]
            grid_v[base + offset] += weight * (mv + affine @ dpos)
            grid_m[base + offset] += weight * p_mass

    @ti.func
    def _clear_grid():
        for I in ti.grouped(grid_m):
            grid_v[I] = ti.Vector.zero(f32, 3)
            grid_m[I] = 0.0

    @ti.func
    def _grid_update():
        """Momentum -> velocity, gravity, slip walls on the outer ``bound`` nodes."""
        for I in ti.grouped(grid_m):
            m = grid_m[I]
            if m > mass_eps:
                vel = grid_v[I] / m + dt * ti.Vector([gx, gy, gz])
                for d in ti.static(range(3)):
                    if I[d] < bound and vel[d] < 0.0:
                        vel[d] = 0.0
                    if I[d] > n_grid - bound and vel[d] > 0.0:
                        vel[d] = 0.0
                grid_v[I] = vel

    @ti.func
    def _g2p():
        """APIC gather of velocity and affine matrix, then advection."""
        for p in x:
            base, fx, w = _stencil(x[p])
            new_v = ti.Vector.zero(f32, 3)
            new_C = ti.Matrix.zero(f32, 3, 3)
            for i, j, k in ti.static(ti.ndrange(3, 3, 3)):
                offset = ti.Vector([i, j, k])
                dpos = ti.cast(offset, f32) - fx  # grid units: (x_i - x_p) / dx
                weight = w[i, 0] * w[j, 1] * w[k, 2]
                g_v = grid_v[base + offset]
                new_v += weight * g_v
                new_C += (4.0 * inv_dx * weight) * g_v.outer_product(dpos)
            v[p] = new_v
            C[p] = new_C
            x[p] += dt * new_v

    @ti.kernel
    def substep_atomic():
        _clear_grid()
        for p in x:  # fused stress + scatter, parallel with atomic adds (mpm88 style)
            _scatter(p, _affine(p))
        _grid_update()
        _g2p()

    @ti.kernel
    def substep_serial():
        _clear_grid()
        for p in x:  # stress (SVD) in parallel
            affine_f[p] = _affine(p)
        ti.loop_config(serialize=True)
        for p in range(n_particles):  # serialized scatter: Taichi demotes the atomics to plain adds
            _scatter(p, affine_f[p])
        _grid_update()
        _g2p()

    substeps = {"atomic": substep_atomic, "serial": substep_serial}
    fields = SimpleNamespace(x=x, v=v, C=C, F=F, grid_v=grid_v, grid_m=grid_m)
    return fields, reset, substeps, n_particles


def run_taichi_block(
    n_grid: int,
    steps: int,
    arch: str = "cpu",
    cpu_max_num_threads: int | None = None,
    repeats: int = 3,
    p2g_scatter: str = "auto",
) -> dict:
    """Time the elastic MLS-MPM block in Taichi.

    Calls ``ti.init`` in this process. Taichi keeps one runtime per process and
    its CPU thread pool is sized at the first initialisation, so to compare
    thread counts (or architectures) use :func:`run_taichi_block_subprocess`.

    The state is reset to the initial block before every repeat (outside the
    timed region), so every repeat times the same ``steps`` steps from rest and
    ``com_y_after`` is the centre-of-mass height after exactly ``steps`` steps.
    One untimed warm-up step compiles the kernels first.

    Parameters
    ----------
    n_grid : int
        Grid nodes per axis (even); ``n_particles = n_grid**3``.
    steps : int
        Steps per timed repeat (>= 1).
    arch : str, optional
        Taichi architecture name: ``"cpu"``, ``"cuda"``, ``"gpu"``,
        ``"vulkan"``, ``"metal"`` or ``"opengl"``. Taichi falls back to CPU if
        the requested backend is missing; the returned ``arch`` is the one
        actually used.
    cpu_max_num_threads : int or None, optional
        Size of Taichi's CPU thread pool; ``None`` keeps Taichi's default (all
        hardware threads). Ignored by GPU backends.
    repeats : int, optional
        Number of timed repeats (>= 1); the median is reported.
    p2g_scatter : {"auto", "atomic", "serial"}, optional
        P2G scatter variant (see :func:`_build_block`). ``"auto"`` picks
        ``"atomic"`` on GPU backends and, on CPU, whichever variant is faster
        over a few untimed probe steps after the warm-up, as a tuned Taichi
        code would.

    Returns
    -------
    dict
        ``n_particles``, ``n_grid``, ``steps``, ``arch`` (actual Taichi arch,
        e.g. ``"x64"``), ``requested_arch``, ``threads`` (CPU pool size, or
        ``None`` on GPU), ``p2g_scatter`` (variant used), ``p2g_probe_s_per_step``
        (probe timings per variant, empty unless ``"auto"`` on CPU),
        ``taichi_version``, ``median_s_per_step``,
        ``particle_steps_per_s``, ``times_s`` (seconds per repeat for all
        ``steps``), ``cpu_utilisation`` (median process CPU time over wall
        time; well below ``threads`` on CPU means the cores were shared with
        other work or the scatter was serial), ``com_y_after`` and ``com_y_expected`` (free-fall value
        from :func:`expected_com_y`).

    Raises
    ------
    ImportError
        If Taichi is not installed.
    ValueError
        On invalid arguments.
    """
    if steps < 1 or repeats < 1:
        raise ValueError("steps and repeats must be >= 1")
    if cpu_max_num_threads is not None and cpu_max_num_threads < 1:
        raise ValueError("cpu_max_num_threads must be >= 1 or None")
    if p2g_scatter not in ("auto", "atomic", "serial"):
        raise ValueError(f"p2g_scatter must be 'auto', 'atomic' or 'serial', got {p2g_scatter!r}")
    import taichi as ti

    x0 = block_positions(n_grid)
    init_kwargs: dict[str, Any] = {
        "arch": _arch_from_name(ti, arch),
        "default_fp": ti.f32,
        "default_ip": ti.i32,
        "debug": False,
    }
    if cpu_max_num_threads is not None:
        init_kwargs["cpu_max_num_threads"] = int(cpu_max_num_threads)
    ti.init(**init_kwargs)
    cfg = ti.lang.impl.current_cfg()
    actual_arch = cfg.arch.name
    on_cpu = actual_arch in ("x64", "arm64")

    fields, reset, substeps, n_particles = _build_block(ti, n_grid)

    if p2g_scatter == "auto":
        candidates = ["atomic", "serial"] if on_cpu else ["atomic"]
    else:
        candidates = [p2g_scatter]
    # warm-up: compile every kernel (and touch all memory) outside the timings
    for name in candidates:
        reset(x0)
        substeps[name]()
        ti.sync()
    probe: dict[str, float] = {}
    if len(candidates) > 1:
        probe_steps = 3
        for name in candidates * 2:  # best of two rounds, interleaved
            reset(x0)
            ti.sync()
            t0 = time.perf_counter()
            for _ in range(probe_steps):
                substeps[name]()
            ti.sync()
            elapsed = (time.perf_counter() - t0) / probe_steps
            probe[name] = min(elapsed, probe.get(name, math.inf))
    scatter = min(candidates, key=lambda name: probe.get(name, 0.0))
    substep = substeps[scatter]

    times: list[float] = []
    cpu_times: list[float] = []
    for _ in range(repeats):
        reset(x0)
        ti.sync()
        c0 = time.process_time()
        t0 = time.perf_counter()
        for _ in range(steps):
            substep()
        ti.sync()
        times.append(time.perf_counter() - t0)
        cpu_times.append(time.process_time() - c0)

    com_y = float(fields.x.to_numpy()[:, 1].astype("float64").mean())
    median_step = statistics.median(times) / steps
    version = ".".join(str(part) for part in ti.__version__)
    result = {
        "n_particles": n_particles,
        "n_grid": n_grid,
        "steps": steps,
        "arch": actual_arch,
        "requested_arch": arch,
        "threads": int(cfg.cpu_max_num_threads) if on_cpu else None,
        "p2g_scatter": scatter,
        "p2g_probe_s_per_step": probe,
        "taichi_version": version,
        "median_s_per_step": median_step,
        "particle_steps_per_s": n_particles / median_step,
        "times_s": times,
        "cpu_utilisation": statistics.median(c / t for c, t in zip(cpu_times, times, strict=True)),
        "com_y_after": com_y,
        "com_y_expected": expected_com_y(steps),
    }
    if not math.isfinite(com_y):
        result["error"] = "non-finite positions after the timed steps"
    return result


def run_taichi_block_subprocess(
    n_grid: int,
    steps: int,
    arch: str = "cpu",
    cpu_max_num_threads: int | None = None,
    repeats: int = 3,
    p2g_scatter: str = "auto",
    python: str | None = None,
    timeout_s: float | None = 600.0,
) -> tuple[dict | None, str | None]:
    """Run :func:`run_taichi_block` in a fresh interpreter and parse its JSON.

    Each call gets its own Taichi runtime, so thread counts and architectures
    can be compared within one benchmark run.

    Parameters
    ----------
    n_grid, steps, arch, cpu_max_num_threads, repeats, p2g_scatter
        Passed on to :func:`run_taichi_block` through the command line.
    python : str or None, optional
        Interpreter to use; defaults to ``sys.executable``.
    timeout_s : float or None, optional
        Wall-clock limit for the subprocess.

    Returns
    -------
    tuple
        ``(result, None)`` on success, where ``result`` is the dict returned by
        :func:`run_taichi_block`; ``(None, reason)`` if Taichi is not
        installed for ``python`` or the run failed.
    """
    python = python or sys.executable
    if python == sys.executable and not taichi_available():
        return None, "taichi is not installed (pip install 'mpm-warp[bench]' or 'pip install taichi')"
    cmd = [
        python,
        os.path.abspath(__file__),
        "--n-grid",
        str(n_grid),
        "--steps",
        str(steps),
        "--arch",
        arch,
        "--repeats",
        str(repeats),
        "--p2g-scatter",
        p2g_scatter,
        "--json",
    ]
    if cpu_max_num_threads is not None:
        cmd += ["--threads", str(cpu_max_num_threads)]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s, check=False)
    except subprocess.TimeoutExpired:
        return None, f"taichi peer timed out after {timeout_s} s"
    except OSError as exc:
        return None, f"could not start {python}: {exc}"
    if proc.returncode == 3:
        return None, "taichi is not installed for " + python
    for line in reversed(proc.stdout.splitlines()):
        if line.startswith("{"):
            try:
                return json.loads(line), None
            except json.JSONDecodeError:
                break
    tail = (proc.stderr or proc.stdout).strip().splitlines()[-5:]
    return None, f"taichi peer failed (exit {proc.returncode}): " + " | ".join(tail)


@contextlib.contextmanager
def _stdout_to_stderr() -> Iterator[None]:
    """Send file descriptor 1 to stderr, so Taichi's banners keep stdout clean."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def format_table(results: list[dict]) -> str:
    """Format benchmark results as a plain-text table.

    Parameters
    ----------
    results : list of dict
        Dicts returned by :func:`run_taichi_block`.

    Returns
    -------
    str
        One header line and one line per result.
    """
    lines = [
        f"{'N':>8} {'n_grid':>6} {'arch':>5} {'threads':>7} {'p2g':>6} {'ms/step':>9} "
        f"{'particle-steps/s':>17} {'cpu_util':>8} {'com_y_after':>12} {'com_y_expected':>14}"
    ]
    for r in results:
        lines.append(
            f"{r['n_particles']:>8} {r['n_grid']:>6} {r['arch']:>5} {r['threads']!s:>7} "
            f"{r['p2g_scatter']:>6} "
            f"{1e3 * r['median_s_per_step']:>9.3f} {r['particle_steps_per_s']:>17.4e} {r['cpu_utilisation']:>8.2f} "
            f"{r['com_y_after']:>12.8f} {r['com_y_expected']:>14.8f}"
        )
    return "\n".join(lines)


def _parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n-grid", type=int, default=32)
    parser.add_argument("--steps", type=int, default=50)
    parser.add_argument("--arch", default="cpu", choices=_ARCH_NAMES)
    parser.add_argument("--threads", type=int, default=None, help="cpu_max_num_threads (default: all)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--p2g-scatter", default="auto", choices=("auto", "atomic", "serial"))
    parser.add_argument("--json", action="store_true", help="print the result dict as one JSON line")
    parser.add_argument(
        "--table",
        action="store_true",
        help="sweep n_grid 24, 32, 48, 64 at 1 thread and all cores, one subprocess each",
    )
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str or None, optional
        Arguments; ``None`` reads ``sys.argv``.

    Returns
    -------
    int
        Exit status: 0 on success, 3 if Taichi is not installed, 1 on failure.
    """
    args = _parse_args(argv)
    if not taichi_available():
        print("taichi is not installed (pip install 'mpm-warp[bench]')", file=sys.stderr)
        return 3
    if args.table:
        results = []
        for n_grid in (24, 32, 48, 64):
            for threads in sorted({1, os.cpu_count() or 1}):
                res, reason = run_taichi_block_subprocess(
                    n_grid, args.steps, args.arch, threads, args.repeats, args.p2g_scatter
                )
                if res is None:
                    print(f"n_grid={n_grid} threads={threads}: {reason}", file=sys.stderr)
                    return 1
                results.append(res)
                print(format_table([res]).splitlines()[1], file=sys.stderr, flush=True)
        print(json.dumps(results) if args.json else format_table(results))
        return 0
    with _stdout_to_stderr():
        res = run_taichi_block(args.n_grid, args.steps, args.arch, args.threads, args.repeats, args.p2g_scatter)
    print(json.dumps(res) if args.json else format_table([res]), flush=True)
    return 0 if "error" not in res else 1


if __name__ == "__main__":
    sys.exit(main())
