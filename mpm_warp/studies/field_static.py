"""The run of a static field study: every case the committed batches scored, set up again from its pit, no MPM.

A script in ``benchmarks/field/`` (weac's static rule by grain form, the FE in both plane limits) parses its
options (with :func:`~mpm_warp.field.studies.drawn.add_data_arguments`) and hands :func:`static_study` what it
computes of one case; :func:`static_study` sets the cases up again (the first 3 with ``--quick``), times them and
writes the JSON with the environment record.
"""

from __future__ import annotations

import os
import time
import warnings

from ..field.studies.drawn import scored_cases
from .environment import write_json
from .protocol import out_dir

__all__ = ["static_study"]


def static_study(args, name: str, results: str, row, head: dict, env: dict) -> int:
    """Write ``<name>.json`` of every case the batches ``args.batches`` scored, set up again from ``args.data``.

    Parameters
    ----------
    args : argparse.Namespace
        The script's arguments (``data``, ``batches``, ``quick``, ``out``).
    name : str
        The JSON's name (``field_static_strength``).
    results : str
        The committed results folder beside the script.
    row : callable
        ``row(batch_row, case) -> dict``: what the study computes of one case.
    head : dict
        The study's own fields, before ``batches``, ``wall_s`` (s), ``environment`` and ``cases``.
    env : dict
        The environment record, taken before the cases.

    Returns
    -------
    int
        The exit status: 2 where a case is not set up as its batch set it up (said on stderr).
    """
    warnings.filterwarnings("ignore")
    t0 = time.perf_counter()
    scored = scored_cases(args.batches, args.data, 3 if args.quick else None)
    if scored is None:
        return 2
    out = [row(b, case) for b, case in zip(*scored, strict=True)]
    wall = time.perf_counter() - t0
    data = {"name": name, **head, "batches": [os.path.relpath(b, os.path.dirname(results)) for b in args.batches],
            "wall_s": wall, "environment": env, "cases": out}
    path = write_json(name, data, out_dir(args, results, name))
    print(f"{path}: {len(out)} cases in {wall:.0f} s")
    return 0
