"""The command line of a field what-if study: draw cases, run them with one switch changed, write the result.

A script in ``benchmarks/field/`` is its question (its docstring) and one call, :func:`what_if_main`: the
protocol's options (``--quick``, ``--out``), the data, the draw, the Dask batch and one option per switch it
offers (:func:`add_what_if_arguments`); :func:`what_if_study` draws the committed batches' cases
(:func:`~mpm_warp.field.studies.drawn.draw_rows`), runs the what-if
(:func:`~mpm_warp.field.studies.what_if.run_what_if`) and writes its JSON in the what-if schema, with the
environment record taken before the runs, into the ``results`` folder beside the script.
"""

from __future__ import annotations

import os
import sys
import warnings

from ..field.studies.drawn import add_draw_arguments, draw_rows
from ..field.studies.switches import SWITCHES
from ..field.studies.what_if import run_what_if
from .environment import environment, write_json
from .protocol import out_dir, parser

__all__ = ["what_if_main", "add_what_if_arguments", "chosen_switch", "what_if_study"]


def _dest(flag: str) -> str:
    return flag.lstrip("-").replace("-", "_")


def add_what_if_arguments(p, names: tuple[str, ...], per_class: int, results: str) -> None:
    """The arguments of a what-if study of the switches ``names`` (the first is run without an option): the draw
    (:func:`~mpm_warp.field.studies.drawn.add_draw_arguments`, from the committed batches in ``results``) and each
    switch's option."""
    add_draw_arguments(p, f"of the what-if ({SWITCHES[names[0]].what})", per_class, results)
    for n in names:
        if SWITCHES[n].option is not None:
            flag, kind, what = SWITCHES[n].option
            p.add_argument(flag, type=kind, default=None, help=what)


def chosen_switch(args, names: tuple[str, ...]) -> tuple[str, object] | str:
    """The switch and value the options ask for (the first switch at its default without one), or why not: one
    line (two options given, a value out of range)."""
    given = [(n, getattr(args, _dest(SWITCHES[n].option[0]))) for n in names if SWITCHES[n].option is not None]
    given = [(n, v) for n, v in given if v is not None]
    if len(given) > 1:
        return f"{' and '.join(SWITCHES[n].option[0] for n, _ in given)}: one what-if a run"
    name, value = given[0] if given else (names[0], SWITCHES[names[0]].default)
    why = SWITCHES[name].check(value)
    return why if why is not None else (name, value)


def what_if_study(args, names: tuple[str, ...], name: str, results: str, env: dict) -> int:
    """Run the what-if study ``name`` (its JSON's name) that :func:`add_what_if_arguments` parsed into ``args``;
    ``env`` is the script's environment record, taken before the runs. Returns the exit status (2: invalid
    arguments or data, said on stderr)."""
    chosen = chosen_switch(args, names)
    if isinstance(chosen, str):
        print(f"error: {chosen}", file=sys.stderr)
        return 2
    switch, value = chosen
    warnings.filterwarnings("ignore")
    cap = 20.0 if args.quick else args.max_wall
    rows, pool = draw_rows(args.batches, args.per_class, args.seed, cap)
    rows = rows[:1] if args.quick else rows
    dest = out_dir(args, results, name)
    result = run_what_if(switch, value, rows, args.data, args.runs, workers=args.workers, threads=args.threads)
    if result is None:
        return 2
    for c in result["cases"]:
        a, b = c["before"], c["after"]
        print(f"{c['test']} ({c['observed']}): {a['predicted']} -> {b['predicted'] or b['status']}, runaway "
              f"{a['runaway_cut']} -> {b['runaway_cut']}", flush=True)
    data = {"name": name, **result, "batches": [os.path.relpath(b, os.path.dirname(results)) for b in args.batches],
            "per_class": args.per_class, "seed": args.seed, "max_wall_s": cap,
            "chosen": f"{len(rows)} drawn ({args.per_class} per observed class, seed {args.seed}) from the {pool} "
                      f"finished cases of the batches whose run took at most {cap:g} s",
            "runs": os.path.basename(os.path.normpath(args.runs)) if args.runs else None, "environment": env}
    path = write_json(name, data, dest)
    print(f"{path}: {len(rows)} cases")
    return 0


def what_if_main(doc: str, script: str, names: tuple[str, ...], per_class: int, argv=None) -> int:
    """The whole command line of the what-if script ``script`` (its ``__file__``; ``doc``, its docstring): the
    switches ``names`` (the first without an option), ``per_class`` cases a class by default. Its JSON is
    ``field_<script's stem>.json`` in ``results/`` beside it (or ``--out``). Returns the exit status."""
    p = parser(doc, "one case of at most 20 s")
    results = os.path.join(os.path.dirname(os.path.abspath(script)), "results")
    add_what_if_arguments(p, names, per_class, results)
    args = p.parse_args(argv)
    name = "field_" + os.path.splitext(os.path.basename(script))[0]
    return what_if_study(args, names, name, results, environment("cpu"))
