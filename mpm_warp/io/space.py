"""A full disk: free space checked before each write, and the one error it becomes (:class:`OutOfSpace`).

A write refused for lack of space (``ENOSPC``), a quota (``EDQUOT``) or a file-size limit (``EFBIG``)
raises :class:`OutOfSpace`, an :class:`~mpm_warp.errors.OutputError` naming the file and what was
being written, whether it came from the operating system (``OSError``) or from HDF5 (h5py's
``RuntimeError`` text carries ``errno = 28``). Writers check the free space before they start
(:func:`ensure_space`), so that on a disk that fills up the common case never reaches HDF5 half-way
through an object; :func:`atomic_write` writes small files aside and moves them in place, leaving no
temporary behind.
"""

from __future__ import annotations

import errno
import os
import re
from collections.abc import Callable

from ..errors import OutputError

__all__ = ["SPACE_ERRNOS", "OutOfSpace", "space_errno", "free_bytes", "ensure_space", "atomic_write", "as_out_of_space",
           "write_image"]

#: the errors of a write that found no room: no space on the device, quota exceeded, file too large
SPACE_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)
_HDF5_ERRNO = re.compile(r"errno = (\d+)")


class OutOfSpace(OutputError):
    """A write found no room. Attributes: ``path`` (the file), ``errno``, ``what`` (what was being written)."""

    def __init__(self, path: str, err: int, what: str, detail: str = ""):
        super().__init__(f"{path}: {os.strerror(err)} (errno {errno.errorcode.get(err, err)}) while writing {what}"
                         + (f": {detail}" if detail else ""))
        self.path, self.errno, self.what = path, err, what


def space_errno(exc: BaseException) -> int | None:
    """The errno of ``exc`` when it is a write that found no room (:data:`SPACE_ERRNOS`), else None."""
    if isinstance(exc, OutOfSpace):
        return exc.errno
    if isinstance(exc, OSError) and exc.errno in SPACE_ERRNOS:
        return exc.errno
    if isinstance(exc, (OSError, RuntimeError)):          # h5py: "... errno = 28, error message = ..."
        m = _HDF5_ERRNO.search(str(exc))
        if m and int(m.group(1)) in SPACE_ERRNOS:
            return int(m.group(1))
    return None


def as_out_of_space(exc: BaseException, path: str, what: str) -> BaseException:
    """``exc`` as an :class:`OutOfSpace` when it is one (:func:`space_errno`), else ``exc`` itself."""
    err = space_errno(exc)
    if err is None or isinstance(exc, OutOfSpace):
        return exc
    return OutOfSpace(path, err, what)


def free_bytes(path: str) -> int:
    """Bytes an unprivileged writer may still put on the file system of ``path`` (its folder if it does not exist)."""
    folder = path if os.path.isdir(path) else os.path.dirname(os.path.abspath(path))
    st = os.statvfs(folder)
    return st.f_bavail * st.f_frsize


def ensure_space(path: str, nbytes: int, what: str) -> None:
    """Raise :class:`OutOfSpace` before writing ``nbytes`` to ``path`` when its file system has less free."""
    try:
        free = free_bytes(path)
    except OSError:                                        # cannot tell (e.g. a file system without statvfs)
        return
    if free < nbytes:
        raise OutOfSpace(path, errno.ENOSPC, what, f"needs {_mib(nbytes)}, {_mib(free)} free")


def _mib(n: float) -> str:
    return f"{n / 2**20:.3g} MiB"


def atomic_write(path: str, write: Callable[[str], None], what: str) -> str:
    """Write ``path`` aside (``write(tmp)``), then move it in place; on any failure the temporary is removed
    and a lack of space becomes :class:`OutOfSpace`. Returns ``path``."""
    tmp = f"{path}.{os.getpid()}.tmp"
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException as e:
        if os.path.lexists(tmp):
            os.remove(tmp)
        err = as_out_of_space(e, path, what)
        if err is e:
            raise
        raise err from None
    return path


def write_image(path: str, data: bytes) -> None:
    """Write ``data`` (a file built in memory) to a new file ``path`` with plain writes, then fsync it."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    try:
        view, done = memoryview(data), 0
        while done < len(view):
            done += os.write(fd, view[done:done + (1 << 26)])
        os.fsync(fd)
    finally:
        os.close(fd)
