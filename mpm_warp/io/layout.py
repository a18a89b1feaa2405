"""The layout of a run file, built in memory (:func:`skeleton`), and the copy of kept particle frames into it.

The skeleton holds every dataset (``keep`` frames long), the attributes, the static fields and the
small series of the kept frames; it is written to disk with plain writes
(:func:`~mpm_warp.io.space.write_image`), so HDF5 never meets a full disk while it builds a file.
"""

from __future__ import annotations

import json
import uuid

import h5py
import numpy as np

from .hdf5 import COMPRESSION, FORMAT, FORMAT_VERSION, LIBVER, OUTCOME_BYTES, PAGE, now, series_chunk, set_attrs
from .opening import reading

__all__ = ["skeleton", "copy_chunks"]


def skeleton(path: str, n_particles: int, fields: dict, scalars: dict, wall_names: list, static: dict, attrs: dict,
             compression: str, src=None, keep: int = 0) -> bytes:
    """The new file's bytes, built in memory: every dataset (``keep`` frames long), the static fields and,
    from ``src``, the kept frames of every series but the particle fields (:func:`copy_chunks` writes those)."""
    f = h5py.File(f"{path}.skeleton-{uuid.uuid4().hex}", "w", driver="core", backing_store=False,
                  libver=LIBVER, fs_strategy="page", fs_page_size=PAGE)
    try:
        f.attrs.update(format=FORMAT, format_version=FORMAT_VERSION, n_particles=n_particles,
                       created=src.attrs["created"] if src else now())
        versions = {"h5py": h5py.__version__, "hdf5": h5py.version.hdf5_version,
                    "numpy": np.__version__} | (attrs.get("versions") or {})
        units = {"length": "m", "time": "s", "mass": "kg", "force": "N", "energy": "J"}
        set_attrs(f, {**attrs, "versions": versions, "units": units | (attrs.get("units") or {})})
        f.attrs.create("outcome", np.bytes_(b"{}".ljust(OUTCOME_BYTES)), dtype=f"S{OUTCOME_BYTES}")
        n, filt = n_particles, COMPRESSION[compression]

        def series(name, dtype, unit, shape=(), chunk=None, **kw):
            chunk = chunk or series_chunk(np.dtype(dtype).itemsize * int(np.prod(shape)))
            d = f.create_dataset(name, shape=(keep, *shape), maxshape=(None, *shape), dtype=dtype,
                                 chunks=(chunk, *shape), fletcher32=True, **kw)
            d.attrs["unit"] = unit
            if src and keep and not name.startswith("particles/"):
                with reading(path, f"{name}, in the {keep} frames the resume keeps"):
                    for i in range(0, keep, chunk):
                        d[i:i + chunk] = src[name][i:min(i + chunk, keep)]
            return d

        series("time", "f8", "s")
        series("step", "i8", "1")
        f.create_group("particles", track_order=True)
        for name, (shape, dtype, unit) in fields.items():
            series(f"particles/{name}", dtype, unit, (n, *shape), chunk=1, **filt)
        f.create_group("static", track_order=True)
        for name, (array, unit) in static.items():
            f.create_dataset(f"static/{name}", data=array, fletcher32=True, **filt).attrs["unit"] = unit
        f.create_group("scalars", track_order=True)
        for name, unit in scalars.items():
            series(f"scalars/{name}", "f8", unit)
        if wall_names:
            series("walls/forces", "f8", "N", (len(wall_names), 3)).attrs["names"] = \
                json.dumps(wall_names)
        f.flush()
        return f.id.get_file_image()
    finally:
        f.close()


def copy_chunks(path: str, s: h5py.Dataset, d: h5py.Dataset, keep: int, verify: bool = True) -> None:
    """The first ``keep`` frames of particle dataset ``s`` into ``d`` (same layout: raw compressed chunks, each
    read once first when ``verify``, so that its checksum is checked)."""
    with reading(path, f"{s.name.lstrip('/')}, in the {keep} frames the resume keeps"):
        if s.chunks == d.chunks and (s.compression, s.shuffle, s.fletcher32) == \
                (d.compression, d.shuffle, d.fletcher32):
            for i in range(s.id.get_num_chunks()):
                info = s.id.get_chunk_info(i)
                if info.chunk_offset[0] < keep:
                    if verify:
                        s[info.chunk_offset[0]]          # decompress: the checksum is checked
                    raw = s.id.read_direct_chunk(info.chunk_offset)[1]
                    d.id.write_direct_chunk(info.chunk_offset, raw, info.filter_mask)
        else:
            for i in range(keep):
                d[i] = s[i]
