"""Text between two marker lines of a Markdown file, replaced whole (the generated parts of the docs)."""

from __future__ import annotations

__all__ = ["with_block"]


def with_block(text: str, lines: list[str], begin: str, end: str) -> str | None:
    """``text`` with what lies between the markers ``begin`` and ``end`` replaced by ``lines``; None without both."""
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < i:
        return None
    return text[:i + len(begin)] + "\n" + "\n".join(lines) + "\n" + text[j:]
