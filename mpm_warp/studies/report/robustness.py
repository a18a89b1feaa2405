"""Sections of the robustness results: what a full disk does to a run and its resume."""

from __future__ import annotations

from collections import Counter

from .core import section
from .fmt import env_note, table

#: kind of a disk-full case -> (what ran out, what its ``size`` counts)
_KINDS = {"tmpfs": ("a tmpfs of that size", "KiB"), "fsize": ("a file-size limit (RLIMIT_FSIZE)", "KiB"),
          "strace": ("ENOSPC injected into that pwrite64", "write index")}


@section("robustness", "A full disk", "robustness/results/disk_full.json",
         "sudo python benchmarks/robustness/disk_full.py",
         question="Does a full disk ever lose a frame, leave debris, crash or hang, and does the resume equal the "
                  "uninterrupted run?")
def render_disk_full(data: dict, ctx) -> list[str]:
    rows = []
    for kind in dict.fromkeys(c["kind"] for c in data["cases"]):
        cs = [c for c in data["cases"] if c["kind"] == kind]
        what, unit = _KINDS.get(kind, (kind, "size"))
        rcs = Counter(c["rc"] for c in cs)
        resumed = [c for c in cs if c.get("resume_rc") is not None]
        rows.append([f"`{kind}`: {what}", f"{min(c['size'] for c in cs)}-{max(c['size'] for c in cs)} {unit}", len(cs),
                     ", ".join(f"{rc} ({n})" for rc, n in sorted(rcs.items())),
                     sum(1 for c in cs if c["lines"] == 1), sum(1 for c in cs if c["leftovers"]),
                     f"{sum(1 for c in resumed if c['resume_rc'] == 0)} of {len(resumed)}",
                     sum(1 for c in resumed if c.get("bit_for_bit")), len(cs) - len(resumed),
                     sum(1 for c in cs if c.get("ok"))])
    out = [f"{data.get('what', '')} The run: `{' '.join(data.get('scenario') or [])}`.", ""]
    out += table(["what ran out", "swept over", "runs", "exit status (runs)", "one-line error", "with debris left",
                  "resumed (exit 0)", "resume bit for bit", "no checkpoint yet (not resumed)", "all checks met"],
                 rows)
    return out + ["", env_note(data)]
