"""The command line every benchmark script has: ``--device``, ``--quick`` and ``--out``.

A full run writes its JSON (and figure) to the committed results beside the script
(``benchmarks/<group>/results/``): running the benchmark is asking for that. ``--quick`` runs a small
case on the CPU in about a minute and writes to a new temporary folder, never over the committed
results, unless ``--out`` names a folder. A full run from a dirty checkout is refused (commit first).
"""

from __future__ import annotations

import argparse
import os
import tempfile

__all__ = ["parser", "parse_cases", "out_dir", "result_name"]


def parser(doc: str, quick: str, device: str | None = "cpu") -> argparse.ArgumentParser:
    """An argument parser with the protocol's options.

    Parameters
    ----------
    doc : str
        The script's module docstring (its first line is the question it answers).
    quick : str
        What ``--quick`` runs, for ``--help``.
    device : str or None
        Default Warp device (None: the script picks one).
    """
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--device", default=device, help=f"Warp device (default {device or 'cuda:0 when present'})")
    ap.add_argument("--quick", action="store_true",
                    help=f"a small CPU case in about a minute ({quick}); writes to a temporary folder unless --out")
    ap.add_argument("--out", default=None, metavar="DIR",
                    help="folder of the JSON and figure (default: the committed results beside the script; "
                         "with --quick a new temporary folder)")
    return ap


def parse_cases(ap: argparse.ArgumentParser, argv, cases, none: str = "default: all") -> argparse.Namespace:
    """Parse ``argv`` with ``ap`` and a positional ``cases``, any of ``cases`` (``none``: what naming none does);
    an unknown case is the parser's one-line error (exit status 2) naming it and the choices."""
    ap.add_argument("cases", nargs="*", help=f"any of {', '.join(cases)} ({none})")
    a = ap.parse_args(argv)
    bad = [c for c in a.cases if c not in cases]
    if bad:
        ap.error(f"unknown case(s) {', '.join(bad)}: choose from {', '.join(cases)}")
    return a


def out_dir(args: argparse.Namespace, results: str, name: str = "study") -> str:
    """The folder a run writes to: ``--out``, else a new temporary folder with ``--quick``, else ``results``.

    A committed results folder from a dirty checkout is refused here, before the run
    (:func:`~mpm_warp.studies.environment.check_provenance`: one line, exit status 1).
    """
    from .environment import check_provenance

    if args.out:
        check_provenance(args.out)
        os.makedirs(args.out, exist_ok=True)
        return args.out
    if args.quick:
        return tempfile.mkdtemp(prefix=f"mpm_warp_{name}_quick_")
    check_provenance(results)
    return results


def result_name(stem: str, args: argparse.Namespace) -> str:
    """``<stem>_<cpu|cuda>``, with ``_quick`` for a quick run: the name of a result file without its extension."""
    tag = "cuda" if (args.device or "").startswith("cuda") else "cpu"
    return f"{stem}_{tag}" + ("_quick" if args.quick else "")
