"""The README's own commands, read from it: what a new user types to install and run the main job, and the tests.

``benchmarks/perf/fresh_clone.py`` times them on a fresh clone; ``tests/test_results_main_job.py`` checks that
the test command is the one CI runs (``.ci/run``).
"""

from __future__ import annotations

import re

__all__ = ["MARKERS", "readme_commands", "split_parts"]

#: command -> the README line after which its bash block is the first one
MARKERS = {"main_job": "## Install and run the main job", "tests": "Install and run the tests"}


def readme_commands(readme: str) -> dict[str, str]:
    """The README's two commands, ``main_job`` and ``tests``, each the first bash block after its marker line.

    A block's continuation lines (``\\`` at the end) are joined into one line.

    Raises
    ------
    ValueError
        When a marker, or a bash block after it, is missing.
    """
    blocks = [(m.start(), m.group(1).strip()) for m in re.finditer(r"```bash\n(.*?)```", readme, re.S)]
    out = {}
    for key, marker in MARKERS.items():
        at = readme.find(marker)
        following = [b for start, b in blocks if start > at] if at >= 0 else []
        if not following:
            raise ValueError(f"README.md: no bash block after {marker!r}")
        out[key] = " ".join(line.rstrip("\\").strip() for line in following[0].splitlines())
    return out


def split_parts(command: str) -> list[str]:
    """The ``&&`` parts of a command line, in order, each stripped."""
    return [p.strip() for p in command.split("&&")]
