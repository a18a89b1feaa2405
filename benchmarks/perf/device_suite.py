"""One command for a CUDA machine: device tests, graph against eager, throughput beside Taichi, memory, a PST.

Usage::

    bash benchmarks/device_suite.sh [--device cuda:0] [--quick] [--out DIR] [--parts tests graph ...]
    python benchmarks/perf/device_suite.py ...            (the same)
    bash benchmarks/device_suite.sh --plan [--quick]     (the parts, budgets and test modules, as JSON)

Every part runs in its own interpreter under its own time budget (a part past
its budget is killed with its process group and reported as ``timed_out`` with
what it had written so far); the whole full-mode suite is budgeted below 8
minutes. Results go to ``<out>/device_suite_<cuda|cpu>[_quick].json``
(default ``benchmarks/perf/results/``; ``--quick``: a temporary folder) with the device name, driver and CUDA
versions, Warp and Taichi versions, the date, the load average, and the
seconds each part took beside its budget.

Parts (full mode; ``--quick`` runs each with tiny sizes and a few steps, on
the CPU in seconds, as ``tests/test_device_suite.py`` does in CI):

``tests``
    The device-parametrised test modules with ``MPM_WARP_TEST_DEVICE`` set to
    the device, one pytest run per module (the modules comparing runs bit for
    bit, graph batching, resume, test_cuda_paths' guarded capture, with ``MPM_WARP_TEST_DETERMINISTIC=1``
    on CUDA, where float atomics are otherwise unordered).
``graph`` / ``graph_deterministic``
    The struck Cam-Clay block stepped eagerly and through a captured CUDA graph
    from the same state: bit-for-bit equality (``graph_deterministic``, Warp's
    run-to-run deterministic atomics; on the CPU every run is deterministic and
    a stand-in replays the captured step batches) or the observables within
    ``mpm_warp.studies.plastic_block.AGREEMENT`` (production atomics), and the seconds per step
    of both.
``memory``
    Device bytes per particle of the particle state and of the grid, elastic
    and Cam-Clay (and the device pool in use on CUDA).
``throughput``
    ``throughput.py`` beside Taichi at about 1M and 4M particles, 2D and
    3D, elastic and plastic (``device_suite_throughput_<dev>.json``, rewritten
    after every configuration).
``pst``
    One production-resolution flat PST (:func:`run_pst_flat`, the one place
    that knows how to run it), with its wall time per simulated second.
``field``
    A small field batch (``mpm_warp.studies.field_columns``): 16 made-up field columns stepped together on the
    device until each is decided, and the first alone on one CPU core: cases per hour both ways.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from concurrent.futures import ThreadPoolExecutor

# mpm_warp is imported inside the parts: the graph_deterministic part sets Warp's deterministic atomics first
HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")
ROOT = os.path.dirname(os.path.dirname(HERE))     # the repository: its tests/ run in the tests part

#: Seconds each part may take: (full, quick). The full budgets sum to 450 s (< 8 min with start-up).
BUDGETS = {"tests": (120, 60), "graph": (25, 40), "graph_deterministic": (25, 40), "memory": (15, 30),
           "throughput": (120, 90), "pst": (60, 60), "field": (85, 60)}
PARTS = tuple(BUDGETS)
#: Device-meaningful test modules, most telling first; the second group compares runs bit for bit.
TEST_MODULES = ("test_transfer", "test_camclay", "test_camclay_large_strain", "test_bonded_camclay",
                "test_bonded_camclay_driver", "test_cracking", "test_elasticity", "test_walls",
                "test_stability_time_step", "test_stability_contrast", "test_stability_impact",
                "test_stability_singular_F", "test_validation_api", "test_validation_elastic", "test_weak_layer")
BITWISE_TEST_MODULES = ("test_graph_batching", "test_resume", "test_cuda_paths")
QUICK_TEST_MODULES = ("test_elasticity", "test_graph_batching")
#: Test modules run side by side in the tests part (each in its own interpreter).
TEST_WORKERS = 8

#: Throughput sizes (approximate particle counts) and steps per repeat.
FULL_PARTICLES = (1.0e6, 4.0e6)
QUICK_PARTICLES = (512.0,)


def _is_cuda(device: str) -> bool:
    return device.startswith("cuda")


def _tag(device: str, quick: bool) -> str:
    return ("cuda" if _is_cuda(device) else "cpu") + ("_quick" if quick else "")


# --------------------------------------------------------------------------------------------- parts
def part_tests(device: str, quick: bool, deadline: float, out_dir: str) -> dict:
    """Run the device-parametrised test modules on ``device``, one pytest per module, within the budget.

    :data:`TEST_WORKERS` modules at a time, each in its own interpreter: on a fresh machine a module's time is mostly
    compiling kernels, CPU work (one by one, the first CUDA run reached 4 of 18 modules in 120 s).
    """
    groups = [(m, False) for m in (QUICK_TEST_MODULES if quick else TEST_MODULES)]
    if not quick:
        groups += [(m, _is_cuda(device)) for m in BITWISE_TEST_MODULES]

    def run_module(module: str, deterministic: bool, tmp: str) -> dict:
        left = deadline - time.time()
        if left < 5:
            return {"status": "not_run", "reason": "part budget spent"}
        env = dict(os.environ, MPM_WARP_TEST_DEVICE=device, MPM_WARP_TEST_DETERMINISTIC="1" if deterministic else "0")
        xml = os.path.join(tmp, module + ".xml")
        cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", f"--junitxml={xml}",
               os.path.join(ROOT, "tests", module + ".py")]
        t0 = time.time()
        rc, tail = _run_group(cmd, left - 2, env, cwd=ROOT)
        rec = {"seconds": time.time() - t0, "deterministic_atomics": deterministic, "exit_code": rc}
        if rc is None:
            return {**rec, "status": "timed_out", "output_tail": tail}
        if not os.path.exists(xml):
            return {**rec, "status": "error", "output_tail": tail}
        rec.update(_junit_counts(xml), status="passed" if rc == 0 else "failed")
        return {**rec, "output_tail": tail} if rc != 0 else rec

    workers = max(1, min(TEST_WORKERS, os.cpu_count() or 1, len(groups)))
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(workers) as pool:
        futures = {m: pool.submit(run_module, m, det, tmp) for m, det in groups}
        modules = {m: f.result() for m, f in futures.items()}
    counts = {k: sum(m.get(k, 0) for m in modules.values()) for k in ("tests", "failures", "errors", "skipped")}
    return {"device": device, "workers": workers, "modules": modules, **counts,
            "all_passed": all(m.get("status") == "passed" for m in modules.values())}


def _junit_counts(path: str) -> dict:
    root = ET.parse(path).getroot()
    suite = root if root.tag == "testsuite" else root.find("testsuite")
    failed = [f"{c.get('classname')}::{c.get('name')}" for c in suite.iter("testcase")
              if c.find("failure") is not None or c.find("error") is not None]
    return {"tests": int(suite.get("tests", 0)), "failures": int(suite.get("failures", 0)),
            "errors": int(suite.get("errors", 0)), "skipped": int(suite.get("skipped", 0)), "failed_tests": failed}


def part_graph(device: str, quick: bool, deadline: float, out_dir: str, deterministic: bool = False) -> dict:
    """Step the struck block eagerly and through captured graphs from the same state; compare and time."""
    import numpy as np
    import warp as wp

    if deterministic and _is_cuda(device):
        wp.config.deterministic = wp.DeterministicMode.RUN_TO_RUN  # before any kernel module exists

    from mpm_warp.studies import plastic_block as pb
    from mpm_warp.studies.blocks import block_simulation

    n_grid = 24 if quick else 64
    steps = 6 if quick else 200
    results = {}
    for use_graph in (False, True):
        sim = block_simulation(3, "plastic", n_grid, device, n_threads=1)
        sim.stepper.use_graph = use_graph
        sim.stepper.graph_batch = 4 if quick else 20
        st = sim.stepper
        st.set_frame_end(1e9)
        with _graph_stand_in(sim) if use_graph and not _is_cuda(device) else contextlib.nullcontext():
            st.steps(st.graph_batch)  # compile, capture
            wp.synchronize_device(sim.device)
            t0 = time.perf_counter()
            st.steps(steps)
            wp.synchronize_device(sim.device)
            sec = (time.perf_counter() - t0) / steps
        results[use_graph] = (sim, sec)
    (eager, t_e), (graph, t_g) = results[False], results[True]
    fields = {"x": (eager.state.x, graph.state.x), "v": (eager.state.v, graph.state.v),
              "H": (eager.state.H, graph.state.H), "log_jp": (eager.state.log_jp, graph.state.log_jp)}
    diffs = {k: float(np.abs(a.numpy().astype(np.float64) - b.numpy().astype(np.float64)).max())
             for k, (a, b) in fields.items()}
    obs_e = pb.observables(eager.state.elastic_deformation_gradient(), eager.state.log_jp.numpy())
    obs_g = pb.observables(graph.state.elastic_deformation_gradient(), graph.state.log_jp.numpy())
    out = {"device": device, "n_particles": eager.model.n_particles, "steps": steps + graph.stepper.graph_batch,
           "graph_batch": graph.stepper.graph_batch, "real_cuda_graph": _is_cuda(device),
           "deterministic_atomics": bool(deterministic and _is_cuda(device)),
           "eager_s_per_step": t_e, "graph_s_per_step": t_g, "graph_speedup": t_e / t_g if t_g > 0 else None,
           "max_abs_difference": diffs, "bit_for_bit": all(d == 0.0 for d in diffs.values()),
           "observables_eager": obs_e, "observables_graph": obs_g, "agreement": pb.agreement(obs_e, obs_g)}
    bitwise_expected = deterministic or not _is_cuda(device)
    out["expectation"] = "bit for bit" if bitwise_expected else f"observables within {pb.AGREEMENT:g}"
    out["ok"] = out["bit_for_bit"] if bitwise_expected else out["agreement"]["agree"]
    return out


class _graph_stand_in:
    """On the CPU, where Warp cannot capture, record the step batch a capture holds and replay it eagerly."""

    def __init__(self, sim):
        self.stepper = sim.stepper

    def __enter__(self):
        import warp as wp

        self._saved = (wp.ScopedCapture, wp.capture_launch)
        stepper = self.stepper
        real_step = stepper._launch_step

        class Capture:
            def __init__(self, device=None):
                self.graph = None

            def __enter__(self):
                self.n = 0

                def count():
                    self.n += 1

                stepper._launch_step = count
                return self

            def __exit__(self, *exc):
                stepper._launch_step = real_step
                self.graph = self.n
                return False

        def replay(graph):
            for _ in range(graph):
                real_step()

        wp.ScopedCapture, wp.capture_launch = Capture, replay
        return self

    def __exit__(self, *exc):
        import warp as wp

        wp.ScopedCapture, wp.capture_launch = self._saved
        return False


def part_memory(device: str, quick: bool, deadline: float, out_dir: str) -> dict:
    """Bytes per particle of the particle state and of the grid, elastic and Cam-Clay, 3D and 2D."""
    from mpm_warp.studies.device_memory import bytes_per_particle

    return bytes_per_particle(device, quick)


def part_field(device: str, quick: bool, deadline: float, out_dir: str) -> dict:
    """A small field batch: 16 made-up columns stepped together on the device, the first alone on one CPU core."""
    from mpm_warp.studies.field_columns import time_columns

    return time_columns(device, 2 if quick else 16, 1, deadline - 30.0, quick)


def part_throughput(device: str, quick: bool, deadline: float, out_dir: str) -> dict:
    """``throughput.run`` at 1M and 4M (quick: one tiny size), 2D and 3D, elastic and plastic, beside Taichi."""
    from mpm_warp.studies.perf import throughput

    name = f"device_suite_throughput_{_tag(device, quick)}"
    particles = list(QUICK_PARTICLES if quick else FULL_PARTICLES)
    out = throughput.run([3, 2], ["plastic", "elastic"], particles, steps=2 if quick else 50, device=device,
                         threads_list=[1], taichi=True, name=name, repeats=1 if quick else 3, results_dir=out_dir,
                         taichi_timeout_s=max(10.0, min(120.0, deadline - time.time())), size_major=True)
    return {"file": name + ".json", "rows": out["rows"], "seconds": out["seconds"]}


def run_pst_flat(device: str, quick: bool):
    """The production-resolution flat PST: the one place that knows how to run it.

    Today the ready scene ``pst_flat`` (``scenarios/pst_flat.toml``: dx = 1 cm, 0.35 s) through
    ``mpm_warp.run``; quick mode runs a 1 m column for 2 ms. Returns the ``RunResult``.
    """
    import mpm_warp

    overrides = ["scene.length=1.0", "time.end=0.002", "time.frame_interval=0.001"] if quick else None
    return mpm_warp.run("pst_flat", device=device, overrides=overrides)


def part_pst(device: str, quick: bool, deadline: float, out_dir: str) -> dict:
    """Run :func:`run_pst_flat` and record its cost and the scene's results (crack speed, ...)."""
    t0 = time.perf_counter()
    res = run_pst_flat(device, quick)
    total = time.perf_counter() - t0
    scene = {k: v for k, v in res.scene_result.items() if isinstance(v, (int, float, str, bool)) or v is None}
    return {"device": res.device, "n_particles": res.n_particles, "steps": res.steps, "sim_time_s": res.sim_time,
            "stepping_wall_s": res.wall_time, "total_wall_s": total, "particle_steps_per_s": res.particle_steps_per_s,
            "wall_s_per_simulated_s": res.wall_time / res.sim_time if res.sim_time > 0 else None,
            "edge_hits": res.edge_hits, "scene_result": scene}


PART_FUNCS = {"tests": part_tests, "graph": part_graph,
              "graph_deterministic": lambda *a: part_graph(*a, deterministic=True),
              "memory": part_memory, "throughput": part_throughput, "pst": part_pst, "field": part_field}


# ----------------------------------------------------------------------------------------- driver
def _run_group(cmd, timeout: float, env=None, cwd=None) -> tuple[int | None, str]:
    """Run ``cmd`` in its own process group; kill that group past ``timeout``. Returns (exit code or None, tail)."""
    with tempfile.TemporaryFile(mode="w+") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env, cwd=cwd, start_new_session=True)
        try:
            rc = proc.wait(timeout=max(timeout, 1.0))
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            rc = None
        log.seek(0)
        return rc, log.read()[-4000:]


def run_suite(device: str, quick: bool, out_dir: str, parts=PARTS) -> dict:
    """Run the parts, each in its own interpreter under its budget; write and return the suite's JSON."""
    from mpm_warp.studies.environment import environment, write_json

    out = {"suite": "mpm_warp device suite", "mode": "quick" if quick else "full", "environment": environment(device),
           "budget_s": {p: BUDGETS[p][1 if quick else 0] for p in parts}, "parts": {}}
    out["budget_s_total"] = sum(out["budget_s"].values())
    t_start = time.time()
    for part in parts:
        budget = BUDGETS[part][1 if quick else 0]
        with tempfile.TemporaryDirectory() as tmp:
            result_path = os.path.join(tmp, "part.json")
            cmd = [sys.executable, os.path.abspath(__file__), "--device", device, "--out", out_dir, "--run-part", part,
                   "--part-result", result_path, "--deadline", str(time.time() + budget)]
            if quick:
                cmd.append("--quick")
            t0 = time.time()
            rc, tail = _run_group(cmd, budget, cwd=ROOT)
            rec = {"seconds": time.time() - t0, "budget_s": budget}
            if rc is None:
                rec["status"] = "timed_out"
            elif rc != 0 or not os.path.exists(result_path):
                rec["status"] = "error"
            else:
                rec["status"] = "ok"
            if os.path.exists(result_path):
                with open(result_path) as fh:
                    rec["result"] = json.load(fh)
            if rec["status"] != "ok":
                rec["output_tail"] = tail
        out["parts"][part] = rec
        print(f"{part:20s} {rec['status']:9s} {rec['seconds']:7.1f} s of {budget} s", flush=True)
    out["total_seconds"] = time.time() - t_start
    path = write_json(f"device_suite_{_tag(device, quick)}", out, out_dir)
    print("wrote", path, flush=True)
    return out


def plan(quick: bool) -> dict:
    """What a run of this mode does: its parts, their budgets (s) and the test modules of the ``tests`` part."""
    mode = 1 if quick else 0
    modules = list(QUICK_TEST_MODULES) if quick else list(TEST_MODULES) + list(BITWISE_TEST_MODULES)
    return {"mode": "quick" if quick else "full", "parts": list(PARTS),
            "budget_s": {p: BUDGETS[p][mode] for p in PARTS}, "budget_s_total": sum(b[mode] for b in BUDGETS.values()),
            "test_modules": modules}


def _default_device() -> str:
    import warp as wp

    return "cuda:0" if wp.get_cuda_device_count() > 0 else "cpu"


def main(argv=None) -> int:
    # the options of mpm_warp.studies.protocol, spelled out here: importing mpm_warp before the graph_deterministic
    # part sets Warp's deterministic atomics would create kernel modules with the default mode
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--device", default=None, help="Warp device (default cuda:0 when present, else cpu)")
    ap.add_argument("--quick", action="store_true",
                    help="tiny sizes, few steps: seconds per part, on the CPU as in CI; writes to a temporary folder "
                         "unless --out")
    ap.add_argument("--out", default=None, metavar="DIR",
                    help="folder of the JSON results (default benchmarks/perf/results; --quick: a temporary folder)")
    ap.add_argument("--parts", nargs="+", default=list(PARTS), choices=PARTS)
    ap.add_argument("--plan", action="store_true",
                    help="print the parts, their budgets (s) and test modules of this mode as JSON, run nothing")
    ap.add_argument("--run-part", default=None, choices=PARTS, help=argparse.SUPPRESS)
    ap.add_argument("--part-result", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--deadline", type=float, default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.plan:
        print(json.dumps(plan(a.quick)))
        return 0
    device = a.device or _default_device()
    if a.run_part:
        deadline = a.deadline or time.time() + BUDGETS[a.run_part][1 if a.quick else 0]
        res = PART_FUNCS[a.run_part](device, a.quick, deadline, a.out)
        with open(a.part_result, "w") as fh:
            json.dump(res, fh, indent=1, default=float)
        return 0
    from mpm_warp.studies.protocol import out_dir

    out = run_suite(device, a.quick, out_dir(a, RESULTS, "device_suite"), a.parts)
    return 0 if all(p["status"] == "ok" for p in out["parts"].values()) else 1


if __name__ == "__main__":
    sys.exit(main())
