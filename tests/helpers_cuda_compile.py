"""CUDA readiness without a GPU: the kernel modules of every ready scene, compiled ahead of time to PTX.

:data:`CASES` are the ready scenes (``scenarios/*.toml``) shrunk to a few thousand particles (the
profile's PST, whose 5 mm grid resolves its thin weak layer, to 27k-108k) and a few steps, in float32
and float64 and in every geometry the scene has (PST: true 2D, the quasi-2D slab
``plane_strain = "slab"`` and a 3D column ``width > 0``, also for the profile's PST with its cracking
slab; shear test: 2D and 3D; the elastic block: its 3D box and a 2D one), the P2G variants a scene's
materials and output select (the block of Cam-Clay snow, yield flags in the output), the interface
closure of a layered stack (``scene.interface_closure``), and the
material-point driver (``mpm_warp.material_point``) for each material model in 2D and 3D.
:func:`run_cases` runs each on the CPU, so that every kernel it needs is built, and
records the Warp modules of the kernels it launched (every kernel is its own module,
``module="unique"``). :func:`compile_ptx` compiles each module once per architecture with
``wp.compile_aot_module(..., use_ptx=True)``, which needs NVRTC (in the warp-lang wheel) but no GPU
and no driver, and returns the PTX bytes per module and architecture and the failures, each with the
kernel's name, source line and NVRTC's log.

Run as a script it does both in a fresh interpreter, and writes a summary for
``tests/test_cuda_compile.py`` and, when asked, the record: in the process that compiled a module for
CUDA, Warp may rebuild its CPU code at the next launch (seen for the driver's), which would slow the
suite's later tests. ::

    python tests/helpers_cuda_compile.py --work DIR --summary DIR/summary.json [--record PATH] [--opt N]

Architectures: sm_70 (Volta), sm_80 (Ampere) and sm_90 (Hopper) were asked for; the NVRTC of
warp-lang 1.19 (CUDA 13) no longer compiles for sm_70, so the oldest target it has stands in for it
(sm_75, Turing) and the record says so (:func:`target_archs`).
"""

from __future__ import annotations

import argparse
import contextlib
import datetime
import json
import os
import platform
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
import warp as wp
from helpers_scenes import TINY_PST  # tests/ is on the path: pytest's rootdir, or this script's folder

from mpm_warp.studies.environment import check_provenance, git_commit

#: architectures asked for (sm_70, sm_80, sm_90)
REQUESTED_ARCHS = (70, 80, 90)

_SHORT = ["time.end=0.002", "time.frame_interval=0.001"]
_BLOCK_2D = ["domain.dimension=2", "domain.lo=[0.0, 0.0]", "domain.hi=[0.6, 0.4]", "domain.boundary_faces='x'",
             "blocks.0.lo=[0.2, 0.1]", "blocks.0.hi=[0.4, 0.2]", "walls.0.point=[0.0, 0.0]",
             "walls.0.normal=[0.0, 1.0]", "time.gravity=[0.0, -9.81]"]
_PST = TINY_PST + _SHORT
#: a 9 cm sample on a 7.5 mm grid (4 cells across the layer), 1.5 cm margins and loading block
_SHEAR = ["scene.dx=0.0075", "scene.sample_length=0.09", "scene.margin=0.015", "scene.load_thickness=0.015"] + _SHORT
#: Cam-Clay snow instead of the elastic block's (with and without the yield flags in the output): the P2G
#: variants no ready scene has and a scene's materials and output can ask for
_CAMCLAY = ["materials.snow.model='camclay'", "materials.snow.p0_ini=1e3"]
_YIELDED = ["output.fields=['x', 'yielded']"]
_GEOMETRIES = {
    "elastic_block": {"3d": _SHORT, "2d": _BLOCK_2D + _SHORT, "3d-camclay": _SHORT + _CAMCLAY,
                      "2d-camclay": _BLOCK_2D + _SHORT + _CAMCLAY, "3d-camclay-yielded": _SHORT + _CAMCLAY + _YIELDED,
                      "2d-camclay-yielded": _BLOCK_2D + _SHORT + _CAMCLAY + _YIELDED},
    "pst": {"2d": _PST, "slab": _PST + ["scene.plane_strain='slab'"], "3d": _PST + ["scene.width=0.02"]},
    "shear_test": {"2d": _SHEAR, "3d": _SHEAR + ["scene.width=0.015"]},
}
#: the profile's PST (a layered slab that cracks, on the profile's weak layer): a 50 cm column (longer than its
#: 39 cm slab, as a PST must be), a few steps
_PROFILE = ["scene.length=0.5", "scene.saw.cut_length=0.1", "time.end=0.0002", "time.frame_interval=0.0001"]
_GEOMETRIES["pst_profile"] = {"2d": _PROFILE, "slab": _PROFILE + ["scene.plane_strain='slab'"],
                              "3d": _PROFILE + ["scene.width=0.01"]}
#: the bonded weak layer's P2G with the yield flags (one PST scene: the three share their kernels)
_PST_YIELDED = {"2d-yielded": _PST + ["output.fields=['x', 'log_jp', 'yielded']"],
                "3d-yielded": _PST + ["scene.width=0.02", "output.fields=['x', 'log_jp', 'yielded']"]}
#: the laminate closure at the layers' interfaces (one PST scene: the three share their kernels), 2D and 3D
_PST_CLOSURE = {"2d-closure": _PST + ["scene.interface_closure=true"],
                "3d-closure": _PST + ["scene.width=0.02", "scene.interface_closure=true"]}
_SCENES = {"elastic_block": "elastic_block", "pst_demo": "pst", "pst_flat": "pst", "pst_slope": "pst",
           "pst_profile": "pst_profile", "shear_test": "shear_test"}
PRECISIONS = ("float32", "float64")
DRIVER_MODELS = ("elastic", "camclay", "bonded_camclay", "tensile_cracking")


@dataclass(frozen=True)
class Case:
    """One thing run on the CPU: a ready scene (``scene``) with ``overrides``, or the driver (``model``)."""

    name: str
    precision: str
    scene: str = ""
    overrides: tuple = ()
    model: str = ""
    dim: int = 3
    #: run this many copies of the scene stepped together (mpm_warp.column_batch: the shared step's kernels)
    columns: int = 0


def _cases() -> tuple[Case, ...]:
    out = []
    for prec in PRECISIONS:
        for scene, kind in _SCENES.items():
            geometries = {**_GEOMETRIES[kind], **({**_PST_YIELDED, **_PST_CLOSURE} if scene == "pst_demo" else {})}
            for geo, ov in geometries.items():
                out.append(Case(f"{scene}/{geo}/{prec}", prec, scene=scene,
                                overrides=tuple(ov) + (f"precision='{prec}'",)))
        for model in DRIVER_MODELS:
            for dim in (2, 3):
                out.append(Case(f"material_point/{model}/{dim}d/{prec}", prec, model=model, dim=dim))
        out.append(Case(f"columns/elastic_block/2d/{prec}", prec, scene="elastic_block", columns=2,
                        overrides=tuple(_GEOMETRIES["elastic_block"]["2d"]) + (f"precision='{prec}'",)))
    return tuple(out)


#: every case, in the order they run
CASES = _cases()


def target_archs() -> tuple[int, ...]:
    """:data:`REQUESTED_ARCHS`, each replaced by the oldest architecture NVRTC compiles at or above it."""
    wp.init()
    have = sorted(wp._src.context.runtime.nvrtc_supported_archs)
    return tuple(min(a for a in have if a >= r) for r in REQUESTED_ARCHS)


def kernel_label(module) -> str:
    """``file:line qualname`` of a module's kernels (the repository-relative file), e.g.
    ``kernels/p2g.py:63 p2g_kernel.<locals>.p2g``."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    labels = []
    for k in module.kernels.values():
        code = k.func.__code__
        path = os.path.relpath(code.co_filename, root) if code.co_filename.startswith(root) else code.co_filename
        labels.append(f"{path}:{code.co_firstlineno} {k.func.__qualname__}")
    return ", ".join(labels)


@contextlib.contextmanager
def launched_modules(into: dict):
    """Record into ``into`` (module name -> module) the module of every mpm_warp kernel launched or recorded
    through ``wp.launch`` while the block runs."""
    real = wp.launch

    def launch(kernel, *args, **kwargs):
        if getattr(kernel.func, "__module__", "").startswith("mpm_warp"):
            into.setdefault(kernel.module.name, kernel.module)
        return real(kernel, *args, **kwargs)

    wp.launch = launch
    try:
        yield into
    finally:
        wp.launch = real


def _drive(case: Case) -> None:
    from mpm_warp.material_point import drive_material_points
    from mpm_warp.materials import BondedCamClay, CamClaySnow, CrackingSnow, Elastic

    mat = {"elastic": Elastic(1e6, 0.3, 250.0),
           "camclay": CamClaySnow(1e6, 0.3, 250.0, M=1.2, beta=0.3, xi=10.0, p0_ini=1e3),
           "bonded_camclay": BondedCamClay(1e6, 0.3, 150.0, M=1.2, beta=0.3, xi=0.05, p_bond=2e3, kappa_s=20.0),
           "tensile_cracking": CrackingSnow(1e6, 0.3, 250.0, tensile_strength=5e3, fracture_energy=0.1,
                                            band_width=0.005)}
    L = np.zeros((3, case.dim, case.dim))
    L[:, 0, 0] = -1e-3                       # three small compressive increments
    r = drive_material_points(L_path=L, material=mat[case.model], dtype=case.precision, device="cpu")
    assert np.all(np.isfinite(r["stress"])), case.name


def run_cases(out_dir: str, cases=CASES) -> dict[str, dict]:
    """Run every case on the CPU (writing the scenes' run files under ``out_dir``); return per case name
    the modules it launched (name -> module) and its particles and steps."""
    import mpm_warp as mw

    runs = {}
    for i, case in enumerate(cases):
        mods: dict = {}
        with launched_modules(mods):
            if case.model:
                _drive(case)
                info = {"particles": 3, "steps": 3}
            elif case.columns:
                info = _together(case, os.path.join(out_dir, f"case{i}"))
            else:
                res = mw.run(case.scene, os.path.join(out_dir, f"case{i}.h5"), device="cpu",
                             overrides=list(case.overrides))
                info = {"particles": res.n_particles, "steps": res.steps}
        runs[case.name] = {"modules": mods, **info}
    return runs


def _together(case: Case, prefix: str) -> dict:
    """``case.columns`` copies of the case's scene stepped together on the CPU (:mod:`mpm_warp.column_batch`),
    writing ``<prefix>_<k>.h5``."""
    import mpm_warp as mw
    from mpm_warp.column_batch import run_columns
    from mpm_warp.runner import simulation_for

    sims = [simulation_for(mw.load_scenario(case.scene, list(case.overrides)), "cpu", 1) for _ in range(case.columns)]
    res = run_columns(sims, [f"{prefix}_{k}.h5" for k in range(case.columns)])
    return {"particles": sum(r.n_particles for r in res), "steps": res[0].steps}


@dataclass
class Compiled:
    """PTX of a set of modules: ``ptx_bytes[module][arch]``, ``seconds[module]`` (all its archs),
    ``failures[(module, arch)]`` (error text), ``labels[module]`` (:func:`kernel_label`)."""

    archs: tuple
    opt_level: int
    ptx_bytes: dict = field(default_factory=dict)
    ptx_paths: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)
    failures: dict = field(default_factory=dict)
    labels: dict = field(default_factory=dict)

    def failure_report(self) -> str:
        """One paragraph per failure: architecture, kernel, module and the error with NVRTC's log."""
        return "\n\n".join(f"sm_{arch}: {self.labels[name]} (module {name}):\n{err}"
                           for (name, arch), err in sorted(self.failures.items()))


@contextlib.contextmanager
def _captured_native_output():
    """Capture what native code writes to the file descriptors 1 and 2 (NVRTC's log) into ``out[0]``."""
    out = [""]
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        saved = [os.dup(1), os.dup(2)]
        try:
            for fd in (1, 2):
                os.dup2(tmp.fileno(), fd)
            yield out
        finally:
            for fd, s in zip((1, 2), saved, strict=True):
                os.dup2(s, fd)
                os.close(s)
            tmp.seek(0)
            out[0] = tmp.read().decode(errors="replace")


def _compile_one(module, archs, module_dir: str) -> tuple[dict, dict, dict]:
    sizes, paths, errors = {}, {}, {}
    for arch in archs:
        try:
            (path,) = wp.compile_aot_module(module, arch=arch, use_ptx=True, module_dir=module_dir)
            sizes[arch], paths[arch] = os.path.getsize(path), str(path)
        except Exception as e:  # noqa: BLE001 - every compile error is reported, with the kernel's name
            errors[arch] = f"{type(e).__name__}: {e}"
    return sizes, paths, errors


def compile_ptx(modules: dict, archs, out_dir: str, opt_level: int | None = None, threads: int = 2) -> Compiled:
    """Compile each module (name -> module) to PTX for each architecture, ``threads`` modules at a time.

    Each module has its own folder under ``out_dir`` (Warp skips a compile whose PTX is already there).
    ``opt_level`` is NVRTC's optimisation level (None: Warp's default for CUDA, 3). A failed compile is
    repeated alone with the native output captured, so that its failure holds NVRTC's log.
    """
    res = Compiled(tuple(archs), 3 if opt_level is None else opt_level)
    saved = wp.config.optimization_level
    wp.config.optimization_level = opt_level      # restored below

    def one(item):
        name, module = item
        t0 = time.perf_counter()
        out = _compile_one(module, archs, os.path.join(out_dir, name))
        return name, out, time.perf_counter() - t0

    try:
        with ThreadPoolExecutor(max(1, threads)) as pool:
            for name, (sizes, paths, errors), sec in pool.map(one, sorted(modules.items())):
                res.labels[name] = kernel_label(modules[name])
                res.ptx_bytes[name], res.ptx_paths[name], res.seconds[name] = sizes, paths, sec
                res.failures.update({(name, a): e for a, e in errors.items()})
        for name, arch in sorted(res.failures):
            with _captured_native_output() as log:
                _, _, again = _compile_one(modules[name], (arch,), os.path.join(out_dir, name))
            res.failures[name, arch] = again.get(arch, res.failures[name, arch]) + "\n" + log[0].strip()
    finally:
        wp.config.optimization_level = saved
    return res


def environment() -> dict:
    """The code (its commit), Warp, its NVRTC, the machine and the date of a record."""
    wp.init()
    tk = wp._src.context.runtime.toolkit_version
    return {"git_commit": git_commit(), "warp": wp.__version__,
            "nvrtc_cuda_toolkit": ".".join(map(str, tk)) if tk else None,
            "cuda_driver": wp.is_cuda_available(), "python": platform.python_version(),
            "machine": platform.machine(), "cpus": os.cpu_count(),
            "load_average_1_5_15_min": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}


def ptx_record(runs: dict, compiled: Compiled, seconds: dict) -> dict:
    """The record to watch (``benchmarks/perf/results/cuda_ptx.json``): PTX bytes per kernel module and
    architecture, the cases that load each module, totals and the largest modules, the environment."""
    cases_of: dict = {}
    for case, run in runs.items():
        for name in run["modules"]:
            cases_of.setdefault(name, []).append(case)
    archs = {f"sm_{a}": a for a in compiled.archs}
    modules = {name: {"kernel": compiled.labels[name], "cases": cases_of.get(name, []),
                      "ptx_bytes": {k: compiled.ptx_bytes[name].get(a) for k, a in archs.items()},
                      "compile_s_all_archs": round(compiled.seconds[name], 3)}
               for name in sorted(compiled.ptx_bytes)}
    return {**record_head(list(archs), compiled.opt_level, seconds, len(runs), modules, environment()),
            "cases": {case: {"particles": r["particles"], "steps": r["steps"], "modules": sorted(r["modules"])}
                      for case, r in runs.items()},
            "modules": modules}


def record_head(archs: list[str], opt_level: int, seconds: dict, n_cases: int, modules: dict, env: dict) -> dict:
    """The record's summary of its ``modules`` (PTX bytes per ``archs`` key, e.g. ``"sm_90"``): totals, the five
    largest modules and the largest of each kernel family per architecture."""

    def largest(k: str) -> list:
        top = sorted(modules.values(), key=lambda m: -(m["ptx_bytes"][k] or 0))[:5]
        return [{"ptx_bytes": m["ptx_bytes"][k], "kernel": m["kernel"], "cases": m["cases"][:4]} for m in top]

    per_family: dict = {}
    for m in modules.values():
        fam = m["kernel"].split(" ")[-1].split(".")[0]
        for k in archs:
            per_family.setdefault(fam, {}).setdefault(k, 0)
            per_family[fam][k] = max(per_family[fam][k], m["ptx_bytes"][k] or 0)
    return {
        "what": "PTX bytes of every Warp kernel module that the ready scenes and the material-point driver load, "
                "compiled ahead of time with wp.compile_aot_module(use_ptx=True) without a GPU "
                "(tests/test_cuda_compile.py; rewrite with MPM_WARP_PTX_RECORD=1)",
        "environment": env,
        "requested_archs": [f"sm_{a}" for a in REQUESTED_ARCHS], "archs": archs,
        "arch_note": "an architecture NVRTC does not compile is replaced by the oldest one above it "
                     "(sm_70 -> sm_75 with the CUDA 13 NVRTC of warp-lang 1.19)",
        "nvrtc_optimization_level": opt_level,
        "n_cases": n_cases, "n_modules": len(modules),
        "seconds": {k: round(v, 2) for k, v in seconds.items()},
        "total_ptx_bytes": {k: sum(m["ptx_bytes"][k] or 0 for m in modules.values()) for k in archs},
        "largest": {k: largest(k) for k in archs},
        "largest_per_kernel_family": dict(sorted(per_family.items(), key=lambda kv: -max(kv[1].values()))),
    }


def summary(runs: dict, compiled: Compiled, seconds: dict) -> dict:
    """What the test checks: per case its modules, per module its kernels' entry names, PTX files and bytes,
    the failures with their reports."""
    return {"archs": list(compiled.archs), "opt_level": compiled.opt_level, "seconds": seconds,
            "cases": {c: {"particles": r["particles"], "steps": r["steps"], "modules": sorted(r["modules"])}
                      for c, r in runs.items()},
            "modules": {n: {"kernel": compiled.labels[n],
                            "family": next(iter(m.kernels.values())).func.__qualname__.split(".")[0],
                            "entries": sorted(k.get_mangled_name() for k in m.kernels.values()),
                            "ptx": {str(a): p for a, p in compiled.ptx_paths[n].items()},
                            "ptx_bytes": {str(a): b for a, b in compiled.ptx_bytes[n].items()},
                            "compile_s": round(compiled.seconds[n], 3)}
                        for r in runs.values() for n, m in r["modules"].items()},
            "failures": [{"module": n, "arch": a, "kernel": compiled.labels[n], "error": e}
                         for (n, a), e in sorted(compiled.failures.items())],
            "failure_report": compiled.failure_report()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Compile every kernel module of the ready scenes to PTX, without a GPU")
    ap.add_argument("--work", required=True, help="folder of the run files and the PTX (one folder per module)")
    ap.add_argument("--summary", help="JSON summary for tests/test_cuda_compile.py")
    ap.add_argument("--record", help="write the PTX record here (e.g. benchmarks/perf/results/cuda_ptx.json)")
    ap.add_argument("--opt", type=int, default=None, help="NVRTC optimisation level (default: Warp's, 3)")
    ap.add_argument("--threads", type=int, default=2, help="modules compiled at a time")
    a = ap.parse_args(argv)
    if a.record:  # uncommitted code's record is refused before the compile, not into the committed results
        check_provenance(os.path.dirname(os.path.abspath(a.record)))
    wp.config.quiet = True
    os.makedirs(a.work, exist_ok=True)
    t0 = time.perf_counter()
    runs = run_cases(a.work)
    t1 = time.perf_counter()
    modules = {n: m for r in runs.values() for n, m in r["modules"].items()}
    res = compile_ptx(modules, target_archs(), os.path.join(a.work, "ptx"), opt_level=a.opt, threads=a.threads)
    seconds = {"cases_on_cpu": round(t1 - t0, 2), "ptx_compile": round(time.perf_counter() - t1, 2),
               "process_cpu": round(time.process_time(), 2), "threads": a.threads,
               "load_average_1_min": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None}
    print(f"{len(runs)} cases: {seconds['cases_on_cpu']:.1f} s; {len(modules)} modules x {len(res.archs)} archs "
          f"(-O{res.opt_level}, {a.threads} threads): {seconds['ptx_compile']:.1f} s; {len(res.failures)} failures; "
          f"CPU time {seconds['process_cpu']:.1f} s, load {seconds['load_average_1_min']}")
    for path, obj in ((a.summary, lambda: summary(runs, res, seconds)),
                      (a.record if not res.failures else None, lambda: ptx_record(runs, res, seconds))):
        if path:
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
            with open(path, "w") as fh:
                json.dump(obj(), fh, indent=1)
                fh.write("\n")
    if res.failures:
        print(res.failure_report(), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
