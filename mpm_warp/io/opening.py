"""Opening run files and checkpoints for reading, so that a damaged file fails at once instead of hanging.

A plain (non-SWMR) HDF5 open verifies every metadata checksum and fails at once on a flipped
or missing byte. An SWMR open instead retries a metadata read whose checksum fails (a writer
may be half-way through it) and on a damaged file never returns. So a file is opened plainly
unless it is *live* (another process holds its lock, :func:`mpm_warp.io.lock.is_live`), or
its writer died without closing it (plain HDF5 then refuses it: "already open for write");
only these two open in SWMR mode, and only after a time-boxed probe in a child process has
opened the file and walked all of its metadata (every object, attribute and chunk index, and
the small series). A probe that does not finish within :data:`open_timeout` seconds is
killed and the file reported damaged. Tested with bytes flipped at many offsets and with
truncated files (``tests/test_damaged_files.py``).
"""

from __future__ import annotations

import os
import stat
import subprocess
import sys

import h5py

from ..errors import MPMError, OutputError
from .lock import is_live

__all__ = ["open_read", "open_timeout", "reading", "DamagedFile"]


class DamagedFile(OutputError):
    """A file that exists but cannot be read: flipped or missing bytes, not HDF5 at all."""

#: child process that opens a file in SWMR mode and touches all of its metadata; exit 0 when it can
_PROBE = r"""
import sys, h5py
def visit(name, obj):
    dict(obj.attrs)
    if isinstance(obj, h5py.Dataset):
        if obj.chunks:
            obj.id.get_num_chunks()
        if obj.size * obj.dtype.itemsize <= 1 << 20:
            obj[()]
try:
    with h5py.File(sys.argv[1], "r", swmr=True) as f:
        dict(f.attrs)
        f.visititems(visit)
except Exception as e:
    sys.stderr.write(f"{type(e).__name__}: {e}\n")
    sys.exit(1)
"""


def open_timeout() -> float:
    """Seconds an SWMR probe may take (``MPM_WARP_OPEN_TIMEOUT``, default 10)."""
    try:
        return max(0.1, float(os.environ.get("MPM_WARP_OPEN_TIMEOUT", "10")))
    except ValueError:
        return 10.0


def _probe_swmr(path: str) -> None:
    timeout = open_timeout()
    try:
        p = subprocess.run([sys.executable, "-c", _PROBE, path], capture_output=True, text=True, timeout=timeout,
                           stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise DamagedFile(f"{path}: damaged (its metadata could not be read within {timeout:g} s; the file was "
                          "not closed by its writer, so only an SWMR open reads it, and that retries a damaged "
                          "block for ever)") from None
    if p.returncode != 0:
        reason = (p.stderr.strip().splitlines() or [f"exit status {p.returncode}"])[-1]
        raise DamagedFile(f"{path}: damaged or not an HDF5 file ({reason})")


def open_read(path, swmr: bool | None = None, probed: bool = False) -> h5py.File:
    """Open a run file or checkpoint read-only without hanging; raises :class:`OutputError`.

    Parameters
    ----------
    path : str or os.PathLike
    swmr : bool, optional
        None (default): plain open unless the file is live or was left open by a dead writer;
        False: plain open only (checkpoints, which are always closed); True: SWMR open.
    probed : bool
        The file was already probed by an SWMR open of this process (skip the child process).
    """
    path = os.fspath(path)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise OutputError(f"{path}: no such file") from None
    except OSError as e:
        raise OutputError(f"{path}: cannot be read ({e.strerror})") from None
    if stat.S_ISDIR(mode):
        raise OutputError(f"{path}: is a directory, not a run file")
    if not stat.S_ISREG(mode):
        raise OutputError(f"{path}: is not a regular file")
    plain_only = swmr is False
    if swmr is None:
        swmr = is_live(path)
    if not swmr:
        try:
            return h5py.File(path, "r")
        except OSError as e:
            if plain_only or "already open for write" not in str(e):
                raise DamagedFile(f"{path}: damaged or not a readable HDF5 file ({_reason(e)})") from None
    if not probed:
        _probe_swmr(path)
    try:
        return h5py.File(path, "r", swmr=True)
    except OSError as e:
        raise DamagedFile(f"{path}: damaged or not a readable HDF5 file ({_reason(e)})") from None


def _reason(e: BaseException) -> str:
    s = str(e)
    return s[s.find("(") + 1:s.rfind(")")] if "(" in s and s.endswith(")") else s


class reading:
    """Context manager that turns the errors of reading a damaged file into one :class:`OutputError` line.

    ``with reading(path, "frame 3"): ...``: h5py's OSError/RuntimeError/KeyError, JSON or
    decoding errors and the TypeError/AttributeError of an unreadable object become
    ``DamagedFile("<path>: damaged (<what>: <reason>)")``; errors of mpm_warp (already clear) pass through.
    """

    def __init__(self, path, what: str = "reading"):
        self.path, self.what = os.fspath(path), what

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        # TypeError/AttributeError: h5py hands back None for an object whose header cannot be read
        if exc is None or isinstance(exc, MPMError) or not isinstance(exc, (OSError, RuntimeError, KeyError,
                                                                          ValueError, TypeError, AttributeError)):
            return False
        raise DamagedFile(f"{self.path}: damaged ({self.what}: {_reason(exc)})") from None
