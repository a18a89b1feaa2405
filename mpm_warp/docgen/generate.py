"""``python -m mpm_warp.docgen``: write the generated parts of ``docs/scenarios.md`` and
``README.md`` (the command-line reference and table from the argument parser, the scenario key reference
from the parameter dataclasses); ``--check`` writes nothing and exits 1 if a committed file is out of date
(``tests/test_docs_generated.py`` checks it in CI).

Each generated part sits between a begin and an end marker (``<!-- cli:begin -->`` ... ``<!-- cli:end -->``)
and is replaced whole; the text around the markers is left as written.
"""

from __future__ import annotations

import os
import sys

from ..markers import checkout_root, generator_args, with_block, write_generated
from . import cli_doc, keys_doc

__all__ = ["generated_files", "main"]


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
    root = root or checkout_root()
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
    a = generator_args("python -m mpm_warp.docgen", __doc__, "block", argv)
    root = a.root or checkout_root()
    files = generated_files(root)
    stale = [rel for rel, (old, new) in files.items() if old != new]
    if not a.check:
        for rel in stale:
            write_generated(os.path.join(root, rel), files[rel][1])
    for rel in stale:
        print(("out of date: " if a.check else "wrote ") + rel)
    if not stale:
        print("current: " + ", ".join(files))
    return 1 if (a.check and stale) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
