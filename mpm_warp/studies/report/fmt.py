"""Number and table formatting of the results document: every number printed comes through here.

Missing or non-finite values print as ``-``; units and digits are chosen by the caller per quantity.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

__all__ = ["finite", "fx", "pct", "spct", "count", "secs", "ratio_range", "span", "table", "env_note",
           "cases_load_note", "environment_of", "bracket", "first", "check_line"]

DASH = "-"


def finite(x) -> bool:
    """True for a real number that is neither nan nor infinite (False for None, strings, booleans)."""
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def fx(x, nd: int = 2, scale: float = 1.0, unit: str = "") -> str:
    """``x * scale`` with ``nd`` decimals (and `` unit``), or ``-``."""
    if not finite(x):
        return DASH
    s = f"{x * scale:.{nd}f}"
    return f"{s} {unit}" if unit else s


def pct(x, nd: int = 1) -> str:
    """A fraction as a percentage, ``0.0123 -> '1.2 %'``."""
    return fx(x, nd, 100.0, "%")


def spct(x, nd: int = 1) -> str:
    """A signed fraction as a signed percentage, ``-0.081 -> '-8.1 %'``."""
    if not finite(x):
        return DASH
    s = f"{100.0 * x:+.{nd}f}"
    return ("0." + "0" * nd if float(s) == 0 else s) + " %"


def count(n) -> str:
    """An integer count with thousands separators, ``386073 -> '386,073'``."""
    return f"{int(round(n)):,}" if finite(n) else DASH


def secs(t) -> str:
    """A wall or CPU time in seconds: two significant digits below 10 s, whole seconds (with separators) above."""
    if not finite(t):
        return DASH
    if t < 10.0:
        return f"{t:.2g} s"
    return f"{int(round(t)):,} s"


def ratio_range(values: Iterable, nd: int = 2, suffix: str = "") -> str:
    """``'a-b'`` of the finite values (one value alone if they agree at ``nd`` decimals)."""
    v = [x for x in values if finite(x)]
    if not v:
        return DASH
    lo, hi = f"{min(v):.{nd}f}", f"{max(v):.{nd}f}"
    if lo == hi:
        return lo + suffix
    return (f"{lo} to {hi}" if lo.startswith("-") or hi.startswith("-") else f"{lo}-{hi}") + suffix


span = ratio_range


def bracket(value, lo, hi, nd: int = 3, unit: str = "m") -> str:
    """A bisected value with its bracket, ``'0.353 m [0.344, 0.362]'``."""
    if not finite(value):
        return DASH
    return f"{value:.{nd}f} {unit} [{lo:.{nd}f}, {hi:.{nd}f}]"


def first(xs: Sequence, default=None):
    """The first element of a sequence, or ``default``."""
    return xs[0] if xs else default


def table(header: Sequence[str], rows: Iterable[Sequence], align: Sequence[str] | None = None) -> list[str]:
    """A Markdown table; ``align`` per column ``'l'`` or ``'r'`` (default: the first left, the others right)."""
    header = list(header)
    align = list(align) if align else ["l"] + ["r"] * (len(header) - 1)
    rule = ["---:" if a == "r" else "---" for a in align]
    out = ["| " + " | ".join(header) + " |", "|" + "|".join(rule) + "|"]
    for r in rows:
        cells = [str(c).replace("|", "\\|") for c in r]
        out.append("| " + " | ".join(cells) + " |")
    return out


def environment_of(data: dict) -> dict:
    """The environment record of a result, from its ``environment`` (or, in older files, its top-level keys).

    Returns a dict with ``device``, ``cpu``, ``cpu_model`` (None in older files), ``cpu_count``, ``date``
    (``YYYY-MM-DD`` or None), ``load`` and ``load_end`` (1-minute load averages or None) and ``versions``
    (name -> version, the peers that ran).
    """
    env = data.get("environment") if isinstance(data.get("environment"), dict) else {}
    versions = dict(data.get("versions") or {})
    for k in ("warp", "taichi", "weac"):
        if env.get(k):
            versions[k] = env[k]
    date = env.get("date") or data.get("date")
    load = env.get("load_average_1_5_15_min")
    load_end = env.get("load_average_at_end_1_5_15_min")
    return {"device": env.get("device", data.get("device")), "cpu": env.get("cpu"), "cpu_model": env.get("cpu_model"),
            "cpu_count": env.get("cpu_count"),
            "date": date[:10] if isinstance(date, str) else None,
            "load": load[0] if load else None, "load_end": load_end[0] if load_end else None,
            "versions": versions}


_PEERS = (("warp", "warp"), ("taichi", "Taichi"), ("weac", "weac"))


def check_line(label: str, criterion: str, passed: bool | None, why: str = "") -> str:
    """The pass line of a comparison with a reference, shown beside its table.

    ``"- **Check, flat ladder against weac:** |MPM / weac - 1| <= 15 %: **pass** (-9.1 %)."``.
    ``passed`` None says the comparison is open (no criterion can be judged from the data); a fail stays
    in the document with ``why``, its explanation.
    """
    verdict = {True: "**pass**", False: "**FAIL**", None: "**open**"}[None if passed is None else bool(passed)]
    return f"- **Check, {label}:** {criterion}: {verdict}" + (f" ({why})" if why else "") + "."


def cases_load_note(envs) -> str | None:
    """The line on the load under a batch's cases: the 1-minute load average at their starts, from each case's own
    environment record (None where none has one), beside :func:`env_note`'s load when the JSON was written."""
    loads = sorted((e["load_average_1_5_15_min"][0], e.get("cpu_count")) for e in envs
                   if e and e.get("load_average_1_5_15_min"))
    if not loads:
        return None
    lo, hi, cores = loads[0][0], loads[-1][0], loads[0][1]
    return (f"- The cases' wall times are upper bounds: the 1-minute load average at their starts was {lo:.1f}-"
            f"{hi:.1f} on the {cores} cores (the note below: when the JSON was written).")


def env_note(*records: dict, verb: str = "measured") -> str:
    """The one-line note of where and when a table was measured, from one or more results' environments.

    ``"*Measured on cpu (x86_64, 2 cores), 2026-11-30, load average 4.4 at the start and 4.4 at the end;
    warp 1.19.0, Taichi 1.7.4.*"``. Several records (the cases of one file) give ranges.
    """
    envs = [environment_of(r) for r in records]
    devices = sorted({e["device"] or "the host, no Warp device" for e in envs})
    cpus = sorted({f"{e['cpu']}, {e['cpu_model'] + ', ' if e['cpu_model'] else ''}{e['cpu_count']} cores"
                   for e in envs if e["cpu"] and e["cpu_count"]})
    where = ", ".join(devices) + (f" ({'; '.join(cpus)})" if cpus else "")
    dates = sorted({e["date"] for e in envs if e["date"]})
    when = (dates[0] if len(dates) == 1 else f"{dates[0]} to {dates[-1]}") if dates else "date not recorded"
    loads = [e["load"] for e in envs if finite(e["load"])]
    ends = [e["load_end"] for e in envs if finite(e["load_end"])]
    if loads:
        load = f"load average {ratio_range(loads, 1)} at the start"
        if ends:
            load += f" and {ratio_range(ends, 1)} at the end"
    else:
        load = "load average not recorded"
    peers = []
    for key, name in _PEERS:
        vs = sorted({e["versions"][key] for e in envs if e["versions"].get(key)})
        if vs:
            peers.append(f"{name} {', '.join(vs)}")
    tail = "; " + ", ".join(peers) if peers else ""
    return f"*{verb.capitalize()} on {where}, {when}, {load}{tail}.*"
