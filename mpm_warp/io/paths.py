"""What may be written: output paths checked before any work, so that no file is ever clobbered by mistake.

A run file (and its checkpoint ``<run>.ckpt.h5``) may replace an existing regular file only
when asked (``overwrite``); a directory, a device node, a fifo or a socket, and the input
scenario, are never replaced. The folder must exist and be writable (tried by creating a
temporary file in it, which also catches read-only file systems and root on ``/sys``).
"""

from __future__ import annotations

import os
import stat
import tempfile

from ..errors import InvalidArgument, OutputError
from .checkpoint import checkpoint_path_for

__all__ = ["check_output_file", "check_output_dir"]


def _writable_dir(where: str, folder: str) -> None:
    if not os.path.exists(folder):
        raise OutputError(f"{where}: the folder {folder} does not exist")
    if not os.path.isdir(folder):
        raise OutputError(f"{where}: {folder} is not a folder")
    try:
        with tempfile.TemporaryFile(dir=folder, prefix=".mpm_warp-"):
            pass
    except OSError as e:
        raise OutputError(f"{where}: the folder {folder} is not writable ({e.strerror})") from None


def _same(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_output_file(path, *, overwrite: bool = False, inputs=(), append: bool = False) -> str:
    """Check that run file ``path`` may be written; return it as a ``str``. Raises :class:`OutputError`.

    Parameters
    ----------
    path : str or os.PathLike
        The run file; its checkpoint ``checkpoint_path_for(path)`` is checked too.
    overwrite : bool
        Allow replacing an existing regular run file (and its checkpoint).
    inputs : sequence of str
        Files the run reads (the scenario): never replaced, even with ``overwrite``.
    append : bool
        The run continues ``path`` (resume): it must exist.
    """
    for name, value in (("overwrite", overwrite), ("append", append)):
        if not isinstance(value, bool):
            raise InvalidArgument(name, value, "True or False")
    if not isinstance(path, (str, os.PathLike)):
        raise InvalidArgument("output", path, "a file path (str or os.PathLike)")
    path = os.fspath(path)
    if not isinstance(path, str):
        raise InvalidArgument("output", path, "a file path (str or os.PathLike of str)")
    if not path:
        raise OutputError("output: an empty file name")
    _writable_dir(path, os.path.dirname(os.path.abspath(path)))
    for p in (path, checkpoint_path_for(path)):
        if not os.path.lexists(p):
            continue
        try:
            mode = os.stat(p).st_mode
        except OSError as e:
            raise OutputError(f"{p}: cannot be examined ({e.strerror})") from None
        if stat.S_ISDIR(mode):
            raise OutputError(f"{p}: is a directory; give a file name")
        if not stat.S_ISREG(mode):
            raise OutputError(f"{p}: is not a regular file (a device, fifo or socket): never replaced, even with "
                              "overwrite")
        for src in inputs:
            if src and _same(p, src):
                raise OutputError(f"{p}: is the input scenario {src}: never replaced, even with overwrite")
    if append:
        if not os.path.exists(path):
            raise OutputError(f"{path}: no such file")
    elif os.path.exists(path) and not overwrite:
        raise OutputError(f"{path}: exists; pass --overwrite (overwrite=True) to replace it, or resume it with "
                          f"`mpm-warp resume {path}`")
    return path


def check_output_dir(path, where: str = "--out") -> str:
    """Check that the folder ``path`` can receive output files (it may be created: its parent must exist)."""
    path = os.fspath(path)
    if os.path.exists(path):
        if not os.path.isdir(path):
            raise OutputError(f"{where}: {path} exists and is not a folder")
        _writable_dir(where, path)
    else:
        _writable_dir(where, os.path.dirname(os.path.abspath(path)))
    return path
