"""Sections of the performance results: throughput beside Taichi, the plastic step, leave-out, plane strain,
the return costs, the eigen-decomposition's cost, and the CUDA results still to come."""

from __future__ import annotations

import os
from collections.abc import Sequence

from .core import pending, section
from .fmt import check_line, count, env_note, finite, fx, pct, ratio_range, secs, table

M = 1e-6   # particle-steps per second -> millions
#: the 2D elastic step's throughput against Taichi's that a field season needs (its share of a field case's cost)
ELASTIC_2D_TARGET = 1.2


def _stem(source: str) -> str:
    return os.path.splitext(os.path.basename(source))[0]


def _device_flag(data: dict) -> str:
    dev = (data.get("environment") or {}).get("device") or "cpu"
    return "" if dev == "cpu" else f" --device {dev}"


def _uniq(values) -> list:
    return sorted({v for v in values})


# ----------------------------------------------------------------------------- throughput
def _throughput_command(source: str):
    def command(data: dict) -> str:
        rows = [r for r in data["rows"] if r["engine"] == "mpm_warp"]
        dev = (data.get("environment") or {}).get("device") or "cpu"
        name = "" if _stem(source) == f"throughput_{dev.split(':')[0]}" else f" --name {_stem(source)}"
        return ("python benchmarks/perf/throughput.py" + _device_flag(data)
                + " --dims " + " ".join(str(d) for d in _uniq(r["dim"] for r in rows))
                + " --particles " + " ".join(str(n) for n in _uniq(r["n_particles"] for r in rows))
                + " --threads " + " ".join(str(t) for t in _uniq(r["threads"] for r in rows)) + name)
    return command


def _stages(row: dict) -> str:
    st = row.get("stages_s")
    if not st:
        return "-"
    return " / ".join(fx(st.get(k), 2, 1e3) for k in ("p2g", "grid_update", "g2p"))


def throughput_rows(data: dict) -> list[tuple[dict, dict | None]]:
    """``(mpm_warp row, Taichi row or None)`` of each configuration, by dimension, material, threads and size."""
    peers = {(r["dim"], r["material"], r["n_particles"], r["threads"]): r
             for r in data["rows"] if r["engine"] == "taichi"}
    mine = [r for r in data["rows"] if r["engine"] == "mpm_warp"]
    mine.sort(key=lambda r: (-r["dim"], r["material"], r["threads"], r["n_particles"]))
    return [(r, peers.get((r["dim"], r["material"], r["n_particles"], r["threads"]))) for r in mine]


def render_throughput(data: dict, ctx) -> list[str]:
    pairs = throughput_rows(data)
    rows = []
    for r, t in pairs:
        rows.append([r["dim"], r["material"], count(r["n_particles"]), r["threads"],
                     fx(r.get("particle_steps_per_cpu_s"), 2, M), fx((t or {}).get("particle_steps_per_cpu_s"), 2, M),
                     fx(r.get("ratio_vs_taichi_cpu_time"), 2), fx(r.get("ratio_vs_taichi"), 2),
                     f"{fx(r.get('cpu_utilisation'), 2)} / {fx((t or {}).get('cpu_utilisation'), 2)}",
                     _stages(r), f"{fx(r.get('bytes_per_particle'), 0)} + {fx(r.get('grid_bytes_per_particle'), 1)}"])
    out = table(["dim", "material", "particles", "threads", "mpm_warp (M/CPU-s)", "Taichi (M/CPU-s)",
                 "ratio (CPU time)", "ratio (wall)", "CPU use mpm_warp / Taichi", "P2G / grid / G2P (ms)",
                 "bytes per particle (+ grid)"], rows, ["r", "l", "r", "r", "r", "r", "r", "r", "r", "r", "r"])
    out += ["", env_note(data), ""]
    out += [f"Both engines run the same block ({data.get('steps', '-')} steps, median of {data.get('repeats', '-')} "
            "repeats from one warmed-up snapshot, kernels compiled first; Taichi in its own process per "
            "configuration). "
            "Rates are particle-steps per second of process CPU time (`particle_steps_per_cpu_s`): on a shared CPU "
            "the wall-clock rates move with the other work's load; both are in the JSON. Stage times are mpm_warp's "
            "P2G, grid update and G2P (one thread, CPU time per step); bytes are mpm_warp's particle state and "
            "its dense grid per particle.", ""]
    for dim in _uniq(r["dim"] for r, _ in pairs)[::-1]:
        parts = []
        for mat in _uniq(r["material"] for r, _ in pairs if r["dim"] == dim):
            v = [r.get("ratio_vs_taichi_cpu_time") for r, _ in pairs
                 if r["dim"] == dim and r["material"] == mat and r["threads"] == 1]
            if any(finite(x) for x in v):
                parts.append(f"{mat} {ratio_range(v, 2)}x")
        if parts:
            out.append(f"- {dim}D, one thread: mpm_warp against Taichi in particle-steps per CPU second, "
                       + ", ".join(parts) + ".")
    el2 = [r for r, _ in pairs if r["dim"] == 2 and r["material"] == "elastic" and r["threads"] == 1]
    if el2:
        wall = [r.get("ratio_vs_taichi") for r in el2]
        cpu = [r.get("ratio_vs_taichi_cpu_time") for r in el2]
        ok = all(finite(x) and x >= ELASTIC_2D_TARGET for x in wall)
        out.append(check_line("the 2D elastic step against Taichi",
                              f"at least {ELASTIC_2D_TARGET:g}x Taichi's particle-steps per second at every size, "
                              "one thread", ok, f"{ratio_range(wall, 2)}x wall clock, {ratio_range(cpu, 2)}x "
                              "CPU time"))
    multi = [(r, t) for r, t in pairs if r["threads"] > 1]
    if multi:
        out.append(f"- With {ratio_range([r['threads'] for r, _ in multi], 0)} threads mpm_warp used "
                   f"{ratio_range([r.get('cpu_utilisation') for r, _ in multi], 2)} of its threads' CPU time: "
                   "on this shared machine those rows say little about scaling.")
    return out


for _src, _title in (("perf/results/throughput_cpu.json", "Throughput beside Taichi, 3D"),
                     ("perf/results/throughput_2d_cpu.json", "Throughput beside Taichi, 2D")):
    section("perf", _title, _src, _throughput_command(_src), figure=_src.replace(".json", ".png"),
            question="How many particle-steps per second, by dimension, material, size and threads, beside Taichi?"
            )(render_throughput)


# ----------------------------------------------------------------------------- the plastic step
def _min_kind(row: dict, kind: str):
    kinds = row.get("return_kinds") or []
    v = [k[kind] for k in kinds if finite(k.get(kind))]
    return min(v) if v else None


def _plastic_command(data: dict) -> str:
    g3 = _uniq(r["n_grid"] for r in data["rows"] if r["dim"] == 3)
    g2 = _uniq(r["n_grid"] for r in data["rows"] if r["dim"] == 2)
    threads = _uniq(r["threads"] for r in data["rows"])
    return ("python benchmarks/perf/plastic_step.py" + _device_flag(data) + " --n-grid " + " ".join(map(str, g3))
            + " --n-grid-2d " + " ".join(map(str, g2)) + f" --steps {data.get('steps')}"
            + " --threads " + " ".join(map(str, threads)))


@section("perf", "The plastic step beside Taichi", "perf/results/plastic_step_cpu.json", _plastic_command,
         question="What does the plastic step cost beside Taichi, and where does its time go?")
def render_plastic_step(data: dict, ctx) -> list[str]:
    mat = (data.get("scene") or {}).get("material") or {}
    rows, parts = [], []
    tol = (data["rows"][0].get("agreement") or {}).get("tolerance") if data["rows"] else None
    for r in sorted(data["rows"], key=lambda r: (-r["dim"], r["n_particles"])):
        w, t = r["mpm_warp"], r["taichi"]
        agree = (r.get("agreement") or {}).get("scaled_differences") or {}
        rows.append([r["dim"], count(r["n_particles"]), fx(w.get("particle_steps_per_cpu_s"), 2, M),
                     fx(t.get("particle_steps_per_cpu_s"), 2, M), fx(r.get("ratio_vs_taichi_cpu_time"), 2),
                     fx(r.get("ratio_vs_taichi"), 2), pct(_min_kind(w, "yielded"), 0), pct(_min_kind(w, "cap"), 0),
                     pct(_min_kind(w, "dry"), 0), f"{max(agree.values()):.1e}" if agree else "-"])
        up = w.get("update_parts_s_per_step") or {}
        parts.append([r["dim"], count(r["n_particles"]), fx(w.get("cpu_s_per_step"), 2, 1e3), _stages(w),
                      fx(w.get("no_plasticity_cpu_s_per_step"), 2, 1e3), fx(up.get("update_s"), 2, 1e3),
                      fx(up.get("return_s"), 2, 1e3), fx(up.get("series_check_s"), 2, 1e3),
                      fx(up.get("principal_path_update_s"), 2, 1e3), fx(up.get("principal_s"), 2, 1e3),
                      fx(t.get("cpu_s_per_step"), 2, 1e3), pct(t.get("return_share"), 0)])
    out = [f"A block of PST weak-layer snow (E {fx(mat.get('E'), 1, 1e-6)} MPa, nu {fx(mat.get('nu'), 2)}, "
           f"rho {fx(mat.get('density'), 0)} kg/m^3, M {fx(mat.get('M'), 2)}, beta {fx(mat.get('beta'), 2)}, "
           f"xi {fx(mat.get('xi'), 4)}, p0_ini {fx(mat.get('p0_ini'), 1, 1e-3)} kPa) struck at "
           f"{fx((data.get('scene') or {}).get('impact_speed'), 0)} m/s: one half compacted and sheared (cap "
           "returns), the other pulled apart and sheared (dry-side returns). Every timed step is checked in both "
           "engines; the agreement is the largest difference of mean p, q, log_Jp and |dlog_Jp| after the same "
           "steps, scaled by each one's size"
           + (f" (tolerance {tol:g})" if finite(tol) else "") + ".", ""]
    out += table(["dim", "particles", "mpm_warp (M/CPU-s)", "Taichi (M/CPU-s)", "ratio (CPU time)", "ratio (wall)",
                  "yielding (min)", "cap (min)", "dry side (min)", "agreement"], rows)
    out += ["", env_note(data), ""]
    out += ["Where the time goes (CPU ms per step; the update's parts are the engine's own functions run on the "
            "step's trial states, `benchmarks/perf/return_cost.py`): the whole step, its stages, the step with "
            "plasticity compiled out, the constitutive update, its Cam-Clay return and small-strain series check, "
            "the same update with an eigen-decomposition of every yielding trial and that decomposition alone; "
            "Taichi's step and its return's share.", ""]
    out += table(["dim", "particles", "step", "P2G / grid / G2P", "no plasticity", "update", "return",
                  "series check", "update with decomposition", "decomposition", "Taichi step", "Taichi return"], parts)
    dev = [r["mpm_warp"].get("update_parts_s_per_step", {}).get("engine_vs_principal_path") for r in data["rows"]]
    dev = [d for d in dev if d]
    out += [""]
    if dev:
        out += ["The series update against the update with the decomposition, largest difference over the sizes: "
                f"H {max(d['H'] for d in dev):.1e}, tau {max(d['tau_Pa'] for d in dev):.1e} Pa, "
                f"log_Jp {max(d['log_jp'] for d in dev):.1e}.", ""]
    med = data.get("median_ratio_vs_taichi_cpu_time") or {}
    if med:
        out.append("Median ratio in CPU time: " + ", ".join(f"{k.upper()} {fx(v, 2)}x" for k, v in sorted(med.items()))
                   + ".")
    return out


# ----------------------------------------------------------------------------- leave-out
_CASES = {"elastic_no_walls": "elastic, no walls", "elastic_box_walls": "elastic, six box walls",
          "camclay_elastic_range_box_walls": "Cam-Clay inside its yield surface, walls",
          "camclay_yielding_box_walls": "Cam-Clay yielding, walls"}


@section("perf", "What a scene does not need costs nothing", "perf/results/leave_out_cpu.json",
         lambda d: f"python benchmarks/perf/leave_out.py --n-grid {d.get('n_grid')} --threads {d.get('threads')}",
         question="Do walls and plasticity cost nothing when a scene does not use them?")
def render_leave_out(data: dict, ctx) -> list[str]:
    rows = [[_CASES.get(k, k), count(c.get("n_particles")), c.get("walls"), fx(c.get("particle_steps_per_s"), 2, M),
             fx(c.get("time_vs_elastic_no_walls"), 3), fx(c.get("bytes_per_particle"), 0),
             pct(c.get("fraction_with_plastic_history"), 0)] for k, c in data["cases"].items()]
    out = table(["case", "particles", "walls", "M particle-steps/s", "time against elastic without walls",
                 "bytes per particle", "with plastic history"], rows)
    n = len(next(iter(data["cases"].values()))["times"])
    return out + ["", env_note(data), "", f"Threads: {data.get('threads')}; the median of {n} repeats (wall time). "
                  "An elastic-only scene compiles and launches no return."]


# ----------------------------------------------------------------------------- plane strain
@section("perf", "Plane-strain PST: 2D against the quasi-2D slab", "perf/results/pst_plane_strain_cpu.json",
         lambda d: f"MPM_WARP_THREADS={d.get('threads')} python benchmarks/perf/pst_plane_strain.py"
                   f" --window {d.get('window_s')} --repeats {d.get('repeats')}",
         question="What does a PST cost in true 2D against the quasi-2D slab?")
def render_plane_strain(data: dict, ctx) -> list[str]:
    rows = [[m["mode"], m["dimension"], count(m["particles"]), count(m["steps"]),
             fx(m["cpu_s_per_simulated_s"], 0), fx(m["wall_s_per_simulated_s"], 0),
             fx(m["particle_steps_per_cpu_s"], 2, M), secs(m.get("settle_wall_s"))] for m in data["modes"].values()]
    out = [f"{data.get('what', '')}. Timed: {fx(data.get('window_s'), 2)} s of simulated time after settling, "
           f"median of {data.get('repeats')}.", ""]
    out += table(["mode", "dimension", "particles", "steps", "CPU s per simulated s", "wall s per simulated s",
                  "M particle-steps per CPU s", "settling (wall)"], rows, ["l", "r", "r", "r", "r", "r", "r", "r"])
    r = data.get("slab_over_2d") or {}
    out += ["", env_note(data), "",
            f"The slab costs {fx(r.get('cpu_s_per_simulated_s'), 1)}x the CPU time of true 2D per simulated second "
            f"({fx(r.get('wall_s_per_simulated_s'), 1)}x in wall time, which moves with the shared machine's load)."]
    return out


# ----------------------------------------------------------------------------- return costs
@section("perf", "The bonded return against plain Cam-Clay", "perf/results/bonded_return_cost_cpu.json",
         lambda d: "python benchmarks/perf/bonded_return_cost.py" + _device_flag(d)
                   + f" --n {d['rows'][0]['n']} --precision {d.get('precision')}",
         question="What does the bonded (weak-layer) return cost against plain Cam-Clay, per point?")
def render_bonded_return(data: dict, ctx) -> list[str]:
    rows = [[r["set"], count(r["n"]),
             f"{pct(r['yielded_fraction_bonded'], 0)} / {pct(r['yielded_fraction_camclay'], 0)}",
             fx(r["bonded_ns_per_point"], 1), fx(r["camclay_ns_per_point"], 1), fx(r["ratio"], 2)]
            for r in data["rows"]]
    out = table(["trial states", "points", "yielding (bonded / Cam-Clay)", "bonded (ns/point)",
                 "Cam-Clay (ns/point)", "bonded / Cam-Clay"], rows)
    return out + ["", env_note(data), "", f"{data.get('precision')}, one launch over all points: the median of "
                  f"{len(data['rows'][0]['bonded_times_s'])} launches after a compiling one."]


pending("perf", "The Cam-Clay update and its parts", "perf/results/return_cost_cpu.json",
        "python benchmarks/perf/return_cost.py",
        question="How long do the Cam-Clay update and its parts take on a real step's trial states? "
                 "(The plastic step's JSON holds the same parts, above.)")


def _eig_cols(e: dict) -> Sequence[str]:
    return [fx(e["ns_per_matrix"], 0), fx(e["max_offdiag_u"], 1), fx(e["p99_offdiag_u"], 1),
            fx(e["max_nonorthogonality_u"], 1)]


@section("perf", "The eigen-decomposition: Jacobi against eig3", "perf/results/eig3_cost_cpu.json",
         lambda d: "python benchmarks/perf/eig3_cost.py" + _device_flag(d) + f" --n {d['rows'][0]['n']}",
         question="What does the large-strain return's Jacobi eigen-decomposition cost against Warp's eig3, "
                  "and how accurate is each?")
def render_eig3(data: dict, ctx) -> list[str]:
    rows = [[r["precision"], count(r["n"]), *_eig_cols(r["jacobi"]), *_eig_cols(r["eig3"]),
             fx(r["jacobi_over_eig3_time"], 2)] for r in data["rows"]]
    out = table(["precision", "matrices", "Jacobi (ns)", "Jacobi max off-diagonal (u)", "Jacobi p99 (u)",
                 "Jacobi non-orthogonality (u)", "eig3 (ns)", "eig3 max off-diagonal (u)", "eig3 p99 (u)",
                 "eig3 non-orthogonality (u)", "Jacobi / eig3 time"], rows)
    return out + ["", env_note(data), "", f"Median of {len(data['rows'][0]['jacobi']['times_s'])} launches of each, "
                  "timed alternately after a compiling one. Residuals in units of the precision's round-off (u): "
                  "the largest and the 99th-percentile off-diagonal of V^T A V, and the largest departure of V from "
                  "orthogonality."]


@section("perf", "CUDA: every kernel compiled to PTX", "perf/results/cuda_ptx.json",
         "python tests/helpers_cuda_compile.py --work /tmp/ptx --record benchmarks/perf/results/cuda_ptx.json",
         question="Do the kernels of the ready scenes compile for CUDA without a GPU?")
def render_cuda_ptx(data: dict, ctx) -> list[str]:
    archs = data["archs"]
    out = [f"{count(data['n_cases'])} cases (every ready scene and the material-point driver, float32 and float64, 2D "
           f"and 3D where the scene allows, each run a few steps on the CPU) load {count(data['n_modules'])} kernel "
           f"modules; each compiles to PTX for {', '.join(archs)} (NVRTC -O{data['nvrtc_optimization_level']}), "
           f"with no GPU and no driver: `tests/test_cuda_compile.py` does it in CI and fails naming the kernel. "
           f"{data.get('arch_note', '')[:1].upper()}{data.get('arch_note', '')[1:]}.", ""]
    rows = [["all modules", *(fx(data["total_ptx_bytes"][a], 2, 1e-6) for a in archs)]]
    fam = data.get("largest_per_kernel_family") or {}
    for name in sorted(fam, key=lambda k: -fam[k][archs[-1]])[:8]:
        rows.append([f"largest `{name}`", *(fx(fam[name][a], 3, 1e-6) for a in archs)])
    out += table(["PTX (MB)", *archs], rows)
    return out + ["", env_note(data), "", "A record to watch: a kernel whose PTX grows by much has gained code on "
                  "every GPU."]
