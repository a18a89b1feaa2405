"""Taichi peer of the block benchmarks: run :mod:`.taichi_mpm` with the protocol of :mod:`.warp_block`.

The scene (2D plane strain or 3D, elastic or Cam-Clay) is defined in
:mod:`.taichi_mpm` and :mod:`mpm_warp.studies.blocks`; this module runs it: ``ti.init``,
compile, ``warmup`` untimed steps, snapshot, then ``repeats`` repeats that
each restore the snapshot and time ``steps`` steps; the median is reported.
On the CPU the faster of the atomic and serialized P2G scatters is picked by a
few untimed probe steps, as a tuned Taichi code would.

Taichi is an optional extra (``pip install mpm-warp[bench]``): it is imported
lazily, only inside :func:`run_taichi_block`, never by the library. Taichi keeps one runtime per process
and sizes its CPU thread pool at ``ti.init``, so every configuration runs in
its own interpreter (:func:`run_taichi_block_subprocess`).

Command line
------------
``python -m mpm_warp.studies.perf.taichi_peer --n-grid 32 --dim 3 --material plastic --steps 50 --arch cpu
--threads 1 --json``
prints the result dict of :func:`run_taichi_block` as one JSON line on stdout
(Taichi's own log lines go to stderr).
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
from typing import Any

from .. import plastic_block as pb
from ..blocks import default_warmup, expected_com_y, initial_state
from . import taichi_mpm

_ARCH_NAMES = ("cpu", "cuda", "gpu", "vulkan", "metal", "opengl")
#: the module a child interpreter runs (``python -m``)
MODULE = "mpm_warp.studies.perf.taichi_peer"
#: the folder that holds this ``mpm_warp`` package: a child of the same interpreter imports this copy
_PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def taichi_available() -> bool:
    """Whether ``import taichi`` would find a module (without importing it)."""
    return importlib.util.find_spec("taichi") is not None


def _time_kernel(ti: Any, scene, kernel, snap: dict, steps: int, repeats: int) -> tuple[list[float], list[float]]:
    times, cpu = [], []
    for _ in range(repeats):
        scene.restore(snap)
        ti.sync()
        c0 = time.process_time()
        t0 = time.perf_counter()
        for _ in range(steps):
            kernel()
        ti.sync()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return times, cpu


def run_taichi_block(n_grid: int, steps: int, arch: str = "cpu", cpu_max_num_threads: int | None = None,
                     repeats: int = 3, p2g_scatter: str = "auto", dim: int = 3, material: str = "elastic",
                     warmup: int | None = None, diagnostics: bool = False, return_share: bool = False) -> dict:
    """Time the block in Taichi (calls ``ti.init`` in this process).

    Parameters
    ----------
    n_grid : int
        Grid nodes per axis (even); ``n_particles = n_grid**dim``.
    steps, repeats : int
        Timed steps per repeat and number of repeats (>= 1); the median is reported.
    arch : str
        ``"cpu"``, ``"cuda"``, ``"gpu"``, ``"vulkan"``, ``"metal"`` or ``"opengl"``;
        Taichi falls back to the CPU if it is missing (``arch`` in the result says).
    cpu_max_num_threads : int or None
        Taichi's CPU thread pool (None: all hardware threads).
    p2g_scatter : {"auto", "atomic", "serial"}
        ``"auto"``: atomic on GPUs; on the CPU the faster over untimed probe steps.
    dim : {2, 3}
    material : {"elastic", "plastic"}
    warmup : int or None
        Untimed steps before the snapshot (default :func:`default_warmup`).
    diagnostics : bool
        Cam-Clay: per-step return kinds of the timed steps (replayed with yield tracking).
    return_share : bool
        Cam-Clay: also time the same steps with the return compiled out
        (``no_return_s_per_step``; ``return_share = 1 - that / this``, from
        process CPU time on the CPU).

    Returns
    -------
    dict
        ``engine``, ``dim``, ``material``, ``n_particles``, ``n_grid``,
        ``steps``, ``warmup``, ``dt``, ``arch``, ``requested_arch``,
        ``threads``, ``p2g_scatter``, ``p2g_probe_s_per_step``,
        ``taichi_version``, ``median_s_per_step``, ``particle_steps_per_s``,
        ``times_s``, ``cpu_utilisation`` (process CPU time over wall time),
        ``bytes_per_particle``, ``grid_bytes_per_particle``, and ``com_y_after``
        with ``com_y_expected`` (elastic) or ``observables`` (Cam-Clay).
    """
    if steps < 1 or repeats < 1:
        raise ValueError("steps and repeats must be >= 1")
    if cpu_max_num_threads is not None and cpu_max_num_threads < 1:
        raise ValueError("cpu_max_num_threads must be >= 1 or None")
    if p2g_scatter not in ("auto", "atomic", "serial"):
        raise ValueError(f"p2g_scatter must be 'auto', 'atomic' or 'serial', got {p2g_scatter!r}")
    if arch not in _ARCH_NAMES:
        raise ValueError(f"arch must be one of {_ARCH_NAMES}, got {arch!r}")
    import taichi as ti

    init_kwargs: dict[str, Any] = {"arch": getattr(ti, arch), "default_fp": ti.f32, "default_ip": ti.i32,
                                   "debug": False}
    if cpu_max_num_threads is not None:
        init_kwargs["cpu_max_num_threads"] = int(cpu_max_num_threads)
    ti.init(**init_kwargs)
    cfg = ti.lang.impl.current_cfg()
    actual_arch = cfg.arch.name
    on_cpu = actual_arch in ("x64", "arm64")

    scene = taichi_mpm.build(ti, n_grid, dim, material)
    plastic = material == "plastic"
    mode = "plastic" if plastic else "elastic"
    candidates = (["atomic", "serial"] if on_cpu else ["atomic"]) if p2g_scatter == "auto" else [p2g_scatter]
    x0, v0, C0 = initial_state(n_grid, dim, material)
    modes = [mode] + (["plastic_track"] if plastic and diagnostics else []) + (["no_return"] if return_share else [])
    for name in candidates:  # compile every kernel outside the timings
        for m in modes:
            scene.reset(x0, v0, C0)
            scene.substep(name, m)()
    ti.sync()
    W = default_warmup(material, n_grid) if warmup is None else warmup
    scene.reset(x0, v0, C0)
    for _ in range(W):
        scene.substep(candidates[0], mode)()
    ti.sync()
    snap = scene.snapshot()

    probe: dict[str, float] = {}
    if len(candidates) > 1:
        for name in candidates * 2:  # best of two interleaved rounds of 3 steps
            t, _ = _time_kernel(ti, scene, scene.substep(name, mode), snap, 3, 1)
            probe[name] = min(t[0] / 3, probe.get(name, math.inf))
    scatter = min(candidates, key=lambda name: probe.get(name, 0.0))
    times, cpu_times = _time_kernel(ti, scene, scene.substep(scatter, mode), snap, steps, repeats)
    median_step = statistics.median(times) / steps
    n = scene.n_particles
    f = scene.fields
    # float32 components per particle: x, v (dim each), C, F (dim^2 each), log_Jp and, in plane strain, F_zz
    components = 2 * dim + 2 * dim * dim + ((2 if dim == 2 else 1) if plastic else 0)
    result = {
        "engine": "taichi", "dim": dim, "material": material, "n_particles": n, "n_grid": n_grid,
        "steps": steps, "warmup": W, "dt": scene.dt, "arch": actual_arch, "requested_arch": arch,
        "threads": int(cfg.cpu_max_num_threads) if on_cpu else None, "p2g_scatter": scatter,
        "p2g_probe_s_per_step": probe, "taichi_version": ".".join(str(part) for part in ti.__version__),
        "median_s_per_step": median_step, "particle_steps_per_s": n / median_step, "times_s": times,
        "cpu_utilisation": statistics.median(c / t for c, t in zip(cpu_times, times, strict=True)),
        "bytes_per_particle": 4.0 * components, "grid_bytes_per_particle": 4 * (dim + 1) * n_grid**dim / n,
    }
    if plastic:
        result["observables"] = pb.observables(f.F.to_numpy(), f.log_jp.to_numpy(),
                                               f.F_zz.to_numpy() if dim == 2 else None)
        finite = math.isfinite(result["observables"]["mean_p"])
    else:
        com_y = float(f.x.to_numpy()[:, 1].astype("float64").mean())
        result["com_y_after"] = com_y
        result["com_y_expected"] = expected_com_y(W + steps, scene.dt)
        finite = math.isfinite(com_y)
    result["cpu_s_per_step"] = statistics.median(cpu_times) / steps
    if return_share and plastic:
        t_nr, c_nr = _time_kernel(ti, scene, scene.substep(scatter, "no_return"), snap, steps, repeats)
        result["no_return_s_per_step"] = statistics.median(t_nr) / steps
        result["no_return_cpu_s_per_step"] = statistics.median(c_nr) / steps
        if on_cpu:  # CPU time on the (shared) CPU, one thread
            result["return_share"] = 1.0 - result["no_return_cpu_s_per_step"] / result["cpu_s_per_step"]
        else:
            result["return_share"] = 1.0 - result["no_return_s_per_step"] / median_step
    if diagnostics and plastic:
        scene.restore(snap)
        kernel = scene.substep(scatter, "plastic_track")
        kinds = []
        before = f.log_jp.to_numpy()
        for _ in range(steps):
            f.yielded.fill(0)
            kernel()
            after = f.log_jp.to_numpy()
            kinds.append(pb.return_kinds(before, after, f.yielded.to_numpy()))
            before = after
        result["return_kinds"] = kinds
        result["return_kind_problems"] = pb.check_return_kinds(kinds)
    if not finite:
        result["error"] = "non-finite state after the timed steps"
    return result


def run_taichi_block_subprocess(n_grid: int, steps: int, arch: str = "cpu", cpu_max_num_threads: int | None = None,
                                repeats: int = 3, p2g_scatter: str = "auto", python: str | None = None,
                                timeout_s: float | None = 600.0, dim: int = 3, material: str = "elastic",
                                warmup: int | None = None, diagnostics: bool = False,
                                return_share: bool = False) -> tuple[dict | None, str | None]:
    """Run :func:`run_taichi_block` in a fresh interpreter (``python -m``, :data:`MODULE`) and parse its JSON line.

    Parameters
    ----------
    n_grid, steps, arch, cpu_max_num_threads, repeats, p2g_scatter, dim, material, warmup, diagnostics, return_share
        As :func:`run_taichi_block`.
    python : str or None
        The interpreter (default this one, which then imports the same ``mpm_warp`` as this process).
    timeout_s : float or None
        Wall-clock limit of the child, seconds (None: none).

    Returns
    -------
    tuple
        ``(result, None)`` on success and ``(None, reason)`` when Taichi is
        not installed for ``python``, the run failed or it ran past ``timeout_s``.
    """
    python = python or sys.executable
    if python == sys.executable and not taichi_available():
        return None, "taichi is not installed (pip install 'mpm-warp[bench]' or 'pip install taichi')"
    cmd = [python, "-m", MODULE, "--n-grid", str(n_grid), "--steps", str(steps), "--arch", arch,
           "--repeats", str(repeats), "--p2g-scatter", p2g_scatter, "--dim", str(dim), "--material", material,
           "--json"]
    if cpu_max_num_threads is not None:
        cmd += ["--threads", str(cpu_max_num_threads)]
    if warmup is not None:
        cmd += ["--warmup", str(warmup)]
    if diagnostics:
        cmd.append("--diagnostics")
    if return_share:
        cmd.append("--return-share")
    env = None
    if python == sys.executable:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [_PACKAGE_ROOT, os.environ.get("PYTHONPATH")])))
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s, check=False, env=env)
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


def main(argv: list[str] | None = None) -> int:
    """Command line; exit status 0 on success, 3 if Taichi is not installed, 1 on failure."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-grid", type=int, default=32)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--arch", default="cpu", choices=_ARCH_NAMES)
    ap.add_argument("--threads", type=int, default=None, help="cpu_max_num_threads (default: all)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--p2g-scatter", default="auto", choices=("auto", "atomic", "serial"))
    ap.add_argument("--dim", type=int, default=3, choices=(2, 3))
    ap.add_argument("--material", default="elastic", choices=("elastic", "plastic"))
    ap.add_argument("--warmup", type=int, default=None)
    ap.add_argument("--diagnostics", action="store_true")
    ap.add_argument("--return-share", action="store_true")
    ap.add_argument("--json", action="store_true", help="print the result dict as one JSON line")
    a = ap.parse_args(argv)
    if not taichi_available():
        print("taichi is not installed (pip install 'mpm-warp[bench]')", file=sys.stderr)
        return 3
    with _stdout_to_stderr():
        res = run_taichi_block(a.n_grid, a.steps, a.arch, a.threads, a.repeats, a.p2g_scatter, a.dim, a.material,
                               a.warmup, a.diagnostics, a.return_share)
    if a.json:
        print(json.dumps(res), flush=True)
    else:
        print(f"{res['engine']} {res['dim']}D {res['material']} N {res['n_particles']} {res['arch']} "
              f"threads {res['threads']} {res['p2g_scatter']}: {res['particle_steps_per_s'] / 1e6:.3f} "
              "M particle-steps/s", flush=True)
    return 0 if "error" not in res else 1


if __name__ == "__main__":
    sys.exit(main())
