"""Checkpoints: the whole state of a run, written atomically (temporary file, fsync, ``os.replace``) and
verified by a SHA-256 checksum when read.

The HDF5 file is built in memory (h5py's core driver, no backing store) and written with plain
``os.write`` calls: HDF5 never writes to the disk itself, so a full disk is one clean ``OSError``
(:class:`~mpm_warp.io.space.OutOfSpace`), never HDF5 failing half-way through closing its objects
(which crashed the process: h5py closing a dataset whose flush had failed). The image costs one
extra copy of the state in host memory while it is written.
"""

from __future__ import annotations

import hashlib
import json
import os
import uuid

import h5py
import numpy as np

from ..errors import OutputError
from .hdf5 import CHECKPOINT_FORMAT, FORMAT_VERSION, check_format, now, to_json
from .opening import DamagedFile, open_read, reading
from .space import as_out_of_space, ensure_space, write_image

__all__ = ["checkpoint_path_for", "write_checkpoint", "read_checkpoint", "read_checkpoint_meta", "checkpoint_digest",
           "checkpoint_is_intact"]


def checkpoint_path_for(run_path) -> str:
    """Checkpoint file of a run: ``run.h5`` -> ``run.ckpt.h5``."""
    base, ext = os.path.splitext(os.fspath(run_path))
    return (base if ext.lower() in (".h5", ".hdf5", ".hdf") else base + ext) + ".ckpt.h5"


def checkpoint_digest(arrays: dict[str, np.ndarray], meta_json: str) -> str:
    """SHA-256 (hex) over the meta text and every array's name, dtype, shape and bytes, in name order."""
    h = hashlib.sha256(meta_json.encode())
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(f"\0{name}\0{a.dtype.str}\0{a.shape}\0".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _fsync(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _image(arrays: dict[str, np.ndarray], meta_json: str) -> bytes:
    """The checkpoint file's bytes, built in memory."""
    f = h5py.File(f"mpm_warp-checkpoint-{uuid.uuid4().hex}.h5", "w", driver="core", backing_store=False)
    try:
        f.attrs.update(format=CHECKPOINT_FORMAT, format_version=FORMAT_VERSION, created=now(), meta=meta_json,
                       sha256=checkpoint_digest(arrays, meta_json))
        for name, a in arrays.items():
            f.create_dataset(name, data=a)
        f.flush()
        return f.id.get_file_image()
    finally:
        f.close()


def write_checkpoint(path, arrays: dict[str, np.ndarray], meta: dict) -> None:
    """Write the full state atomically: a temporary file, fsync, then ``os.replace``.

    A process killed mid-write, or a full disk, leaves the previous checkpoint intact and no
    temporary file; the lack of space raises :class:`~mpm_warp.io.space.OutOfSpace`. The file
    carries the SHA-256 of its arrays and meta (attribute ``sha256``, :func:`checkpoint_digest`).

    Parameters
    ----------
    path : str or os.PathLike
    arrays : dict of str -> ndarray
        State arrays, stored uncompressed (speed) under their names ('/' makes groups).
    meta : dict
        JSON-serialisable description (step, time, frames written, scenario, ...).
    """
    path = os.fspath(path)
    tmp = path + ".tmp"
    arrays = {name: np.asarray(a) for name, a in arrays.items()}
    image = _image(arrays, to_json(meta))
    try:
        ensure_space(path, len(image), "the checkpoint")
        write_image(tmp, image)
        os.replace(tmp, path)
    except BaseException as e:
        if os.path.lexists(tmp):
            os.remove(tmp)
        err = as_out_of_space(e, path, "the checkpoint")
        if err is e:
            raise
        raise err from None
    try:                                      # make the rename durable too
        _fsync(os.path.dirname(os.path.abspath(path)))
    except OSError:                           # directories cannot be fsynced everywhere
        pass


def _corrupt(path: str, why: str) -> OutputError:
    return OutputError(f"{path}: checkpoint is corrupt ({why}); it cannot be resumed from (the run file's complete "
                       "frames are not affected)")


def read_checkpoint(path) -> tuple[dict[str, np.ndarray], dict]:
    """Read and verify a checkpoint: ``(arrays by name, meta)``; raises :class:`OutputError`.

    A checkpoint whose arrays or meta do not match its SHA-256 is refused ("checkpoint is corrupt
    (checksum mismatch)"); checkpoints written before the checksum existed are read unverified.
    """
    path = os.fspath(path)
    arrays = {}
    try:
        with open_read(path, swmr=False) as f, reading(path, "its arrays"):
            check_format(f, CHECKPOINT_FORMAT)
            f.visititems(lambda name, obj: arrays.__setitem__(name, obj[()])
                         if isinstance(obj, h5py.Dataset) else None)
            meta_json, digest = f.attrs["meta"], f.attrs.get("sha256")
    except DamagedFile as e:
        raise _corrupt(path, str(e).split(": ", 1)[1]) from None
    if digest is not None and checkpoint_digest(arrays, meta_json) != digest:
        raise _corrupt(path, "checksum mismatch")
    try:
        return arrays, json.loads(meta_json)
    except ValueError:
        raise _corrupt(path, "its meta is not JSON") from None


def read_checkpoint_meta(path) -> dict:
    """The ``meta`` of a checkpoint alone (no arrays read, not verified); raises :class:`OutputError`."""
    path = os.fspath(path)
    try:
        with open_read(path, swmr=False) as f, reading(path, "its meta"):
            check_format(f, CHECKPOINT_FORMAT)
            return json.loads(f.attrs["meta"])
    except DamagedFile as e:
        raise _corrupt(path, str(e).split(": ", 1)[1]) from None


def checkpoint_is_intact(path) -> bool:
    """Whether ``path`` is a checkpoint that reads and matches its checksum."""
    try:
        read_checkpoint(path)
    except OutputError:
        return False
    return True
