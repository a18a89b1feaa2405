"""The benchmark scripts' figures: pyplot without a display, and a figure written as the results keep it."""

from __future__ import annotations

__all__ = ["pyplot", "save_figure"]


def pyplot():
    """matplotlib's ``pyplot`` on the Agg backend (files only, no display), imported at first use."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: str, dpi: int = 130) -> None:
    """Lay ``fig`` out tight, write it to ``path`` at ``dpi`` dots per inch and close it."""
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)
