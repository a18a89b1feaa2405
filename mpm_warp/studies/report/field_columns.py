"""Section of field cases per hour: each case alone against many columns stepped together, on the CPU and a GPU."""

from __future__ import annotations

from .core import section
from .fmt import check_line, env_note, fx, table

#: the GPU's file beside the CPU's, rendered in the same table when committed
CUDA = "field/results/field_columns_cuda.json"


def _work_ratio(d: dict) -> float:
    """Particle-steps of the cases run together over those of the same cases alone (-)."""
    ok = [r for r in d["rows"] if r["status"] == ["ok", "ok"]]
    return sum(r["particles"] * r["steps"][1] for r in ok) / sum(r["particles"] * r["steps"][0] for r in ok)


def _rows(d: dict) -> list[list]:
    dev = d["environment"].get("device_name") or d["device"]
    w = d["workers"]
    return [[f"{d['device']} ({dev})", "alone", f"{w} x 1", fx(d["alone"]["wall_s"], 0),
             fx(d["alone"]["cases_per_hour"], 0), "1.00"],
            [f"{d['device']} ({dev})", f"{d['columns']} together", f"{w} x 1", fx(d["together"]["wall_s"], 0),
             fx(d["together"]["cases_per_hour"], 0), fx(d["speedup"], 2)]]


@section("field", "Field cases per hour: each alone, or many columns stepped together",
         "field/results/field_columns_cpu.json",
         lambda d: (f"python benchmarks/field/columns.py DIR --limit {d['draw']['limit']} --columns {d['columns']} "
                    f"--workers {d['workers']}"),
         question="How many field cases an hour on 2 CPU cores and on one GPU, each case alone or many columns "
                  "stepped together with one step size, and does each case keep its class and runaway cut?")
def render_columns(data: dict, ctx) -> list[str]:
    runs = [data] + ([ctx.load(CUDA)] if ctx.exists(CUDA) else [])
    ag = data["agreement"]
    out = [f"The first {data['draw']['limit']} cases of the development set's stratified draw (seed "
           f"{data['draw']['seed']}; {data['cases']} of them set up by the protocol), each run twice by the "
           "field protocol into a fresh folder: alone, then in groups stepped together (`mpm-warp field "
           "--columns N`), kernels compiled beforehand by a first case. Wall times are the whole batch's, set-up "
           "and Dask included.", ""]
    out += table(["device", "cases", "workers x threads", "wall (s)", "cases per hour", "against alone"],
                 [r for d in runs for r in _rows(d)], ["l", "l", "l", "r", "r", "r"])
    out += ["", f"- Both ways ran {ag['both_ok']} of the {data['cases']} cases; {ag['same_class']} kept their "
            f"class and {ag['same_runaway_cut_1cm']} their runaway cut within 1 cm.",
            f"- The shared step cost a column {fx(ag['shared_step_cost_median'], 2)} times its own steps at the "
            f"median and {fx(ag['shared_step_cost_max'], 2)} at most (its own elastic step over its group's "
            "least; docs/architecture.md, \"Columns stepped together\"): the groups took "
            f"{fx(_work_ratio(data), 2)} times the particle-steps of the cases alone.",
            "- On the CPU a group runs its columns one after another on one thread, so it saves nothing there: it "
            "pays the shared step's extra steps, and its slowest group ends the batch. Groups are for a GPU, which "
            "one column leaves idle.", ""]
    if not ctx.exists(CUDA):
        out += ["No GPU run is committed yet: `bash benchmarks/device_suite.sh` runs a small field batch on one "
                "(its `field` part), and `python benchmarks/field/columns.py DIR --device cuda --columns 64` this "
                "draw.", ""]
    out += [check_line("columns stepped together keep each case's class", "every case that ran both ways",
                       ag["same_class"] == ag["both_ok"], f"{ag['same_class']} of {ag['both_ok']}"), "",
            env_note(data)]
    return out
