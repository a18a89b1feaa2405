"""Every kernel the ready scenes and the material-point driver load compiles for CUDA (PTX), without a GPU.

The cases (``tests/helpers_cuda_compile.py``: the six ready scenes in every geometry they have, the P2G
variants that a scene's materials and output select, and the material-point driver for each material
model, float32 and float64, 64 in all) run a few steps on the CPU in a fresh interpreter; the Warp modules
of the kernels they launched, each compiled once however many cases share it, are compiled to PTX for
sm_75 (standing in for sm_70, which the CUDA 13 NVRTC of warp-lang 1.19 no longer targets), sm_80 and
sm_90 in this test's temporary folder. Any compile error fails the test with the kernel's file, line and
name and NVRTC's log. CI compiles at NVRTC's ``-O2``: the CUDA front end and the code generator (where a
CUDA-only error arises) run at every level, and ``-O3``, Warp's default for a GPU run, costs 2.8 times the
CPU time (433 s against 155 s, measured here).

The record ``benchmarks/perf/results/cuda_ptx.json`` (PTX bytes per kernel module and architecture at ``-O3``,
what a GPU run builds, with the environment) is written only when asked::

    MPM_WARP_PTX_RECORD=1 .venv/bin/python -m pytest -q tests/test_cuda_compile.py     (or =path.json)
    .venv/bin/python tests/helpers_cuda_compile.py --work /tmp/ptx --record benchmarks/perf/results/cuda_ptx.json

The test of the test: a kernel whose native snippet calls ``ndtri``, a helper Warp's CPU runtime has and
CUDA has not, runs on the CPU and must fail the CUDA compile, named.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest
import warp as wp
from helpers_cuda_compile import CASES, DRIVER_MODELS, compile_ptx, target_archs

HERE = os.path.dirname(os.path.abspath(__file__))
RECORD = os.environ.get("MPM_WARP_PTX_RECORD", "")
RECORD_PATH = (os.path.join(os.path.dirname(HERE), "benchmarks", "perf", "results", "cuda_ptx.json")
               if RECORD in ("1", "true") else RECORD)
#: NVRTC's optimisation level in CI (see the module docstring); the record uses Warp's default (-O3)
CI_OPT_LEVEL = 2
THREADS = max(1, min(4, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1))

#: kernel families (factory names) each kind of case launches: the step (on the CPU with its threads' floating-point
#: mode set and put back, flush_kernels), its health check and energies; walls; the stresses where the output holds
#: p, q; the bonded layer's column means and tracker; the monitors' kernels
STEP = {"begin_step_kernel", "p2g_kernel", "grid_update_kernel", "g2p_kernel", "end_step_kernel", "health_kernel",
        "energy_kernel", "wall_state_kernel", "flush_kernels"}
BONDED = {"kappa_column_sum_kernel", "kappa_column_mean_kernel", "column_sums_zero_kernel", "weak_layer_kernel"}
EXPECTED = {"elastic_block": STEP | {"stress_kernel"}, "pst": STEP | BONDED | {"deflection_kernel"},
            "shear_test": STEP | BONDED | {"push_kernel", "stress_kernel"}, "material_point": {"drive_kernel"}}


def _expected(case: str) -> set[str]:
    if case.startswith("columns/"):                  # a scene's copies stepped together: the shared step too
        return _expected(case.split("/", 1)[1]) | {"offer_dt_kernel", "least_dt_kernel", "take_dt_kernel"}
    kind, geometry = case.split("/")[:2]
    kind = "pst" if kind.startswith("pst") else kind
    out = set(EXPECTED[kind])
    if geometry.startswith("2d") and (kind != "elastic_block" or "camclay" in geometry):
        out.add("health_zz_kernel")                  # F_zz of plane-strain Cam-Clay particles
    if geometry.endswith("closure"):
        out.add("closure_kernel")                    # the laminate closure before every P2G
    if kind == "elastic_block" and geometry.endswith("yielded"):
        out.discard("stress_kernel")                 # that output holds x and the yield flags only
    return out


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    """Run the cases and compile their modules in a fresh interpreter (``helpers_cuda_compile.py``); its summary."""
    tmp = tmp_path_factory.mktemp("cuda_compile")
    cmd = [sys.executable, os.path.join(HERE, "helpers_cuda_compile.py"), "--work", str(tmp),
           "--summary", str(tmp / "summary.json"), "--threads", str(THREADS)]
    cmd += ["--record", RECORD_PATH] if RECORD else ["--opt", str(CI_OPT_LEVEL)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-6000:]
    print("\ncuda compile:", proc.stdout.strip().splitlines()[-1])
    with open(tmp / "summary.json") as fh:
        return json.load(fh)


@pytest.mark.slow
def test_every_case_ran_and_launched_its_kernels(compiled):
    runs, modules = compiled["cases"], compiled["modules"]
    assert list(runs) == [c.name for c in CASES]
    assert len(CASES) == 2 * (6 + 4 * 3 + 2 + 2 + 2 + 2 * len(DRIVER_MODELS) + 1)
    for case, r in runs.items():
        families = {modules[n]["family"] for n in r["modules"]}
        if not case.startswith("material_point"):
            families.discard("drive_kernel")   # a scene's first build calibrates its weak layer with the driver
        assert families == _expected(case), case
        assert r["steps"] > 0 and r["particles"] > 0, case
    # one module per kernel variant: the three PST scenes share theirs, precisions share only the kernels
    # without a scalar type (the clock's, the column sums' reset, the floating-point mode's two)
    step = {c: {n for n in runs[c]["modules"] if modules[n]["family"] != "drive_kernel"}
            for c in ("pst_demo/2d/float32", "pst_slope/2d/float32", "pst_demo/2d/float64")}
    assert step["pst_demo/2d/float32"] == step["pst_slope/2d/float32"]
    shared = step["pst_demo/2d/float32"] & step["pst_demo/2d/float64"]
    assert {modules[n]["family"] for n in shared} == {"end_step_kernel", "column_sums_zero_kernel", "flush_kernels"}
    assert len(shared) == 4
    by_family = {}
    for m in modules.values():
        by_family[m["family"]] = by_family.get(m["family"], 0) + 1
    assert by_family["drive_kernel"] == 2 * 2 * len(DRIVER_MODELS)
    # P2G: elastic, cracking, Cam-Clay and the bonded layer, the two plastic ones with and without yield flags
    assert by_family["p2g_kernel"] == 2 * 2 * 6


@pytest.mark.slow
def test_every_module_compiles_to_ptx_for_every_arch(compiled):
    assert compiled["failures"] == [], "CUDA compile errors:\n" + compiled["failure_report"]
    archs = compiled["archs"]
    assert tuple(archs) == target_archs() and len(archs) == 3
    for name, m in compiled["modules"].items():
        assert sorted(m["ptx"]) == sorted(map(str, archs)), name
        for arch, path in m["ptx"].items():
            with open(path) as fh:
                ptx = fh.read()
            assert len(ptx) == m["ptx_bytes"][arch] > 0 and re.search(rf"^\.target sm_{arch}\b", ptx, re.M), name
            # the kernel's CUDA entry point is in its module's PTX
            assert any(re.search(rf"\.entry {re.escape(e)}_cuda_kernel_forward\b", ptx) for e in m["entries"]), name


# ------------------------------------------------------------------------------------- test of the test
def _host_only_kernel():
    """A kernel Warp builds and runs on the CPU that is not valid CUDA: its native snippet calls ``ndtri``, the
    inverse normal CDF that Warp's CPU runtime defines (``crt.h``) and CUDA's device library does not."""

    @wp.func_native("return ndtri(y);")
    def host_ndtri(y: wp.float64) -> wp.float64: ...

    @wp.kernel(enable_backward=False, module="unique")
    def quantile_975(out: wp.array(dtype=wp.float64)):
        out[wp.tid()] = host_ndtri(wp.float64(0.975))

    return quantile_975


def test_a_kernel_that_is_not_valid_cuda_fails_the_check_named(tmp_path):
    kernel = _host_only_kernel()
    out = wp.zeros(2, dtype=wp.float64, device="cpu")
    wp.launch(kernel, 2, inputs=[out], device="cpu")       # a valid CPU kernel: the 97.5 % normal quantile
    np.testing.assert_allclose(out.numpy(), 1.959963984540054, rtol=1e-14)
    res = compile_ptx({kernel.module.name: kernel.module}, (target_archs()[-1],), str(tmp_path), opt_level=CI_OPT_LEVEL)
    assert set(res.failures) == {(kernel.module.name, target_archs()[-1])}
    report = res.failure_report()
    assert "test_cuda_compile.py" in report and "_host_only_kernel.<locals>.quantile_975" in report
    assert 'identifier "ndtri" is undefined' in report
