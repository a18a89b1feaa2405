"""Section of the CPU step's scaling over threads: the PST beside the elastic block, rates and cost breakdown."""

from __future__ import annotations

from .core import section
from .fmt import count, env_note, fx, pct, secs, table

M = 1e-6      # particle-steps per second -> millions
MS = 1e3      # seconds -> milliseconds
SCENES = (("pst_demo", "PST (pst_demo)"), ("elastic_block", "elastic block"))


def _rates(entry: dict) -> list[list[str]]:
    rows = []
    for nt, row in entry["threads"].items():
        r = row["rates"]
        rows.append([nt, fx(r["pst_demo"]["particle_steps_per_s"], 2, M),
                     fx(r["elastic_block"]["particle_steps_per_s"], 2, M), fx(row["pst_over_block"], 3)])
    return rows


def _breakdown(entry: dict) -> list[list[str]]:
    rows = []
    for nt, row in entry["threads"].items():
        for key, name in SCENES:
            b = row["breakdown"][key]
            cells = [nt, name, fx(b["total"], 3, MS), fx(b["serial"], 3, MS)]
            for stage in ("p2g", "grid", "g2p"):
                s = b[stage]
                cells.append(f"{fx(s['wall'], 3, MS)} ({' / '.join(fx(x, 3, MS) for x in s['busy'])})")
            cells.append(pct((b["total"] - sum(max(b[s]["busy"]) for s in ("p2g", "grid", "g2p")) - b["serial"])
                             / b["total"], 0))
            rows.append(cells)
    return rows


@section("perf", "The PST step across threads, beside the elastic block", "perf/results/pst_scaling_cpu.json",
         lambda d: f"python benchmarks/perf/pst_scaling.py --label '{list(d['runs'])[-1]}' --repeats "
                   f"{list(d['runs'].values())[-1]['repeats']}",
         question="Does the PST's step scale from one thread to two like an elastic step, and where does its time go?")
def render_pst_scaling(data: dict, ctx) -> list[str]:
    out = []
    for label, entry in data["runs"].items():
        commit = (entry.get("environment") or {}).get("git_commit") or "?"
        parts = entry["threads"]["1"]["breakdown"]
        out += [f"**{label}** ({commit[:7]}): particle-steps per wall second through `mw.run` over the first "
                f"{fx(entry['window_s'], 2)} s (median of {entry['repeats']}, the two scenes in turns); "
                f"pst_demo {count(parts['pst_demo']['particles'])} particles, the block "
                f"{count(parts['elastic_block']['particles'])}.", ""]
        out += table(["threads", "PST (M/s)", "elastic block (M/s)", "PST / block"], _rates(entry))
        out += ["", "Per step (ms): the serial launches on thread 0 and, per parallel stage, its wall time with each "
                "thread's own work in brackets; the last column is the share of the step spent waiting at the "
                "threads' meetings (wall time neither thread spends in a launch).", ""]
        out += table(["threads", "scene", "step", "serial", "P2G", "grid update", "G2P", "waiting"],
                     _breakdown(entry), ["r", "l", "r", "r", "r", "r", "r", "r"])
        one, two = (entry["threads"][k]["breakdown"] for k in ("1", "2"))
        share = {key: max(two[key]["p2g"]["busy"]) / (0.5 * one[key]["p2g"]["busy"][0]) for key, _ in SCENES}
        slower = max(share.values()) > 1.05
        out += ["", f"At two threads each thread's own P2G takes {fx(share['pst_demo'], 2)}x (PST) and "
                f"{fx(share['elastic_block'], 2)}x (block) half the one-thread P2G: "
                + ("a thread's launches run slower beside another's (which shared resource slows them is not "
                   "measured)." if slower else "each thread's launches run about as fast as alone.")
                + " One profile of 200 steps per scene and thread count, after the rates."]
        ab = entry["threads"]["2"].get("meeting_ab")
        if ab:
            out += ["", "The meeting point against `threading.Barrier` in the same stepper at two threads, "
                    f"{len(ab['pst_demo']['times']['meeting_point'])} batches of each in turns: "
                    + "; ".join(f"{name} {fx(ab[key]['meeting_over_barrier'], 3)}x the step time"
                                for key, name in SCENES) + "."]
        out += ["", env_note(entry), ""]
    return out[:-1]


@section("perf", "`pst_flat` from its own command", "perf/results/pst_flat_wall_cpu.json",
         "python benchmarks/perf/pst_flat_wall.py",
         question="How long does the 8 m flat PST take on this 2-core CPU, and how fast was the machine that day?")
def render_pst_flat_wall(data: dict, ctx) -> list[str]:
    s = data["summary"]
    work = s["n_particles"] * s["steps"]
    block = 0.5 * (data["block_rate_before"] + data["block_rate_after"])
    out = table(["command", "wall time", "particles", "steps", "stepping (M particle-steps/s)",
                 "elastic block before / after (M/s)"],
                [[f"`{data['command']}`", secs(data["wall_s"]), count(s["n_particles"]), count(s["steps"]),
                  fx(s["particle_steps_per_s"], 2, M),
                  f"{fx(data['block_rate_before'], 2, M)} / {fx(data['block_rate_after'], 2, M)}"]])
    out += ["", env_note(data), "",
            f"- {fx(data['wall_s'] / 60, 1)} min, after a short run of the scene compiled its kernels; the command "
            f"ran on {data['threads']} threads, {fx(s['particle_steps_per_s'] / block, 2)}x the elastic block's "
            f"rate (mean of before and after). Its {fx(work / 1e9, 1)} G particle-steps in 15 min take "
            f"{fx(work / 900, 1, M)} M particle-steps/s: at that ratio, any day on which the block runs at "
            f"{fx(work / 900 / (s['particle_steps_per_s'] / block), 1, M)} M/s or more.",
            "- The elastic block (82,944 particles, 2 threads, 200 steps) was timed just before and just after the "
            "run: this shared machine's speed on the day, against which a run on another day can be scaled."]
    return out
