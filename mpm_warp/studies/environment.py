"""The environment record of a study's result (device, versions, date, load, CPU, commit), and its JSON file.

A result in the committed results folders (``benchmarks/<group>/results/``) must name the code that made
it: :func:`write_json` refuses to write one there from a dirty tree (:func:`check_provenance`); a
``--quick`` run, or one with ``--out`` elsewhere, still writes, its ``git_commit`` marked ``+dirty``.
"""

from __future__ import annotations

import datetime
import importlib.metadata
import os
import platform
import subprocess
import sys

import warp as wp

from ..finite_json import dump_finite
from ..result import versions

__all__ = ["environment", "git_commit", "write_json", "is_committed_results", "dirty_marks", "check_provenance",
           "DirtyResultError"]

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
"""The checkout this package runs from (its ``benchmarks/`` holds the committed results)."""
DIRTY_MARKS = ("+dirty", "uncommitted")
"""What a commit string holds when the code that made a result was not committed."""


def environment(device: str | None) -> dict:
    """Device, versions, date, load average, CPU and commit of a run on ``device`` (a Warp device name).

    ``load_average_1_5_15_min`` says how busy the (shared) machine was when the run started;
    :func:`write_json` adds the load at the end. ``git_commit`` is the commit of the checkout the package
    runs from (``+dirty`` with uncommitted changes; None outside git).
    """
    dev = wp.get_device(device) if device else None
    cuda = dev is not None and dev.is_cuda
    env = {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "device": device,
        "device_name": dev.name if dev is not None else "",
        "cuda_driver": _version_str(wp.get_cuda_driver_version()) if cuda else None,
        "cuda_toolkit": _version_str(wp.get_cuda_toolkit_version()) if cuda else None,
        "load_average_1_5_15_min": list(os.getloadavg()),
        "git_commit": git_commit(),
        "cpu": platform.processor() or platform.machine(),
        "cpu_model": cpu_model(),
        "cpu_count": os.cpu_count(),
        **versions(),
    }
    try:
        env["taichi"] = importlib.metadata.version("taichi")
    except importlib.metadata.PackageNotFoundError:  # optional: the peer of the throughput benchmarks
        env["taichi"] = None
    return env


def cpu_model() -> str | None:
    """The CPU's model name, family and model numbers and AVX-512 (Linux ``/proc/cpuinfo``; None elsewhere), e.g.
    ``"AMD EPYC family 25 model 17 avx512f"``: runs on hosts of different CPU generations, which one ``cpu`` value
    hides, then tell apart."""
    try:
        with open("/proc/cpuinfo") as fh:
            first = fh.read().split("\n\n")[0].splitlines()           # the first core's block
    except OSError:
        return None
    info = {k.strip(): v.strip() for k, v in (line.split(":", 1) for line in first if ":" in line)}
    name = info.get("model name")
    if not name:
        return None
    parts = [name, f"family {info['cpu family']}" if "cpu family" in info else "",
             f"model {info['model']}" if "model" in info else "",
             "avx512f" if "avx512f" in info.get("flags", "").split() else ""]
    return " ".join(p for p in parts if p)


def git_commit(path: str | None = None) -> str | None:
    """The commit of the git checkout holding ``path`` (default: this package), ``+dirty`` if it has changes."""
    where = path or os.path.dirname(os.path.abspath(__file__))
    try:
        head = subprocess.run(["git", "-C", where, "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10)
        dirty = subprocess.run(["git", "-C", where, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    if head.returncode != 0:
        return None
    return head.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")


class DirtyResultError(SystemExit):
    """A result from uncommitted code was to be written into the committed results (exits with its line)."""


def is_committed_results(folder: str, root: str | None = None) -> bool:
    """Whether ``folder`` is (under) a committed results folder ``<root>/benchmarks/<group>/results``.

    ``root`` is the checkout (default :data:`REPO_ROOT`); symbolic links are resolved on both sides.
    """
    rel = os.path.relpath(os.path.realpath(folder), os.path.realpath(root or REPO_ROOT))
    parts = rel.split(os.sep)
    return len(parts) >= 3 and parts[0] == "benchmarks" and parts[2] == "results"


def dirty_marks(data) -> list[str]:
    """Every commit string in ``data`` (nested dicts and lists) marked as uncommitted code (:data:`DIRTY_MARKS`).

    The keys read are those naming a commit: ``git_commit``, ``commit`` and ``git_commit_*`` (a merged
    result keeps the commit of each run it merges).
    """
    found: list[str] = []
    if isinstance(data, dict):
        for k, v in data.items():
            if isinstance(v, str) and (k in ("git_commit", "commit") or k.startswith("git_commit_")):
                if any(m in v for m in DIRTY_MARKS):
                    found.append(v)
            else:
                found += dirty_marks(v)
    elif isinstance(data, (list, tuple)):
        for v in data:
            found += dirty_marks(v)
    return found


def check_provenance(folder: str, data: dict | None = None, root: str | None = None) -> None:
    """Refuse (raise :class:`DirtyResultError`) a result from uncommitted code bound for the committed results.

    Outside the committed results (``--quick``, ``--out`` elsewhere) nothing is refused: the result's
    ``git_commit`` carries ``+dirty``. Inside them, the commits ``data`` records decide (the code is
    the one loaded when the run started, so an edit made while it runs does not void it); ``data``
    recording none (or None: the check a script makes before a long run) asks the checkout now.
    """
    if not is_committed_results(folder, root):
        return
    marks = dirty_marks(data) if data is not None else []
    if data is None or not _records_commit(data):
        now = git_commit(root or REPO_ROOT)
        marks = [now] if now and any(m in now for m in DIRTY_MARKS) else []
    if marks:
        raise DirtyResultError(
            f"refused: a result from uncommitted code ({marks[0]}) cannot go into the committed results "
            f"{folder}; commit your changes and rerun, or write elsewhere with --out DIR (or --quick)")


def _records_commit(data) -> bool:
    if isinstance(data, dict):
        return any((k in ("git_commit", "commit") or k.startswith("git_commit_")) and isinstance(v, str)
                   or _records_commit(v) for k, v in data.items())
    if isinstance(data, (list, tuple)):
        return any(_records_commit(v) for v in data)
    return False


def _version_str(v) -> str | None:
    return ".".join(str(p) for p in v) if v else None


def write_json(name: str, data: dict, results_dir: str, end_load: bool = True) -> str:
    """Write ``<results_dir>/<name>.json`` (through a temporary file, so a kill leaves the old one); return its path.

    When ``data`` has an ``environment`` the load average at writing time is added beside the one at
    the start (how busy the shared machine was), unless ``end_load`` is False (a result re-derived from a
    stored run keeps its run's record). No inf or NaN is written: a non-finite number becomes null
    with its reason under ``<key>_null`` (:func:`~mpm_warp.finite_json.finite_json`).

    Into a committed results folder a result from uncommitted code is refused (:func:`check_provenance`
    raises :class:`DirtyResultError`: one line, nothing written); elsewhere it is written, and a line on
    stderr says it is marked dirty.
    """
    check_provenance(results_dir, data)
    marks = dirty_marks(data)
    if marks:
        print(f"note: {name}.json is marked dirty ({marks[0]}): not a result to commit", file=sys.stderr)
    if end_load and isinstance(data.get("environment"), dict):
        data["environment"]["load_average_at_end_1_5_15_min"] = list(os.getloadavg())
    os.makedirs(results_dir, exist_ok=True)
    path = os.path.join(results_dir, name + ".json")
    with open(path + ".tmp", "w") as fh:
        dump_finite(data, fh, indent=1, default=float)
        fh.write("\n")
    os.replace(path + ".tmp", path)
    return path
