"""Writing HDF5 run files, frame by frame and crash-safe (NumPy and h5py only; no Warp).

Run file layout (``format = "mpm_warp-run"``, ``format_version = 1``)::

    /                    attrs: format, format_version, created (ISO 8601, UTC), n_particles,
                         units, versions, scenario, resumed, ... (dicts and lists as JSON text,
                         their names listed in the ``json_attrs`` attribute)
    /time                (n_frames,) float64 [s]
    /step                (n_frames,) int64 [1]
    /particles/<name>    (n_frames, N, *shape), declared dtype; chunk = one frame, compressed
    /static/<name>       (N, *shape), per-particle constants written once
    /walls/forces        (n_frames, n_walls, 3) float64 [N]; attr ``names`` (JSON list)
    /scalars/<name>      (n_frames,) float64, e.g. kinetic and elastic energy [J]

Every dataset has a ``unit`` attribute and the Fletcher-32 checksum filter of HDF5 (a flipped
byte in any frame fails its read instead of giving a wrong number). Compression of particle
data: ``"gzip"`` = shuffle + gzip level 1 (any HDF5 tool reads it; level 4 was no smaller and
10-30 % slower), ``"lzf"`` = shuffle + LZF (about 3.5x faster to write, ~10 % larger, an
h5py-only filter), ``"none"``.

Crash safety (docs/robustness.md, "How files are kept safe")
-------------------------------------------------------------
Superblock v3, SWMR writes (HDF5 orders its metadata so that any prefix of the writes is a
consistent file), 4 KiB paged aggregation, one chunk per particle frame; a frame is complete
when every per-frame dataset holds its row (readers take ``min(lengths)``). A new or rebuilt
file is written aside (``<path>.part``, its layout built in memory) and renamed over ``path``.
Free space is checked before each frame; a write that finds no room raises
:class:`~mpm_warp.io.space.OutOfSpace` and leaves the complete frames readable.
"""

from __future__ import annotations

import contextlib
import json
import os

import h5py
import numpy as np

from ..errors import InvalidArgument, OutputError
from .hdf5 import (
    COMPRESSION,
    FORMAT,
    LIBVER,
    OUTCOME_BYTES,
    PAGE,
    RESERVED_ATTRS,
    check_format,
    check_name,
    get_attrs,
    layout,
    now,
    open_read,
    pad_to_stored_eof,
    series_datasets,
)
from .layout import copy_chunks, skeleton
from .opening import reading
from .space import as_out_of_space, ensure_space, space_errno, write_image

__all__ = ["RunWriter"]

#: free space a write needs beyond its raw bytes and a page per dataset: HDF5's metadata pages (chunk indices,
#: object headers), bytes
_METADATA_MARGIN = 16 * PAGE


class RunWriter:
    """Writer of one run file, frame by frame; see the module docstring for layout and safety.

    Parameters
    ----------
    path : str or os.PathLike
        Run file to create (or to extend with ``append=True``).
    n_particles : int
        Number of particles N.
    particle_fields : dict
        ``name -> (per-particle shape, numpy dtype, unit)``, e.g. ``{"x": ((3,), "float32", "m")}``;
        only these fields are stored.
    static_fields : dict, optional
        ``name -> (array (N, ...), unit)``: per-particle constants written once.
    wall_names : sequence of str
        Walls whose reaction force [N] is stored per frame.
    scalar_series : dict, optional
        Per-frame scalars ``name -> unit``, e.g. ``{"kinetic_energy": "J"}``.
    attrs : dict, optional
        Run attributes (scenario, versions, device, precision, units, ...).
    compression : {"gzip", "lzf", "none"}
        Filter of the particle datasets.
    overwrite : bool
        Replace an existing file; if False an existing ``path`` raises :class:`OutputError`.
    append : bool
        Extend ``path`` if it exists; its layout must equal the one given (static fields,
        compression and the attributes already stored are kept).
    keep_frames : int, optional
        With ``append``: complete frames kept (default all), e.g. those of the checkpoint resumed.
    verify : bool
        With ``append``: read (decompress, checksum) every kept frame before copying it; a damaged one
        raises :class:`OutputError` and leaves the file as it was. False when the caller read them already.
    """

    def __init__(self, path, *, n_particles: int,
                 particle_fields: dict[str, tuple[tuple[int, ...], str, str]],
                 static_fields: dict[str, tuple[np.ndarray, str]] | None = None,
                 wall_names=(), scalar_series: dict[str, str] | None = None,
                 attrs: dict | None = None, compression: str = "gzip", overwrite: bool = True,
                 append: bool = False, keep_frames: int | None = None, verify: bool = True):
        self.path, self._f, self._verify = os.fspath(path), None, verify
        for name, value in (("overwrite", overwrite), ("append", append), ("verify", verify)):
            if not isinstance(value, bool):
                raise InvalidArgument(name, value, "True or False")
        if not isinstance(n_particles, (int, np.integer)) or n_particles < 1:
            raise InvalidArgument("n_particles", n_particles, "an integer >= 1")
        if compression not in COMPRESSION:
            raise InvalidArgument("compression", compression, f"one of {sorted(COMPRESSION)}")
        self.n_particles, self._fields = int(n_particles), {}
        for name, spec in particle_fields.items():
            check_name("particle_fields", name)
            try:
                shape, dtype, unit = spec
                self._fields[name] = (tuple(int(s) for s in shape), np.dtype(dtype), str(unit))
            except (TypeError, ValueError) as e:
                raise InvalidArgument(f"particle_fields[{name!r}]", spec,
                                      "(shape tuple, numpy dtype name, unit)") from e
            if self.n_particles * self._fields[name][1].itemsize * int(np.prod(shape)) >= 2**32:
                raise InvalidArgument(f"particle_fields[{name!r}]", spec, f"a frame under 4 GiB "
                                      f"(HDF5 chunk limit) for {n_particles} particles")
        self.wall_names = [str(w) for w in wall_names]
        self._scalars = {name: str(unit) for name, unit in (scalar_series or {}).items()}
        static = {}
        for name, (array, unit) in (static_fields or {}).items():
            check_name("static_fields", name)
            static[name] = (np.asarray(array), str(unit))
            if static[name][0].ndim < 1 or static[name][0].shape[0] != n_particles:
                raise InvalidArgument(f"static_fields[{name!r}].shape", static[name][0].shape,
                                      f"({n_particles}, ...)")
        for name in self._scalars:
            check_name("scalar_series", name)
        names = [*self._fields, *self._scalars, *static, "wall_forces"]
        if len(set(names)) < len(names):
            raise InvalidArgument("field names", names, "names unique across particle fields, "
                                  "scalars, static fields and 'wall_forces'")
        #: the most bytes one frame adds to the file (its rows uncompressed, and a page per dataset)
        rows = sum(self.n_particles * dt.itemsize * int(np.prod(sh)) for sh, dt, _ in self._fields.values())
        self._frame_bytes = rows + 8 * (len(self._scalars) + 2) + 24 * len(self.wall_names) \
            + PAGE * (len(self._fields) + len(self._scalars) + 3) + _METADATA_MARGIN
        self._failed, self._last_time = False, None
        attrs = dict(attrs or {})
        if RESERVED_ATTRS & attrs.keys():
            raise InvalidArgument("attrs keys", sorted(RESERVED_ATTRS & attrs.keys()),
                                  f"none of the reserved keys {sorted(RESERVED_ATTRS)}")
        if append and os.path.exists(self.path):
            self._f = self._resume(keep_frames, attrs)
        else:
            if os.path.exists(self.path) and not overwrite:
                raise OutputError(f"{self.path}: exists (pass overwrite=True to replace it)")
            self._f, self._n = self._build(static, attrs, compression), 0
        self._datasets = {d.name.lstrip("/"): d for d in series_datasets(self._f)}

    @classmethod
    def reopen(cls, path, *, keep_frames: int | None = None, attrs: dict | None = None,
               verify: bool = True) -> RunWriter:
        """Reopen a run (also one whose writer was killed) to append frames, e.g. to resume it.

        The layout is read from the file; ``keep_frames`` complete frames are kept (all if
        None) and, with ``verify``, read once (a damaged one raises); ``attrs`` are added to the
        stored attributes.
        """
        with open_read(path) as f:
            check_format(f, FORMAT)
            n_particles, fields, walls, scalars = layout(f)
        return cls(path, n_particles=n_particles, particle_fields=fields, wall_names=walls,
                   scalar_series=scalars, attrs=attrs, append=True, keep_frames=keep_frames, verify=verify)

    def _resume(self, keep_frames, attrs) -> h5py.File:
        expected = (self.n_particles, {k: (s, d.str, u) for k, (s, d, u) in self._fields.items()},
                    self.wall_names, self._scalars)
        with open_read(self.path) as src:
            check_format(src, FORMAT)
            complete, found = min(d.shape[0] for d in series_datasets(src)), layout(src)
            if found != expected:
                raise InvalidArgument("layout (n_particles, particle_fields, wall_names, "
                                      "scalar_series)", expected, f"the layout of {self.path}: {found}")
            keep = complete if keep_frames is None else keep_frames
            if not isinstance(keep, (int, np.integer)) or not 0 <= keep <= complete:
                raise InvalidArgument("keep_frames", keep_frames, f"an integer in [0, {complete}]")
            old = get_attrs(src)
            resumed = old.pop("resumed", []) + [{"at": now(), "kept_frames": int(keep)}]
            attrs = {k: v for k, v in old.items() if k not in RESERVED_ATTRS} | attrs
            with reading(self.path, "its static fields"):
                static = {k: (d[()], d.attrs["unit"]) for k, d in src["static"].items()}
            first = next(iter(src["particles"].values()), None)
            compression = {"gzip": "gzip", "lzf": "lzf"}.get(getattr(first, "compression", 0), "none")
            f = self._build(static, {**attrs, "resumed": resumed}, compression, src, int(keep))
        self._n = int(keep)
        return f

    def _build(self, static, attrs, compression, src=None, keep=0) -> h5py.File:
        """Write the file aside, with the first ``keep`` frames of ``src`` if given, switch it to
        SWMR mode and move it over ``path``: a kill leaves the old file or the new one.

        Its layout (and the small series of the kept frames) is built in memory and written with
        plain writes (:func:`~mpm_warp.io.layout.skeleton`), so a full disk there is one clean error; HDF5 itself then
        writes only the kept particle frames, after a check that the space for them is free.
        """
        part = self.path + ".part"
        need = sum(a.nbytes for a, _ in static.values()) + self._frame_bytes + _METADATA_MARGIN   # and a first frame
        ensure_space(self.path, need + (os.path.getsize(self.path) if src and keep else 0),
                     "the run file" + (f" rebuilt with its {keep} frames" if src and keep else ""))
        f = None
        try:
            write_image(part, skeleton(self.path, self.n_particles, self._fields, self._scalars, self.wall_names,
                                        static, attrs, compression, src, keep))
            f = h5py.File(part, "r+", libver=LIBVER)
            if src and keep:
                for name in self._fields:
                    copy_chunks(self.path, src[f"particles/{name}"], f[f"particles/{name}"], keep, self._verify)
            f.swmr_mode = True                # flushes; from here on datasets only grow
            os.replace(part, self.path)
            return f
        except BaseException as e:
            if f is not None:
                try:
                    f.close()
                except Exception:             # a close that cannot flush (a full disk): the file is removed anyway
                    pass
            if os.path.lexists(part):
                os.remove(part)
            err = as_out_of_space(e, self.path, "the run file")
            if err is e:
                raise
            raise err from None

    @property
    def scalar_series(self) -> dict[str, str]:
        """The declared scalar series, name -> unit."""
        return dict(self._scalars)

    @property
    def n_frames(self) -> int:
        """Number of complete frames in the file."""
        return self._n

    def write_frame(self, time: float, step: int, particles: dict[str, np.ndarray],
                    wall_forces: np.ndarray | None = None,
                    scalars: dict[str, float] | None = None) -> int:
        """Append one frame, whole or not at all, and flush it to the file.

        Parameters
        ----------
        time : float
            Simulated time [s].
        step : int
            Step number.
        particles : dict
            Every declared particle field, ``name -> array (N, *shape)`` (cast to its dtype).
        wall_forces : ndarray, optional
            Reaction forces ``(n_walls, 3)`` [N]; required when walls were declared.
        scalars : dict, optional
            Every declared scalar series, ``name -> value``.

        Returns
        -------
        int
            Index of the frame written.
        """
        if self._f is None:
            raise OutputError(f"{self.path}: writer is closed")
        time = float(time)
        if not np.isfinite(time):
            raise InvalidArgument("time", time, "a finite number of seconds")
        if particles.keys() != self._fields.keys():
            raise InvalidArgument("particles (field names)", sorted(particles),
                                  f"exactly the declared fields {sorted(self._fields)}")
        rows = {}
        for name, (shape, dtype, _) in self._fields.items():
            a = np.asarray(particles[name])
            if a.shape != (self.n_particles, *shape):
                raise InvalidArgument(f"particles[{name!r}].shape", a.shape, str((self.n_particles, *shape)))
            if not np.can_cast(a.dtype, dtype, "same_kind"):
                raise InvalidArgument(f"particles[{name!r}].dtype", a.dtype.name, f"castable to {dtype}")
            rows[f"particles/{name}"] = a.astype(dtype, copy=False)
        scalars = dict(scalars or {})
        if scalars.keys() != self._scalars.keys():
            raise InvalidArgument("scalars (names)", sorted(scalars),
                                  f"exactly the declared series {sorted(self._scalars)}")
        rows.update({f"scalars/{k}": float(v) for k, v in scalars.items()})
        if self.wall_names:
            w = None if wall_forces is None else np.asarray(wall_forces, dtype=float)
            if w is None or w.shape != (len(self.wall_names), 3):
                raise InvalidArgument("wall_forces.shape", None if w is None else w.shape,
                                      str((len(self.wall_names), 3)))
            rows["walls/forces"] = w
        rows["step"], rows["time"] = int(step), time          # time is written last
        n = self._n
        if self._failed:
            raise OutputError(f"{self.path}: a write failed before; the writer holds {n} complete frames and "
                              "writes no more")
        ensure_space(self.path, self._frame_bytes, f"frame {n}")
        try:
            for name, value in rows.items():
                self._datasets[name].resize(n + 1, axis=0)
                self._datasets[name][n] = value
            self._f.flush()
        except Exception as e:
            err = as_out_of_space(e, self.path, f"frame {n}")
            if err is e:
                raise
            self._failed = True
            err.frames, err.last_time = n, self._last_time
            raise err from None
        self._n, self._last_time = n + 1, time
        return n

    def set_outcome(self, outcome: dict) -> None:
        """Store how the run ended (JSON of at most :data:`~mpm_warp.io.hdf5.OUTCOME_BYTES` bytes) in the root
        ``outcome`` attribute, rewritten in place; read back by :attr:`mpm_warp.io.RunData.attrs`."""
        text = json.dumps(outcome, allow_nan=True, default=float).encode()
        if len(text) > OUTCOME_BYTES:
            raise InvalidArgument("outcome", f"{len(text)} bytes of JSON", f"at most {OUTCOME_BYTES} bytes")
        self._f.attrs.modify("outcome", np.bytes_(text.ljust(OUTCOME_BYTES)))
        self._f.flush()

    def close(self) -> None:
        """Trim a partly written frame (left by an exception) and close the file.

        After a write that found no room the trim and the close's flush may fail too: they are
        given up quietly (readers take the complete frames, ``min`` of the lengths, either way).
        """
        if self._f is None:
            return
        f, self._f, trim_error = self._f, None, None
        try:
            for d in self._datasets.values():
                if d.shape[0] != self._n:
                    d.resize(self._n, axis=0)
        except BaseException as e:
            trim_error = e
        try:
            f.close()
        except Exception as e:
            if not (self._failed or space_errno(e)):
                raise
        if self._failed:                      # a flush that found no room may have left the file short of its end
            with contextlib.suppress(OSError):
                pad_to_stored_eof(self.path)
        if trim_error is not None and not (self._failed or space_errno(trim_error)):
            raise trim_error

    def __enter__(self) -> RunWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

