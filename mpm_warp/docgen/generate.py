"""``python -m mpm_warp.docgen``: write the generated parts of ``docs/scenarios.md`` and
``README.md`` (the command-line reference and table from the argument parser, the scenario key reference
from the parameter dataclasses); ``--check`` writes nothing and exits 1 if a committed file is out of date
(``tests/test_docs_generated.py`` checks it in CI).

Each generated part sits between a begin and an end marker (``<!-- cli:begin -->`` ... ``<!-- cli:end -->``)
and is replaced whole; the text around the markers is left as written.
"""

from __future__ import annotations

import argparse
import os
import sys

from ..markers import with_block
from . import cli_doc, keys_doc

__all__ = ["generated_files", "main"]


def _root() -> str:
    return os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _blocks() -> dict[str, list[tuple[str, str, list[str]]]]:
    """``{file: [(begin, end, lines), ...]}``: every generated block, by the file it lives in."""
    from ..cli import build_parser

    parser = build_parser()
    return {"docs/scenarios.md": [(cli_doc.BEGIN, cli_doc.END, cli_doc.cli_lines(parser)),
                                  (keys_doc.BEGIN, keys_doc.END, keys_doc.keys_lines())],
            "README.md": [(cli_doc.README_BEGIN, cli_doc.README_END, cli_doc.readme_lines(parser))]}


def generated_files(root: str | None = None) -> dict[str, tuple[str, str]]:
    """``{path relative to root: (committed text, generated text)}`` of every file with generated blocks.

    Raises
    ------
    ValueError
        A file that lacks one of its blocks' markers (the block would silently not be written).
    """
    root = root or _root()
    out = {}
    for rel, blocks in _blocks().items():
        with open(os.path.join(root, rel)) as fh:
            old = fh.read()
        text = old
        for begin, end, lines in blocks:
            new = with_block(text, lines, begin, end)
            if new is None:
                raise ValueError(f"{rel}: no {begin} ... {end} markers")
            text = new
        out[rel] = (old, text)
    return out


def main(argv=None) -> int:
    """Write (or with ``--check`` only compare) the generated blocks; the exit status 1 means out of date."""
    ap = argparse.ArgumentParser(prog="python -m mpm_warp.docgen", description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", default=None, help="the repository (default: the checkout this package runs from)")
    ap.add_argument("--check", action="store_true", help="write nothing; exit 1 if a generated block is out of date")
    a = ap.parse_args(argv)
    root = a.root or _root()
    files = generated_files(root)
    stale = [rel for rel, (old, new) in files.items() if old != new]
    if not a.check:
        for rel in stale:
            path = os.path.join(root, rel)
            with open(path + ".tmp", "w") as fh:
                fh.write(files[rel][1])
            os.replace(path + ".tmp", path)
    for rel in stale:
        print(("out of date: " if a.check else "wrote ") + rel)
    if not stale:
        print("current: " + ", ".join(files))
    return 1 if (a.check and stale) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
