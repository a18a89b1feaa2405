"""``mpm-warp field``: run every PST of real pits (CAAML folders, CSV tables) on Dask and score them."""

from __future__ import annotations

import sys

__all__ = ["add_field"]

DESCRIPTION = (
    "Run every PST record of real snow pits as the field runs it (the saw stops once the crack runs away) and "
    "measure the predicted outcome (END, SF, ARR) against what the observer wrote. INPUT: folders of CAAML "
    "files, CAAML files, or CSV tables of PSTs (columns: id, outcome, slope_deg, column_cm, cut_cm, slab_cm and "
    "slab_density or layers, weak_layer_cm, optional weak_layer_density, w_f, column_ends; docs/field.md). "
    "Each case is a Dask task on a local cluster (--workers) or an existing one (--scheduler); a killed batch "
    "resumes where it stopped. Writes the runs, cases.csv, refused.csv, scores.json and confusion.png to --out; "
    "every refused record is also one line on the terminal, and Dask's logs go to dask.log there (--verbose: to the "
    "terminal).")
EXAMPLE = "example: mpm-warp field pits/ --out field-run --workers 2"
#: columns stepped together on a GPU unless --columns says otherwise: one field column leaves a GPU idle
GPU_COLUMNS = 64


def cmd_field(a) -> int:
    """Exit status 0 when every case ran (refusals are not failures), 1 when some failed."""
    from .field.batch import run_field
    from .field.protocol import FieldProtocol

    on_gpu = str(a.device).startswith("cuda")
    columns = a.columns if a.columns is not None else (GPU_COLUMNS if on_gpu else 1)
    workers = a.workers if a.workers is not None or not on_gpu else 1
    res = run_field(a.inputs, a.out, workers=workers, scheduler=a.scheduler, device=a.device, limit=a.limit,
                    protocol=FieldProtocol(max_particles=a.max_particles, threads=a.threads,
                                           rigid_base=not a.elastic_substratum, pre_cut_share=a.pre_cut_share,
                                           interface_closure=a.interface_closure, columns=columns),
                    progress=not a.quiet, verbose=a.verbose, calibration=a.calibration)
    sc = res.scores
    for r in res.refused:
        print(f"refused {r.line()}", file=sys.stderr)

    def ba(k):
        v = sc[k]["balanced_accuracy"]
        return "-" if v is None else f"{v:.3f}"

    def skill(k):
        v = sc.get("forecast", {}).get(k, {}).get("rpss")
        return "-" if v is None else f"{v:+.3f}"

    print(f"field: {sc['cases']} cases scored ({res.skipped} from an earlier batch), {sc['failed']} failed, "
          f"{len(res.refused)} records refused (refused.csv)\nbalanced accuracy: model {ba('model')}, majority "
          f"class {ba('majority')}, weac static {ba('weac_static')}\nranked probability skill against the cases' "
          f"climatology: model {skill('model')}, its readings calibrated {skill('calibrated')}, information bar "
          f"{skill('information_bar')}" + (f", calibration file {skill('calibrated_from_file')}" if a.calibration
                                           else "") + f" (scores.json)\nresults: {res.out_dir}")
    for r in res.records:
        if r.get("status") != "ok":
            print(f"failed {r['id']}: {r.get('error')}", file=sys.stderr)
    return 1 if sc["failed"] else 0


def add_field(sub) -> None:
    """The ``field`` subcommand on the CLI's subparsers ``sub``."""
    from .field.protocol import FieldProtocol

    p = sub.add_parser("field", help="run real pits' PSTs in bulk on Dask and score END/SF/ARR against the field",
                       description=DESCRIPTION, epilog=EXAMPLE)
    p.add_argument("inputs", nargs="+", metavar="INPUT", help="folder of CAAML files, a CAAML file, or a CSV table")
    p.add_argument("--out", required=True, help="folder of the runs and results (an earlier batch's cases are kept)")
    p.add_argument("--workers", type=int, help="workers of the local cluster (default: the cores over --threads; "
                   "1 on a GPU)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="existing Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--device", default="cpu", help="cpu | cuda | cuda:N (default cpu)")
    p.add_argument("--limit", type=int, help="run only the first N runnable cases")
    p.add_argument("--max-particles", type=int, default=FieldProtocol.max_particles,
                   help=f"per-case budget: most particles of a column (default {FieldProtocol.max_particles:,})")
    p.add_argument("--threads", type=int, default=FieldProtocol.threads,
                   help="CPU threads of each case's step (default 1); workers x threads should not exceed the cores")
    p.add_argument("--columns", type=int, metavar="N",
                   help=f"columns stepped together in one task, with one step size, each on one thread (default "
                        f"{GPU_COLUMNS} on a GPU, 1 on the CPU: each case alone)")
    p.add_argument("--elastic-substratum", action="store_true",
                   help="run the weak layer on the profile's old snow instead of a rigid base (weac's column)")
    p.add_argument("--pre-cut-share", type=float, default=FieldProtocol.pre_cut_share, metavar="SHARE",
                   help="start each column sawn this share of weac's critical cut, in [0, 0.9] (default 0.5; 0: none)")
    p.add_argument("--interface-closure", action="store_true",
                   help="run each column with the laminate closure at its layer interfaces (docs/model.md §5b)")
    p.add_argument("--calibration", metavar="FILE",
                   help="calibration.json of another batch under the same protocol: its calibrated forecast of the "
                        "model's readings is scored on these cases too (each batch writes its own)")
    p.add_argument("--quiet", action="store_true", help="no progress line")
    p.add_argument("--verbose", action="store_true", help="Dask's logs on the terminal (default: dask.log in --out)")
    p.set_defaults(func=cmd_field)
