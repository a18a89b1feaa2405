"""HDF5 helpers shared by run files and checkpoints: formats, attributes, safe opening (NumPy and h5py only)."""

from __future__ import annotations

import datetime
import json
import os

import h5py
import numpy as np

from ..errors import InvalidArgument, OutputError
from .opening import DamagedFile, open_read

__all__ = ["FORMAT", "FORMAT_VERSION", "CHECKPOINT_FORMAT", "now", "to_json", "set_attrs", "get_attrs", "open_read",
           "check_format", "series_datasets", "layout", "check_name", "LIBVER", "PAGE", "series_chunk",
           "RESERVED_ATTRS", "COMPRESSION", "pad_to_stored_eof", "stored_eof"]

FORMAT = "mpm_warp-run"
FORMAT_VERSION = 1
CHECKPOINT_FORMAT = "mpm_warp-checkpoint"
LIBVER = ("v110", "v110")
#: file-space page [bytes] of run files (HDF5 paged aggregation), the Linux page: an object smaller than a page
#: never straddles two, so rewriting it in place is one page-cache copy, which a SIGKILL cannot tear
PAGE = 4096


def series_chunk(row_bytes: int) -> int:
    """Frames per chunk of a small per-frame series: the most whose chunk, with its 4-byte Fletcher-32
    checksum, fits in one :data:`PAGE` (a chunk is rewritten in place at every frame until it is full)."""
    return max(1, (PAGE - 4) // max(1, int(row_bytes)))
RESERVED_ATTRS = {"format", "format_version", "created", "n_particles", "json_attrs", "outcome"}
#: bytes reserved for the ``outcome`` attribute (a fixed-size string rewritten in place when a run ends: within one
#: page, so a kill during that write cannot tear it across two)
OUTCOME_BYTES = 2048
COMPRESSION = {"gzip": dict(compression="gzip", compression_opts=1, shuffle=True),
                "lzf": dict(compression="lzf", shuffle=True), "none": {}}


def now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def to_json(value) -> str:
    def default(o):
        if isinstance(o, (np.generic, np.ndarray)):
            return o.tolist()
        raise TypeError(f"{type(o).__name__} is not JSON serialisable")
    return json.dumps(value, default=default)


def set_attrs(obj, attrs: dict) -> None:
    """Store ``attrs`` on an HDF5 object; dicts, lists, tuples and None go as JSON text."""
    as_json = set(json.loads(obj.attrs.get("json_attrs", "[]")))
    for key, value in attrs.items():
        is_json = isinstance(value, (dict, list, tuple)) or value is None
        obj.attrs[key] = to_json(value) if is_json else value
        (as_json.add if is_json else as_json.discard)(key)
    obj.attrs["json_attrs"] = json.dumps(sorted(as_json))


def get_attrs(obj) -> dict:
    as_json = set(json.loads(obj.attrs.get("json_attrs", "[]")))
    out = {k: json.loads(v) if k in as_json else v.item() if isinstance(v, np.generic) else v
           for k, v in obj.attrs.items() if k != "outcome"}
    out.pop("json_attrs", None)
    if "outcome" in obj.attrs:
        try:
            out["outcome"] = json.loads(bytes(obj.attrs["outcome"]).rstrip(b" \0").decode() or "{}")
        except (ValueError, UnicodeDecodeError):
            out["outcome"] = {}
    return out


def check_format(f: h5py.File, expected: str) -> None:
    fmt, version = f.attrs.get("format"), f.attrs.get("format_version")
    if fmt != expected:
        raise OutputError(f"{f.filename}: not an {expected} file (format attribute {fmt!r})")
    if version is None or int(version) > FORMAT_VERSION:
        raise OutputError(f"{f.filename}: format_version {version!r} is not supported "
                          f"(this library reads up to {FORMAT_VERSION})")


def series_datasets(f: h5py.File) -> list[h5py.Dataset]:
    """Every per-frame dataset, in the order they are written (``time`` last)."""
    for name in ("particles", "scalars", "step", "time"):
        if name not in f:
            raise OutputError(f"{f.filename}: incomplete run file (no /{name})")
    try:
        out = [*f["particles"].values(), *f["scalars"].values()]
        out += ([f["walls/forces"]] if "walls/forces" in f else []) + [f["step"], f["time"]]
    except KeyError as e:                         # the link exists, its object header does not read
        raise DamagedFile(f"{f.filename}: damaged ({e.args[0] if e.args else e})") from None
    if any(d is None for d in out):               # h5py's answer for an object whose header cannot be read
        raise DamagedFile(f"{f.filename}: damaged (the header of a per-frame dataset cannot be read)")
    return out


def layout(f: h5py.File) -> tuple:
    """``(n_particles, particle_fields, wall_names, scalar_series)`` of an open run file."""
    return (int(f.attrs["n_particles"]),
            {k: (d.shape[2:], d.dtype.str, d.attrs["unit"]) for k, d in f["particles"].items()},
            json.loads(f["walls/forces"].attrs["names"]) if "walls/forces" in f else [],
            {k: d.attrs["unit"] for k, d in f["scalars"].items()})


def check_name(kind: str, name: str) -> None:
    if not isinstance(name, str) or not name or "/" in name or name in (".", "time", "step"):
        raise InvalidArgument(kind, name, "a non-empty name without '/', not 'time' or 'step'")



def stored_eof(path: str) -> int | None:
    """The end-of-file address a run file's superblock records (versions 2 and 3, ``libver="v110"``), else None."""
    with open(path, "rb") as fh:
        head = fh.read(36)
    # superblock v2/v3: signature (8), version, sizes of offsets and lengths, flags, base, extension, EOF address
    if len(head) < 36 or head[:8] != b"\x89HDF\r\n\x1a\n" or head[8] not in (2, 3) or head[9] != 8:
        return None
    return int.from_bytes(head[28:36], "little")


def pad_to_stored_eof(path: str, check=None) -> int:
    """Extend a run file shorter than the end of file its superblock records, with a hole; return the bytes added.

    A write that found no room can leave the superblock's end-of-file address (updated by an SWMR
    flush) past the bytes that reached the disk; HDF5 then refuses the whole file ("truncated file").
    The missing bytes belong to the frame that failed, which is not complete: a hole of zeros in
    their place (no disk space on the usual file systems) makes the complete frames readable again.
    A file that then fails ``check(path)`` (default: it opens) is cut back to its own bytes: a file
    truncated by other means is left exactly as it was.
    """
    eof, size = stored_eof(path), os.path.getsize(path)
    if eof is None or size >= eof or eof - size > 1 << 34:   # not short, or an address no run file writes
        return 0
    os.truncate(path, eof)
    try:
        if check is None:
            with open_read(path):
                pass
        else:
            check(path)
    except (OSError, OutputError):
        os.truncate(path, size)
        return 0
    return eof - size
