"""Does the model's slab break once it lands, after the crack has reached the end, and more often in SF records?

The batch stops a case at its END call; an observer watches the cut slab fall onto its collapsed weak layer.
For every finished case of a field batch's runs folder that the batch called END, a copy of its run is resumed
from its checkpoint for ``--after`` seconds more (``mpm_warp.field.run_on``; the batch's files are not written),
stopping at a crack through the slab. Per case: whether and when the slab cracked through, its peak stress over
strength before and after the call, the longest touchdown distance the run measured, and Heierli's touchdown
distance against the column (``mpm_warp.field.mechanisms``). Summed by observed class, with the SF-against-END
AUC of the peak stress after the call and of a through-crack. A case's record is kept in ``--work`` (a rerun
resumes). Writes ``benchmarks/field/results/field_landing.json``.

The slab's stress is read twice: over the whole slab (its rows next to the weak layer included, where the grid
ties the slab to the collapsing layer and it cracks along the bed) and over its body, the reading the model's
P(SF) takes at the call (docs/field.md, "The outcome as a probability"): its peak over the frames run on
(``body_peak_after``; a run file written before the body's series records none) and its carried stress at the end,
from the copy's final checkpoint (``body_at_end``, 1 where a body particle cracked).

Usage: ``python benchmarks/field/landing.py --runs RUNDIR --work DIR [--after 0.1] [--cases JSON] [--part K/N]``
(``--cases``: only the scored columns of a disagreements file; ``--part``: the K-th of N interleaved shares, for
N processes on one ``--work``; a run without ``--part`` gathers every share's records; ``--finished``: only the
records already in ``--work``, running nothing, for a study stopped early; ``--observed SF,END``: only those
observed classes). A record in ``--work`` from another runs folder or another ``--after`` stops the study with
one line, never reused or overwritten. ``--quick``: one case.
"""

from __future__ import annotations

import glob
import json
import os
import statistics
import sys
import warnings

from mpm_warp.errors import InvalidArgument
from mpm_warp.field.mechanisms import touchdown_distance
from mpm_warp.field.run_on import kept_record, run_on, scenario_of
from mpm_warp.field.scores import FIELD_CLASSES, field_class
from mpm_warp.field.studies.at_call import body_stress_ratio
from mpm_warp.io.records import write_record
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def one(rec: dict, run_dir: str, work: str, after: float) -> dict:
    """The landing record of the batch record ``rec`` (kept in ``work``; read back when there)."""
    path = os.path.join(work, rec["id"] + ".landing.json")
    study = {"runs": os.path.basename(os.path.normpath(run_dir)), "after_s": after}
    kept = kept_record(path, study)
    if kept is not None:
        return kept
    sc = scenario_of(run_dir, rec["id"])
    p = sc.scene
    out = {**study, **{k: rec.get(k) for k in ("id", "test", "observed", "predicted", "slab_depth", "slab_density")}}
    out.update(touchdown_distance=touchdown_distance(p), column_m=float(p.length))
    try:
        out.update(status="ok", **run_on(run_dir, rec["id"], work, after))
        out["body_at_end"] = body_stress_ratio(work, rec["id"], sc)     # the copy's final checkpoint
    except Exception as e:      # recorded, never stops the others
        out.update(status="failed", error=f"{type(e).__name__}: {e}")
    write_record(path, out, "a landing record", default=str)
    for f in (rec["id"] + ".h5", rec["id"] + ".ckpt.h5"):      # the copy has served: keep the record only
        if os.path.exists(os.path.join(work, f)):
            os.remove(os.path.join(work, f))
    return out


def summary(rows: list[dict]) -> dict:
    """Per observed class: cases, through-cracks after the call, median peak stress ratio after it; and the AUCs."""
    from sklearn.metrics import roc_auc_score

    ok = [r for r in rows if r["status"] == "ok"]
    by = {}
    for c in FIELD_CLASSES:
        of = [r for r in ok if r["observed"] == c]
        after = sorted(r["peak_stress_ratio_after"] for r in of if r["peak_stress_ratio_after"] is not None)
        body = [r["body_peak_after"] for r in of if r.get("body_peak_after") is not None]
        end = [r["body_at_end"] for r in of if r.get("body_at_end") is not None]
        inside = [r for r in of if r["touchdown_distance"] < r["column_m"]]
        by[c] = {"cases": len(of), "through_crack": sum(r["slab_through_crack_time"] is not None for r in of),
                 "touchdown_inside": len(inside),
                 "through_crack_touchdown_inside": sum(r["slab_through_crack_time"] is not None for r in inside),
                 "median_peak_after": after[len(after) // 2] if after else None,
                 "median_body_peak_after": statistics.median(body) if body else None, "body_read": len(body),
                 "median_body_at_end": statistics.median(end) if end else None,
                 "body_cracked_at_end": sum(v >= 1.0 for v in end), "body_at_end_read": len(end)}
    se = [r for r in ok if r["observed"] in ("SF", "END") and r["peak_stress_ratio_after"] is not None]
    y = [r["observed"] == "SF" for r in se]
    two = 0 < sum(y) < len(y)
    sb = [r for r in se if r.get("body_peak_after") is not None]
    yb = [r["observed"] == "SF" for r in sb]
    sz = [r for r in se if r.get("body_at_end") is not None]
    yz = [r["observed"] == "SF" for r in sz]
    return {"by_observed": by,
            "auc_body_at_end": float(roc_auc_score(yz, [r["body_at_end"] for r in sz])) if 0 < sum(yz) < len(yz)
            else None, "sf_end_body_at_end_cases": len(sz),
            "auc_body_peak_after": float(roc_auc_score(yb, [r["body_peak_after"] for r in sb]))
            if 0 < sum(yb) < len(yb) else None, "sf_end_body_cases": len(sb),
            "auc_peak_after": float(roc_auc_score(y, [r["peak_stress_ratio_after"] for r in se])) if two else None,
            "auc_through_crack": float(roc_auc_score(y, [r["slab_through_crack_time"] is not None for r in se]))
            if two else None, "sf_end_cases": len(se)}


def _part(p, text: str | None) -> tuple[int, int] | None:
    """``(K, N)`` of ``--part K/N``, or the parser's one-line error."""
    if text is None:
        return None
    try:
        k, n = (int(x) for x in text.split("/"))
    except ValueError:
        k = n = 0
    if not 1 <= k <= n:
        p.error(f"--part = {text!r}: K/N with 1 <= K <= N, e.g. 1/2")
    return k, n


def main(argv=None) -> int:
    p = parser(__doc__, "one case")
    p.add_argument("--runs", required=True, help="a field batch's runs folder (field_batch.py --runs)")
    p.add_argument("--work", required=True, help="folder of the copies and the per-case records (kept: resumes)")
    p.add_argument("--after", type=float, default=0.1, help="simulated time past the END call (s, default 0.1)")
    p.add_argument("--cases", help="a disagreements file (field_disagreements.json): only its scored columns")
    p.add_argument("--part", help="K/N: run only the K-th of N interleaved shares of the cases (1 <= K <= N)")
    p.add_argument("--finished", action="store_true", help="summarise the records already in --work, run nothing")
    p.add_argument("--observed", default=",".join(FIELD_CLASSES),
                   help="the observed classes to run on, comma-separated (default END,SF,ARR)")
    args = p.parse_args(argv)
    share = _part(p, args.part)
    warnings.filterwarnings("ignore")
    recs = []
    for f in sorted(glob.glob(os.path.join(args.runs, "*.json"))):
        with open(f) as fh:
            r = json.load(fh)
        if r.get("status") == "ok" and r.get("predicted") == "END" and r.get("observed"):
            recs.append(r)
    classes = [c.strip() for c in args.observed.split(",") if c.strip()]
    if not classes or any(c not in FIELD_CLASSES for c in classes):
        p.error(f"--observed = {args.observed!r}: a comma-separated subset of {','.join(FIELD_CLASSES)}")
    recs = [r for r in recs if field_class(r["observed"]) in classes]
    if args.cases:
        with open(args.cases) as fh:
            keep = {c["id"] for c in json.load(fh)["cases"] if c["observed"] in FIELD_CLASSES}
        recs = [r for r in recs if r["id"] in keep]
    recs = recs[:1] if args.quick else recs
    if share is not None:
        recs = recs[share[0] - 1::share[1]]
    planned = len(recs)
    if args.finished:
        recs = [r for r in recs if os.path.exists(os.path.join(args.work, r["id"] + ".landing.json"))]
    rows = []
    for r in recs:
        try:
            rows.append(one(r, args.runs, args.work, args.after))
        except InvalidArgument as e:
            print(f"landing: {e}", file=sys.stderr)
            return 2
        x = rows[-1]
        print(f"{x['test']} ({x['observed']}): through-crack {x.get('slab_through_crack_time')}, peak after "
              f"{x.get('peak_stress_ratio_after')}", flush=True)
    if share is not None:
        print(f"part {share[0]}/{share[1]}: {len(rows)} records in {args.work}")
        return 0
    data = {"name": "field_landing", "runs": os.path.basename(os.path.normpath(args.runs)), "after_s": args.after,
            "planned": planned, "observed": classes, "cases_from": os.path.basename(args.cases) if args.cases else None,
            "environment": environment("cpu"), "summary": summary(rows), "cases": rows}
    path = write_json("field_landing", data, out_dir(args, RESULTS, "field_landing"))
    print(f"{path}: {len(rows)} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
