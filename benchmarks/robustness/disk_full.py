"""A full disk, for real: runs of the elastic block into small file systems, each then resumed and compared.

Three ways of running out of room, each swept over its size or write index:

- ``tmpfs``: a tmpfs of S KiB mounted for the run (needs root and ``mount``), then remounted 64 MiB
  ("space freed") for the resume;
- ``fsize``: a file-size limit (``RLIMIT_FSIZE``) of S KiB on every file, lifted for the resume;
- ``strace``: ``ENOSPC`` injected by strace into the K-th ``pwrite64`` (HDF5's writes).

Every run must end with exit status 2 and one line on stderr (never 139, a traceback or a hang), leave no
``.tmp``/``.part``/``.lock``, and, when a checkpoint exists, ``mpm-warp resume`` must complete and equal
the uninterrupted run bit for bit (CPU); without one, the line must say to run again (or that nothing
was written: the lock file itself found no room). Writes
``benchmarks/robustness/results/disk_full.json``.

Usage::

    sudo .venv/bin/python benchmarks/robustness/disk_full.py          # all three where the machine allows them
    .venv/bin/python benchmarks/robustness/disk_full.py --quick       # a few sizes of each, to a temporary folder
"""

from __future__ import annotations

import datetime
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

import mpm_warp as mw
from mpm_warp.studies.environment import environment, write_json
from mpm_warp.studies.protocol import out_dir, parser

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")

SETS = ["time.end=0.05", "time.frame_interval=0.005", "output.checkpoint_every=3"]
LIMITED = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), int(sys.argv[1])))
from mpm_warp.cli import main
sys.exit(main(sys.argv[2:]))
"""
CLI = [sys.executable, "-m", "mpm_warp.cli"]


def _run_args(out: str) -> list[str]:
    return ["run", "elastic_block", "--out", out, "--quiet", "--device", "cpu",
            *[a for s in SETS for a in ("--set", s)]]


def _same(a: str, b: str) -> bool:
    ra, rb = mw.read_run(a), mw.read_run(b)
    return ra.n_frames == rb.n_frames and np.array_equal(ra.times, rb.times) and all(
        np.array_equal(ra.frame(k)[n], rb.frame(k)[n]) for k in range(ra.n_frames) for n in ra.particle_fields) \
        and np.array_equal(ra.wall_forces, rb.wall_forces)


def _case(kind: str, size, p, folder: str, ref: str, resume_cmd) -> dict:
    err = [ln for ln in p.stderr.splitlines() if "CUDA" not in ln]
    left = sorted(f for f in os.listdir(folder) if f.endswith((".tmp", ".part", ".lock")))
    out = os.path.join(folder, "r.h5")
    rec = dict(kind=kind, size=size, rc=p.returncode, lines=len(err), line=err[-1] if err else "", leftovers=left)
    if os.path.exists(mw.io.checkpoint_path_for(out)):
        r = resume_cmd()
        rec["resume_rc"] = r.returncode
        rec["bit_for_bit"] = r.returncode == 0 and _same(ref, out)
    else:
        rec["resume_rc"], rec["bit_for_bit"] = None, None
    rec["ok"] = (rec["rc"] == 2 and rec["lines"] == 1 and not left
                 and (rec["bit_for_bit"] is True or (rec["bit_for_bit"] is None and (
                     "run again" in rec["line"] or "nothing was written" in rec["line"]))))
    print(f"{kind:6s} {size!s:>6s}: rc {rec['rc']} lines {rec['lines']} left {left} resume {rec['resume_rc']} "
          f"bit-for-bit {rec['bit_for_bit']} | {rec['line'][:150]}", flush=True)
    return rec


def tmpfs_sweep(sizes_kib, ref) -> list[dict]:
    out = []
    for kib in sizes_kib:
        d = tempfile.mkdtemp(prefix="disk_full_")
        if subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={kib}k", "tmpfs", d]).returncode != 0:
            os.rmdir(d)
            return [{"kind": "tmpfs", "skipped": "mount refused"}]
        try:
            p = subprocess.run(CLI + _run_args(os.path.join(d, "r.h5")), capture_output=True, text=True, timeout=300)

            def resume(d=d):
                subprocess.run(["mount", "-o", "remount,size=64m", d], check=True)
                return _resume(d)

            out.append(_case("tmpfs", kib, p, d, ref, resume))
        finally:
            subprocess.run(["umount", d])
            os.rmdir(d)
    return out


def _resume(d: str) -> subprocess.CompletedProcess:
    """``mpm-warp resume`` of the run ``r.h5`` in the folder ``d`` on the CPU, its output captured."""
    return subprocess.run(CLI + ["resume", os.path.join(d, "r.h5"), "--quiet", "--device", "cpu"],
                          capture_output=True, text=True, timeout=300)


def fsize_sweep(sizes_kib, ref) -> list[dict]:
    out = []
    for kib in sizes_kib:
        d = tempfile.mkdtemp(prefix="disk_full_")
        try:
            p = subprocess.run([sys.executable, "-c", LIMITED, str(kib * 1024), *_run_args(os.path.join(d, "r.h5"))],
                               capture_output=True, text=True, timeout=300)
            out.append(_case("fsize", kib, p, d, ref, lambda d=d: _resume(d)))
        finally:
            shutil.rmtree(d)
    return out


def strace_sweep(indices, ref) -> list[dict]:
    if shutil.which("strace") is None:
        return [{"kind": "strace", "skipped": "no strace"}]
    out = []
    for k in indices:
        d = tempfile.mkdtemp(prefix="disk_full_")
        try:
            p = subprocess.run(["strace", "-f", "-qq", "-o", os.devnull, "-e", "trace=pwrite64", "-e",
                                f"inject=pwrite64:error=ENOSPC:when={k}", *CLI, *_run_args(os.path.join(d, "r.h5"))],
                               capture_output=True, text=True, timeout=300)
            if p.returncode == 0:                      # fewer pwrites than k: the run never met the fault
                out.append(dict(kind="strace", size=k, rc=0, note="finished before the K-th pwrite"))
                break
            out.append(_case("strace", k, p, d, ref, lambda d=d: _resume(d)))
        finally:
            shutil.rmtree(d)
    return out


def main(argv=None) -> None:
    a = parser(__doc__, "a few sizes of each").parse_args(argv)
    ref_dir = tempfile.mkdtemp(prefix="disk_full_ref_")
    ref = os.path.join(ref_dir, "r.h5")
    subprocess.run(CLI + _run_args(ref), check=True, capture_output=True)
    sizes = [72, 200, 264, 300, 420, 560, 640] if a.quick else list(range(72, 720, 24))
    fsizes = [8, 48, 96, 224, 320] if a.quick else [4, 16, 32, 48, 64, *range(80, 420, 16)]
    strace_k = [1, 5, 10, 20, 40] if a.quick else list(range(1, 200, 3))
    cases = tmpfs_sweep(sizes, ref) + fsize_sweep(fsizes, ref) + strace_sweep(strace_k, ref)
    done = [c for c in cases if "ok" in c]
    data = dict(what=__doc__.split("\n")[0], date=datetime.datetime.now().isoformat(timespec="seconds"),
                environment=environment("cpu"), scenario=["elastic_block", *SETS], cases=cases,
                summary={kind: dict(cases=sum(c.get("kind") == kind for c in done),
                                    ok=sum(c.get("kind") == kind and c["ok"] for c in done))
                         for kind in ("tmpfs", "fsize", "strace")})
    print(data["summary"])
    print(write_json("disk_full", data, out_dir(a, RESULTS, "disk_full")))
    shutil.rmtree(ref_dir)


if __name__ == "__main__":
    main()
