"""The generated parts of the docs: text between two marker lines of a Markdown file, replaced whole, and what
the two generators (``python -m mpm_warp.docgen``, ``python -m mpm_warp.studies.report``) share: the checkout
they write in, their ``--root``/``--check`` command line and the write of a generated file."""

from __future__ import annotations

import argparse
import os

__all__ = ["with_block", "checkout_root", "generator_args", "write_generated"]


def with_block(text: str, lines: list[str], begin: str, end: str) -> str | None:
    """``text`` with what lies between the markers ``begin`` and ``end`` replaced by ``lines``; None without both."""
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < i:
        return None
    return text[:i + len(begin)] + "\n" + "\n".join(lines) + "\n" + text[j:]


def checkout_root() -> str:
    """The repository this package runs from (an editable install's checkout)."""
    return os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def generator_args(prog: str, doc: str, what: str, argv=None) -> argparse.Namespace:
    """A generator's command line, parsed from ``argv``: ``--root`` (the repository) and ``--check`` (write
    nothing; exit 1 if a generated ``what`` is out of date); ``doc``'s first paragraph describes it."""
    ap = argparse.ArgumentParser(prog=prog, description=doc.split("\n\n")[0])
    ap.add_argument("--root", default=None, help="the repository (default: the checkout this package runs from)")
    ap.add_argument("--check", action="store_true", help=f"write nothing; exit 1 if a generated {what} is out of date")
    return ap.parse_args(argv)


def write_generated(path: str, text: str) -> None:
    """Write ``text`` to ``path`` whole or not at all (a temporary file beside it, then renamed), its folder
    created."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path + ".tmp", "w") as fh:
        fh.write(text)
    os.replace(path + ".tmp", path)
