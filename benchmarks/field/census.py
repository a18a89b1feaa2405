"""How many real PST records become runnable columns, and why the others do not (mpm_warp.field).

Reads every CAAML file of a folder of snow pits (the development set: 3,220 SnowPilot pits, see
docs/profiles.md), sets up every PST record as a column (reader, failure depth, weak layer, densities,
the fracture energy the record implies, the weak layer's calibration) and counts:

- files read, records per outcome, runnable columns per outcome, refusals per reason (with examples);
- the weak layer's thickness and which rule chose it; the implied fracture energies that were read and why
  the others were not; the columns that lean on a density fallback;
- the two CAAML readers side by side on the same files: files read, PST records recovered, layers, time.

Writes ``benchmarks/field/results/field_census.json``.

Usage: ``python benchmarks/field/census.py DIR [--quick]`` with DIR the unpacked pits (``--quick``: the first
100 files, to a temporary folder). About 5 minutes on 2 CPU cores for the whole set.
"""

from __future__ import annotations

import collections
import glob
import logging
import os
import sys
import time
import warnings

import numpy as np

from mpm_warp.field import FieldCase, field_cases
from mpm_warp.field.cases import OUTCOMES
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
#: before this work (the snowprofile reader, the whole profile layer as the weak layer), counted on the same set
BEFORE = {"files_read": 1275, "files": 3263, "records_set_up": 505, "records_read": 1488}


def readers(files: list[str]) -> dict:
    """snowpylot and snowprofile on the same files: files read, PST records, layers, wall time (s)."""
    import snowprofile.io as sp_io
    from snowpylot import caaml_parser

    out = {}
    t = time.perf_counter()
    ok = recs = layers = 0
    for f in files:
        try:
            p = caaml_parser(f)
        except Exception:       # a refusal by the library is what is counted
            continue
        ok, recs, layers = ok + 1, recs + len(p.stability_tests.PST), layers + len(p.snow_profile.layers)
    out["snowpylot"] = {"files_read": ok, "pst_records": recs, "layers": layers, "wall_s": time.perf_counter() - t}
    t = time.perf_counter()
    ok = recs = layers = 0
    logging.disable(logging.CRITICAL)
    for f in files:
        try:
            sp = sp_io.read_caaml6_xml(f)
        except Exception:       # likewise
            continue
        if sp is None:
            continue
        ok += 1
        recs += sum(1 for s in sp.stability_tests if getattr(s, "type", None) == "PST")
        layers += 0 if sp.stratigraphy_profile is None else len(sp.stratigraphy_profile.data)
    logging.disable(logging.NOTSET)
    out["snowprofile"] = {"files_read": ok, "pst_records": recs, "layers": layers, "wall_s": time.perf_counter() - t}
    return out


def unreadable_records(path: str) -> collections.Counter:
    """The PST outcomes a file we cannot read records, as snowpylot counts them (none if it cannot either)."""
    from snowpylot import caaml_parser

    try:
        return collections.Counter(t.fracture_prop or "none" for t in caaml_parser(path).stability_tests.PST)
    except Exception:           # a file no reader reads holds no countable record
        return collections.Counter()


def weak_layer_rule(choice: str) -> str:
    """Which rule of docs/profiles.md chose a column's weak-layer thickness, from its description."""
    if choice == "given":
        return "given"
    if choice.startswith("the default"):
        return "the default 3 cm (weac's)"
    if "taken as" in choice:
        return "a profile layer under 1 cm, taken as 1 cm"
    return "the profile layer's own (1-3 cm)"


def census(files: list[str]) -> dict:
    outcome, runnable, reasons = collections.Counter(), collections.Counter(), collections.Counter()
    by_reason_outcome, examples = collections.defaultdict(collections.Counter), collections.defaultdict(list)
    choice, d_wl, wf, wf_why, fallback = collections.Counter(), [], [], collections.Counter(), 0
    unreadable = 0
    t = time.perf_counter()
    for f in files:
        for r in field_cases(f):
            if not r.test:
                unreadable += 1
                lost = unreadable_records(f)
                outcome.update(lost)
                reasons[r.reason] += sum(lost.values())
                for o, n in lost.items():
                    by_reason_outcome[r.reason][o] += n
                examples[r.reason].append(r.line()) if len(examples[r.reason]) < 3 else None
                continue
            outcome[r.outcome or "none"] += 1
            if isinstance(r, FieldCase):
                runnable[r.outcome] += 1
                choice[weak_layer_rule(r.column.weak_layer_choice)] += 1
                d_wl.append(r.column.weak_layer_thickness)
                fallback += bool(r.notes)
                if r.fracture_energy.value is not None:
                    wf.append(r.fracture_energy.value)
                else:
                    wf_why["long cut" if "long cut" in r.fracture_energy.reason else "outside range"] += 1
                continue
            reasons[r.reason] += 1
            by_reason_outcome[r.reason][r.outcome or "none"] += 1
            if len(examples[r.reason]) < 3:
                examples[r.reason].append(r.line())
    wall = time.perf_counter() - t
    n_field = sum(outcome[o] for o in OUTCOMES)
    n_run = sum(runnable.values())

    def q(a, p):
        return float(np.percentile(a, p)) if len(a) else None
    return {
        "files": len(files), "files_unreadable": unreadable, "records": sum(outcome.values()),
        "records_by_outcome": dict(outcome), "runnable_by_outcome": dict(runnable), "runnable": n_run,
        "field_outcome_records": n_field, "runnable_fraction_of_field_outcomes": n_run / n_field if n_field else None,
        "refusals": dict(reasons.most_common()),
        "refusals_by_outcome": {k: dict(v) for k, v in by_reason_outcome.items()},
        "refusal_examples": dict(examples),
        "weak_layer_choice": dict(choice),
        "weak_layer_thickness_m": {"median": q(d_wl, 50), "max": max(d_wl) if d_wl else None, "min": min(d_wl) if d_wl
                                   else None},
        "implied_w_f": {"read": len(wf), "not_read": dict(wf_why), "median_J_m2": q(wf, 50), "p10": q(wf, 10),
                        "p90": q(wf, 90), "min": min(wf) if wf else None, "max": max(wf) if wf else None},
        "columns_with_density_fallback": fallback, "wall_s": wall, "before": BEFORE,
    }


def main(argv=None) -> int:
    p = parser(__doc__, "the first 100 files, written to a temporary folder")
    p.add_argument("data", help="folder of CAAML files (the unpacked development set)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    files = sorted(glob.glob(os.path.join(args.data, "*.xml")) + glob.glob(os.path.join(args.data, "*.caaml")))
    if not files:
        print(f"census: data = {args.data!r} is invalid: expected a folder with CAAML files (*.xml, *.caaml)",
              file=sys.stderr)
        return 2
    files = files[:100] if args.quick else files
    data = {"name": "field_census", "data": os.path.basename(os.path.normpath(args.data)),
            "environment": environment("cpu"), "readers": readers(files), "census": census(files)}
    path = write_json("field_census", data, out_dir(args, RESULTS, "field_census"))
    c = data["census"]
    print(f"{path}: {c['runnable']} of {c['field_outcome_records']} End/SF/Arr records runnable "
          f"({c['runnable_fraction_of_field_outcomes']:.1%}); refusals {c['refusals']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
