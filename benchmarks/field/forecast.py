"""How do the model's outcome probabilities score against the references, as a forecaster scores them?

Scores a field batch's finished cases (``field_batch.py --runs RUNDIR``, resumed or stopped early) with
``mpm_warp.field.scoring``: the model's first-order probabilities (its run's slab-body stress under snow's Weibull
strength scatter; a run recorded before the body's series is read at its call from its final checkpoint,
``mpm_warp.field.studies.at_call``), the set's climatology, the majority class and weac's static rule as sure
forecasts, the information bar (a logistic regression on slab depth, density, slope and cut share,
cross-validated by pit) and the model's readings calibrated by the same regression and folds
(``mpm_warp.field.calibrated``; a run from before them read from its files).
Ranked probability skill against the climatology, Brier score per class, one-vs-rest AUC for SF and ARR,
balanced accuracy of the most probable class, each with paired bootstrap intervals; and the reliability
diagram. Writes ``benchmarks/field/results/field_forecast.json`` and ``field_forecast.png``.

Usage: ``python benchmarks/field/forecast.py DIR --runs RUNDIR [--per-class 50] [--seed 0] [--no-measured]``
(the same draw as ``field_batch.py``: its first cases, in its interleaved order, whose runs have finished);
``--quick``: a small made-up set, no runs.
"""

from __future__ import annotations

import os
import sys
import warnings

import numpy as np

from mpm_warp.field.calibrated import MODEL_READINGS
from mpm_warp.field.draw import finished_draw
from mpm_warp.field.probability import slab_reading
from mpm_warp.field.scores import FIELD_CLASSES
from mpm_warp.field.scoring import forecasts, score_records, scored
from mpm_warp.field.studies.at_call import body_at_call
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
#: points: where each forecast's bin counts sit against its markers, so that forecasts sharing a bin stay legible
LABEL_OFFSETS = ((4, 4), (4, -11), (-16, 4), (-16, -11), (-6, 10))


def reliability_figure(sc: dict, path: str) -> None:
    """Observed frequency against forecast probability, per class, for every forecast with a reliability table."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [n for n in ("model", "calibrated", "information_bar", "climatology", "weac_static")
             if n in sc["forecast"]]
    fig, axes = plt.subplots(1, 3, figsize=(12, 4.2), sharey=True)
    for ax, cls in zip(axes, FIELD_CLASSES, strict=True):
        ax.plot([0, 1], [0, 1], color="0.6", lw=1, ls="--", label="perfectly reliable")
        for k, name in enumerate(names):
            t = sc["forecast"][name]["reliability"][cls]
            pts = [(f, o, n) for f, o, n in zip(t["forecast"], t["observed"], t["count"], strict=True) if n]
            if pts:
                f, o, n = map(np.array, zip(*pts, strict=True))
                (line,) = ax.plot(f, o, marker="o", label=f"{name} (RPSS {sc['forecast'][name]['rpss']:+.2f})")
                for fx, ox, nx in pts:         # each forecast's counts in its colour, on its own side of the point
                    ax.annotate(str(nx), (fx, ox), textcoords="offset points",
                                xytext=LABEL_OFFSETS[k % len(LABEL_OFFSETS)],
                                fontsize=7, color=line.get_color())
        ax.set(title=f"{cls}", xlabel=f"forecast P({cls})", xlim=(-0.03, 1.03), ylim=(-0.03, 1.03))
    axes[0].set_ylabel("observed frequency (numbers: cases in the bin)")
    axes[0].legend(fontsize=7, loc="upper left")
    fig.suptitle(f"Reliability of the outcome forecasts on {sc['cases']} field PSTs")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def made_up(n: int = 30, seed: int = 0) -> list[dict]:
    """A small made-up batch (``--quick``): three classes, two cases a pit, a model that half knows SF, the model's
    readings noise."""
    rng = np.random.default_rng(seed)
    recs = []
    for i in range(n):
        obs = FIELD_CLASSES[i % 3]
        recs.append({"id": f"c{i}", "pit": f"p{i // 2}", "status": "ok", "observed": obs,
                     "predicted": "SF" if obs == "SF" and i % 2 else "END", "static_class": "END",
                     "slab_peak_stress_ratio": float(rng.uniform(0.2, 1.2)), "slab_depth": float(rng.uniform(0.2, 0.8)),
                     "slab_density": float(rng.uniform(100, 250)), "slope_deg": 30.0, "cut_share": 0.4, "wall_s": 1.0,
                     **{k: float(rng.uniform(0.0, 1.0)) for k in MODEL_READINGS}})
    return recs


def main(argv=None) -> int:
    p = parser(__doc__, "a made-up set of 30 cases")
    p.add_argument("data", nargs="?", help="folder of CAAML files (the unpacked development set)")
    p.add_argument("--runs", help="folder of the batch's runs (field_batch.py --runs)")
    p.add_argument("--per-class", type=int, default=50, help="the batch's sampled cases per class (default 50)")
    p.add_argument("--seed", type=int, default=0, help="the batch's seed (default 0)")
    p.add_argument("--no-measured", action="store_true",
                   help="the batch's draw without the measured-density columns (field_batch.py --no-measured)")
    args = p.parse_args(argv)
    warnings.filterwarnings("ignore")
    if args.quick:
        recs, selection = made_up(), {"made_up": True}
    else:
        if not (args.data and args.runs):
            p.error("DIR and --runs are needed without --quick")
        recs, selection = finished_draw(args.data, args.runs, args.per_class, args.seed,
                                        measured=not args.no_measured)
        body_at_call(recs, args.runs)
    ok = scored(recs)
    made = forecasts(ok)
    sc = score_records(recs, probs=made)
    probs = made[0]
    dest = out_dir(args, RESULTS, "field_forecast")
    data = {"name": "field_forecast", "environment": environment("cpu"), "selection": selection, "scores": sc,
            "cases": [{"id": r["id"], "observed": r["observed"], "predicted": r["predicted"],
                       "slab_reading": slab_reading(r)[1],
                       **{name: [float(x) for x in pr[i]] for name, pr in probs.items() if name != "climatology"}}
                      for i, r in enumerate(ok)]}
    path = write_json("field_forecast", data, dest)
    reliability_figure(sc, os.path.join(dest, "field_forecast.png"))
    for name, f in sc["forecast"].items():
        print(f"{name:16s} RPSS {f['rpss']:+.3f}  Brier SF {f['brier']['SF']:.3f}  AUC SF {f['auc']['SF']}  "
              f"balanced accuracy {f['balanced_accuracy']:.3f}")
    print(f"{path}: {sc['cases']} cases")
    return 0


if __name__ == "__main__":
    sys.exit(main())
