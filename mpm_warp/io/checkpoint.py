"""Checkpoints: the whole state of a run, written atomically (temporary file, fsync, ``os.replace``)."""

from __future__ import annotations

import json
import os

import h5py
import numpy as np

from .hdf5 import CHECKPOINT_FORMAT, FORMAT_VERSION, check_format, now, open_read, to_json

__all__ = ["checkpoint_path_for", "write_checkpoint", "read_checkpoint", "read_checkpoint_meta"]


def checkpoint_path_for(run_path) -> str:
    """Checkpoint file of a run: ``run.h5`` -> ``run.ckpt.h5``."""
    base, ext = os.path.splitext(os.fspath(run_path))
    return (base if ext.lower() in (".h5", ".hdf5", ".hdf") else base + ext) + ".ckpt.h5"


def _fsync(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_checkpoint(path, arrays: dict[str, np.ndarray], meta: dict) -> None:
    """Write the full state atomically: a temporary file, fsync, then ``os.replace``.

    A process killed mid-write leaves the previous checkpoint intact.

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
    try:
        with h5py.File(tmp, "w") as f:
            f.attrs.update(format=CHECKPOINT_FORMAT, format_version=FORMAT_VERSION, created=now(),
                           meta=to_json(meta))
            for name, a in arrays.items():
                f.create_dataset(name, data=np.asarray(a))
        _fsync(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
    try:                                      # make the rename durable too
        _fsync(os.path.dirname(os.path.abspath(path)))
    except OSError:                           # directories cannot be fsynced everywhere
        pass


def read_checkpoint(path) -> tuple[dict[str, np.ndarray], dict]:
    """Read a checkpoint: ``(arrays by name, meta)``; raises :class:`OutputError`."""
    arrays = {}
    with open_read(path) as f:
        check_format(f, CHECKPOINT_FORMAT)
        f.visititems(lambda name, obj: arrays.__setitem__(name, obj[()])
                     if isinstance(obj, h5py.Dataset) else None)
        return arrays, json.loads(f.attrs["meta"])


def read_checkpoint_meta(path) -> dict:
    """The ``meta`` of a checkpoint alone (no arrays read); raises :class:`OutputError`."""
    with open_read(path) as f:
        check_format(f, CHECKPOINT_FORMAT)
        return json.loads(f.attrs["meta"])
