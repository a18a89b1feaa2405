"""One writer per run file: an exclusive ``flock`` on ``<run>.lock``, taken before any work.

The lock file holds its holder (pid, host, start time) as JSON. The kernel drops an ``flock``
when its process dies, however it dies, so a lock file left by a killed run is *stale*: the
next run takes it over and says so (a ``logging`` warning of the ``mpm_warp`` logger). A
second run on a live output fails at once with :class:`OutputError` naming the holder.
Readers use :func:`is_live` to learn whether a writer holds the file (then it must be opened
in SWMR mode). Linux/POSIX only (``fcntl``); local file systems (``flock`` over NFS is not
reliable).
"""

from __future__ import annotations

import contextlib
import datetime
import fcntl
import json
import logging
import os
import signal
import socket
import threading
import time

from ..errors import OutputError

__all__ = ["output_lock", "is_live", "lock_path_for", "holder"]

log = logging.getLogger("mpm_warp")

#: locks held by this process: real path -> [fd, depth] (a nested output_lock of the same file is a no-op)
_HELD: dict[str, list] = {}
#: a reader probing the lock holds it shared for microseconds: a writer retries this long before giving up (s)
_RETRY_S = 0.25
#: the signals that stop a command-line run (mpm_warp.stop)
_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def _stop_signals_held():
    """Record SIGINT/SIGTERM for the block instead of handling them; yields the list of those received.

    Only the main thread runs Python's signal handlers (elsewhere the list stays empty); a handler Python did not
    install (``getsignal`` None) is left as it is.
    """
    got: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield got
        return
    old = {sig: h for sig in _STOP_SIGNALS if (h := signal.getsignal(sig)) is not None}
    for sig in old:
        signal.signal(sig, lambda signum, frame: got.append(signum))
    try:
        yield got
    finally:
        for sig, h in old.items():
            signal.signal(sig, h)


def lock_path_for(path) -> str:
    """The lock file of a run file: ``run.h5`` -> ``run.h5.lock``."""
    return os.fspath(path) + ".lock"


def _read_holder(fd: int) -> dict:
    try:
        os.lseek(fd, 0, os.SEEK_SET)
        info = json.loads(os.read(fd, 4096).decode() or "{}")
        return info if isinstance(info, dict) else {}
    except (OSError, ValueError):
        return {}


def _describe(info: dict) -> str:
    if not info:
        return "an unknown process"
    return f"pid {info.get('pid', '?')} on {info.get('host', '?')}, started {info.get('started', '?')}"


def _alive(info: dict) -> bool:
    """False only when the holder is known dead: a pid of this host that no longer exists."""
    if info.get("host") != socket.gethostname() or not isinstance(info.get("pid"), int):
        return True
    try:
        os.kill(info["pid"], 0)
    except ProcessLookupError:
        return False
    except OSError:
        pass
    return True


def holder(path) -> dict:
    """The holder recorded in ``path``'s lock file (``pid``, ``host``, ``started``), {} without one."""
    try:
        fd = os.open(lock_path_for(path), os.O_RDONLY)
    except OSError:
        return {}
    try:
        return _read_holder(fd)
    finally:
        os.close(fd)


def _acquire(path: str) -> int:
    lock = lock_path_for(path)
    deadline = time.monotonic() + _RETRY_S
    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as e:
            raise OutputError(f"{path}: cannot create its lock file {lock} ({e.strerror})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            info = _read_holder(fd)
            os.close(fd)
            if (info and _alive(info)) or time.monotonic() > deadline:
                raise OutputError(f"{path}: in use by another run ({_describe(info)}); wait for it to end or "
                                  f"choose another output") from None
            time.sleep(0.02)
            continue
        try:                                   # the file may have been unlinked by a holder releasing it
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)


@contextlib.contextmanager
def output_lock(path):
    """Hold the exclusive lock of run file ``path`` for the ``with`` block (re-entrant in one process).

    Raises :class:`OutputError` at once when another live process holds it; takes over the
    stale lock of a dead one with a warning. The lock file is removed on every way out of
    the block (a killed process leaves it behind, stale).
    """
    path = os.fspath(path)
    key = os.path.realpath(path)
    if key in _HELD:
        _HELD[key][1] += 1
        try:
            yield
        finally:
            _HELD[key][1] -= 1
        return
    with _stop_signals_held() as held:         # a signal between the lock file's creation and the block that
        fd = _acquire(path)                    # removes it would leave the file behind: it waits for that block
        try:
            old = _read_holder(fd)
            if old:
                log.warning("%s: taking over the stale lock of %s, which is no longer running", path,
                            _describe(old))
            me = {"pid": os.getpid(), "host": socket.gethostname(),
                  "started": datetime.datetime.now().astimezone().isoformat(timespec="seconds")}
            os.ftruncate(fd, 0)
            os.pwrite(fd, json.dumps(me).encode(), 0)
            _HELD[key] = [fd, 1]
        except BaseException as e:
            with contextlib.suppress(OSError):
                os.unlink(lock_path_for(path))
            os.close(fd)
            if isinstance(e, OSError) and not isinstance(e, OutputError):
                raise OutputError(f"{path}: cannot write its lock file {lock_path_for(path)} ({e.strerror}); "
                                  "nothing was written") from None
            raise
    try:
        for signum in held:                    # delivered now, to the handlers of before
            signal.raise_signal(signum)
        yield
    finally:
        del _HELD[key]
        with contextlib.suppress(OSError):
            os.unlink(lock_path_for(path))
        os.close(fd)                           # closing drops the flock


def is_live(path) -> bool:
    """Whether another process holds the lock of run file ``path`` (it is being written)."""
    path = os.fspath(path)
    if os.path.realpath(path) in _HELD:
        return False
    try:
        fd = os.open(lock_path_for(path), os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        return False
    except BlockingIOError:
        return True
    finally:
        os.close(fd)                           # also drops the shared lock
