"""The environment record of a study's result (device, versions, date, load, CPU, commit), and its JSON file."""

from __future__ import annotations

import datetime
import importlib.metadata
import os
import platform
import subprocess

import warp as wp

from ..finite_json import dump_finite
from ..result import versions

__all__ = ["environment", "git_commit", "write_json"]


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
        "cpu_count": os.cpu_count(),
        **versions(),
    }
    try:
        env["taichi"] = importlib.metadata.version("taichi")
    except importlib.metadata.PackageNotFoundError:  # optional: the peer of the throughput benchmarks
        env["taichi"] = None
    return env


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


def _version_str(v) -> str | None:
    return ".".join(str(p) for p in v) if v else None


def write_json(name: str, data: dict, results_dir: str, end_load: bool = True) -> str:
    """Write ``<results_dir>/<name>.json`` (through a temporary file, so a kill leaves the old one); return its path.

    When ``data`` has an ``environment`` the load average at writing time is added beside the one at
    the start (how busy the shared machine was), unless ``end_load`` is False (a result re-derived from a
    stored run keeps its run's record). No inf or NaN is written: a non-finite number becomes null
    with its reason under ``<key>_null`` (:func:`~mpm_warp.finite_json.finite_json`).
    """
    if end_load and isinstance(data.get("environment"), dict):
        data["environment"]["load_average_at_end_1_5_15_min"] = list(os.getloadavg())
    os.makedirs(results_dir, exist_ok=True)
    path = os.path.join(results_dir, name + ".json")
    with open(path + ".tmp", "w") as fh:
        dump_finite(data, fh, indent=1, default=float)
        fh.write("\n")
    os.replace(path + ".tmp", path)
    return path
