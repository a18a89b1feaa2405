"""The README's own commands, read from it: what a new user types to install and run the main job, and the tests.

``benchmarks/perf/fresh_clone.py`` times them on a fresh clone; ``tests/test_results_main_job.py`` checks that
the test command is the one CI runs (``.ci/run``). On the plain install it also runs ``mpm-warp field`` on
:data:`FIELD_TABLE`, which must say in one line that it needs the field extra (:func:`plain_field_verdict`).
"""

from __future__ import annotations

import re

__all__ = ["MARKERS", "FIELD_TABLE", "readme_commands", "split_parts", "plain_field_verdict"]

#: command -> the README line after which its bash block is the first one
MARKERS = {"main_job": "## Install and run the main job", "tests": "Install and run the tests"}

#: a one-row CSV table of PSTs (docs/field.md) for ``mpm-warp field`` on the plain install
FIELD_TABLE = ("id,outcome,slope_deg,column_cm,cut_cm,slab_cm,slab_density,weak_layer_cm,weak_layer_density,w_f,"
               "column_ends\ntiny-a,End,0,40,12,15,180,4,,0.3,\n")


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


def plain_field_verdict(rc: int, stderr: str) -> dict:
    """``mpm-warp field``'s exit status and stderr on an install without the field extra, judged: ``ok`` when it
    exits 2 with one line (Warp's no-GPU notice aside) that names ``"mpm-warp[field]"``, and no traceback."""
    lines = [ln for ln in stderr.splitlines() if ln.strip() and not ln.startswith("Warp ")]
    ok = rc == 2 and len(lines) == 1 and '"mpm-warp[field]"' in lines[0] and "Traceback" not in stderr
    return {"rc": rc, "stderr": lines, "ok": ok}
