"""HDF5 run files and checkpoints of mpm_warp (NumPy and h5py only; no Warp).

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

Every dataset has a ``unit`` attribute. Compression of particle data: ``"gzip"`` = shuffle +
gzip level 1 (any HDF5 tool reads it; level 4 was no smaller and 10-30 % slower), ``"lzf"`` =
shuffle + LZF (about 3.5x faster to write, ~10 % larger, an h5py-only filter), ``"none"``.

Crash safety: a frame is written whole or not at all
----------------------------------------------------
Files use superblock v3 (``libver="v110"``, read by HDF5 >= 1.10) and are written in SWMR
mode, in which HDF5 orders its metadata writes (flush dependencies) so that the file is
consistent after any prefix of them, and ``H5Fflush`` writes raw chunks before metadata.
:meth:`RunWriter.write_frame` checks every input, grows and fills each per-frame dataset
(``time`` last) and flushes. A frame is complete when every per-frame dataset holds its row;
readers take ``n_frames = min(lengths)``, so a kill between two dataset headers, or an
exception between two datasets, never shows a partial frame. A file is never touched outside
SWMR mode: it is built aside (``<path>.part``), switched to SWMR, then renamed over ``path``.
A killed writer (SIGKILL, default SIGTERM, OOM) leaves the superblock marked "open for write",
which plain HDF5 refuses ("use h5clear"); :func:`read_run` opens with ``swmr=True``, which reads
it (and runs still being written). SIGINT raises ``KeyboardInterrupt`` between HDF5 calls and
``__exit__`` closes the file cleanly. :meth:`RunWriter.reopen` (resume) copies the kept frames
chunk by chunk (raw bytes, no recompression) into a rebuilt file that replaces the old one, so a
kill during resume leaves the old file or the new one. Verified by killing a writer (strace
fault injection) at every one of its ``pwrite`` calls. Protected: death of the process. Not
protected: power loss (no fsync per frame), network file systems (no SWMR write ordering).
"""

from __future__ import annotations

import datetime
import json
import os

import h5py
import numpy as np

from .errors import InvalidArgument, OutputError

__all__ = ["FORMAT", "FORMAT_VERSION", "CHECKPOINT_FORMAT", "RunWriter", "RunData", "read_run",
           "write_checkpoint", "read_checkpoint", "checkpoint_path_for"]

FORMAT = "mpm_warp-run"
FORMAT_VERSION = 1
CHECKPOINT_FORMAT = "mpm_warp-checkpoint"
_LIBVER = ("v110", "v110")
_SERIES_CHUNK = 256                       # frames per chunk of the small per-frame series
_RESERVED_ATTRS = {"format", "format_version", "created", "n_particles", "json_attrs"}
_COMPRESSION = {"gzip": dict(compression="gzip", compression_opts=1, shuffle=True),
                "lzf": dict(compression="lzf", shuffle=True), "none": {}}


def _now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def _to_json(value) -> str:
    def default(o):
        if isinstance(o, (np.generic, np.ndarray)):
            return o.tolist()
        raise TypeError(f"{type(o).__name__} is not JSON serialisable")
    return json.dumps(value, default=default)


def _set_attrs(obj, attrs: dict) -> None:
    """Store ``attrs`` on an HDF5 object; dicts, lists, tuples and None go as JSON text."""
    as_json = set(json.loads(obj.attrs.get("json_attrs", "[]")))
    for key, value in attrs.items():
        is_json = isinstance(value, (dict, list, tuple)) or value is None
        obj.attrs[key] = _to_json(value) if is_json else value
        (as_json.add if is_json else as_json.discard)(key)
    obj.attrs["json_attrs"] = json.dumps(sorted(as_json))


def _get_attrs(obj) -> dict:
    as_json = set(json.loads(obj.attrs.get("json_attrs", "[]")))
    out = {k: json.loads(v) if k in as_json else v.item() if isinstance(v, np.generic) else v
           for k, v in obj.attrs.items()}
    out.pop("json_attrs", None)
    return out


def _open_read(path) -> h5py.File:
    """Open a run or checkpoint read-only; ``swmr=True`` also opens files whose writer died."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise OutputError(f"{path}: no such file")
    try:
        return h5py.File(path, "r", swmr=True)
    except OSError as e:
        raise OutputError(f"{path}: not a readable HDF5 file ({e})") from e


def _check_format(f: h5py.File, expected: str) -> None:
    fmt, version = f.attrs.get("format"), f.attrs.get("format_version")
    if fmt != expected:
        raise OutputError(f"{f.filename}: not an {expected} file (format attribute {fmt!r})")
    if version is None or int(version) > FORMAT_VERSION:
        raise OutputError(f"{f.filename}: format_version {version!r} is not supported "
                          f"(this library reads up to {FORMAT_VERSION})")


def _series(f: h5py.File) -> list[h5py.Dataset]:
    """Every per-frame dataset, in the order they are written (``time`` last)."""
    try:
        out = [*f["particles"].values(), *f["scalars"].values()]
        return out + ([f["walls/forces"]] if "walls/forces" in f else []) + [f["step"], f["time"]]
    except KeyError as e:
        raise OutputError(f"{f.filename}: incomplete run file ({e})") from e


def _layout(f: h5py.File) -> tuple:
    """``(n_particles, particle_fields, wall_names, scalar_series)`` of an open run file."""
    return (int(f.attrs["n_particles"]),
            {k: (d.shape[2:], d.dtype.str, d.attrs["unit"]) for k, d in f["particles"].items()},
            json.loads(f["walls/forces"].attrs["names"]) if "walls/forces" in f else [],
            {k: d.attrs["unit"] for k, d in f["scalars"].items()})


def _check_name(kind: str, name: str) -> None:
    if not isinstance(name, str) or not name or "/" in name or name in (".", "time", "step"):
        raise InvalidArgument(kind, name, "a non-empty name without '/', not 'time' or 'step'")


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
    """

    def __init__(self, path, *, n_particles: int,
                 particle_fields: dict[str, tuple[tuple[int, ...], str, str]],
                 static_fields: dict[str, tuple[np.ndarray, str]] | None = None,
                 wall_names=(), scalar_series: dict[str, str] | None = None,
                 attrs: dict | None = None, compression: str = "gzip", overwrite: bool = True,
                 append: bool = False, keep_frames: int | None = None):
        self.path, self._f = os.fspath(path), None
        if not isinstance(n_particles, (int, np.integer)) or n_particles < 1:
            raise InvalidArgument("n_particles", n_particles, "an integer >= 1")
        if compression not in _COMPRESSION:
            raise InvalidArgument("compression", compression, f"one of {sorted(_COMPRESSION)}")
        self.n_particles, self._fields = int(n_particles), {}
        for name, spec in particle_fields.items():
            _check_name("particle_fields", name)
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
            _check_name("static_fields", name)
            static[name] = (np.asarray(array), str(unit))
            if static[name][0].ndim < 1 or static[name][0].shape[0] != n_particles:
                raise InvalidArgument(f"static_fields[{name!r}].shape", static[name][0].shape,
                                      f"({n_particles}, ...)")
        for name in self._scalars:
            _check_name("scalar_series", name)
        names = [*self._fields, *self._scalars, *static, "wall_forces"]
        if len(set(names)) < len(names):
            raise InvalidArgument("field names", names, "names unique across particle fields, "
                                  "scalars, static fields and 'wall_forces'")
        attrs = dict(attrs or {})
        if _RESERVED_ATTRS & attrs.keys():
            raise InvalidArgument("attrs keys", sorted(_RESERVED_ATTRS & attrs.keys()),
                                  f"none of the reserved keys {sorted(_RESERVED_ATTRS)}")
        if append and os.path.exists(self.path):
            self._f = self._resume(keep_frames, attrs)
        else:
            if os.path.exists(self.path) and not overwrite:
                raise OutputError(f"{self.path}: exists (pass overwrite=True to replace it)")
            self._f, self._n = self._build(static, attrs, compression), 0
        self._datasets = {d.name.lstrip("/"): d for d in _series(self._f)}

    @classmethod
    def reopen(cls, path, *, keep_frames: int | None = None, attrs: dict | None = None) -> RunWriter:
        """Reopen a run (also one whose writer was killed) to append frames, e.g. to resume it.

        The layout is read from the file; ``keep_frames`` complete frames are kept (all if
        None); ``attrs`` are added to the stored attributes.
        """
        with _open_read(path) as f:
            _check_format(f, FORMAT)
            n_particles, fields, walls, scalars = _layout(f)
        return cls(path, n_particles=n_particles, particle_fields=fields, wall_names=walls,
                   scalar_series=scalars, attrs=attrs, append=True, keep_frames=keep_frames)

    def _resume(self, keep_frames, attrs) -> h5py.File:
        layout = (self.n_particles, {k: (s, d.str, u) for k, (s, d, u) in self._fields.items()},
                  self.wall_names, self._scalars)
        with _open_read(self.path) as src:
            _check_format(src, FORMAT)
            complete, found = min(d.shape[0] for d in _series(src)), _layout(src)
            if found != layout:
                raise InvalidArgument("layout (n_particles, particle_fields, wall_names, "
                                      "scalar_series)", layout, f"the layout of {self.path}: {found}")
            keep = complete if keep_frames is None else keep_frames
            if not isinstance(keep, (int, np.integer)) or not 0 <= keep <= complete:
                raise InvalidArgument("keep_frames", keep_frames, f"an integer in [0, {complete}]")
            old = _get_attrs(src)
            resumed = old.pop("resumed", []) + [{"at": _now(), "kept_frames": int(keep)}]
            attrs = {k: v for k, v in old.items() if k not in _RESERVED_ATTRS} | attrs
            static = {k: (d[()], d.attrs["unit"]) for k, d in src["static"].items()}
            first = next(iter(src["particles"].values()), None)
            compression = {"gzip": "gzip", "lzf": "lzf"}.get(getattr(first, "compression", 0), "none")
            f = self._build(static, {**attrs, "resumed": resumed}, compression, src, int(keep))
        self._n = int(keep)
        return f

    def _build(self, static, attrs, compression, src=None, keep=0) -> h5py.File:
        """Write the file aside, with the first ``keep`` frames of ``src`` if given, switch it to
        SWMR mode and move it over ``path``: a kill leaves the old file or the new one."""
        part = self.path + ".part"
        f = h5py.File(part, "w", libver=_LIBVER)
        try:
            f.attrs.update(format=FORMAT, format_version=FORMAT_VERSION, n_particles=self.n_particles,
                           created=src.attrs["created"] if src else _now())
            versions = {"h5py": h5py.__version__, "hdf5": h5py.version.hdf5_version,
                        "numpy": np.__version__} | (attrs.get("versions") or {})
            units = {"length": "m", "time": "s", "mass": "kg", "force": "N", "energy": "J"}
            _set_attrs(f, {**attrs, "versions": versions, "units": units | (attrs.get("units") or {})})
            n, filt = self.n_particles, _COMPRESSION[compression]

            def series(name, dtype, unit, shape=(), chunk=_SERIES_CHUNK, **kw):
                d = f.create_dataset(name, shape=(keep, *shape), maxshape=(None, *shape), dtype=dtype,
                                     chunks=(chunk, *shape), **kw)
                d.attrs["unit"] = unit
                if src and keep and chunk == 1 and src[name].chunks == d.chunks and \
                        (src[name].compression, src[name].shuffle) == (d.compression, d.shuffle):
                    for i in range(src[name].id.get_num_chunks()):   # copy compressed bytes as is
                        info = src[name].id.get_chunk_info(i)
                        if info.chunk_offset[0] < keep:
                            raw = src[name].id.read_direct_chunk(info.chunk_offset)[1]
                            d.id.write_direct_chunk(info.chunk_offset, raw, info.filter_mask)
                elif src and keep:
                    for i in range(0, keep, chunk):
                        d[i:i + chunk] = src[name][i:min(i + chunk, keep)]
                return d

            series("time", "f8", "s")
            series("step", "i8", "1")
            f.create_group("particles", track_order=True)
            for name, (shape, dtype, unit) in self._fields.items():
                series(f"particles/{name}", dtype, unit, (n, *shape), chunk=1, **filt)
            f.create_group("static", track_order=True)
            for name, (array, unit) in static.items():
                f.create_dataset(f"static/{name}", data=array, **filt).attrs["unit"] = unit
            f.create_group("scalars", track_order=True)
            for name, unit in self._scalars.items():
                series(f"scalars/{name}", "f8", unit)
            if self.wall_names:
                series("walls/forces", "f8", "N", (len(self.wall_names), 3)).attrs["names"] = \
                    json.dumps(self.wall_names)
            f.swmr_mode = True                # flushes; from here on datasets only grow
            os.replace(part, self.path)
            return f
        except BaseException:
            f.close()
            os.remove(part)
            raise

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
        for name, value in rows.items():
            self._datasets[name].resize(n + 1, axis=0)
            self._datasets[name][n] = value
        self._f.flush()
        self._n = n + 1
        return n

    def close(self) -> None:
        """Trim a partly written frame (left by an exception) and close the file."""
        if self._f is None:
            return
        try:
            for d in self._datasets.values():
                if d.shape[0] != self._n:
                    d.resize(self._n, axis=0)
        finally:
            self._f.close()
            self._f = None

    def __enter__(self) -> RunWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class RunData:
    """Contents of a run file; small series are loaded, particle fields read on demand.

    Attributes
    ----------
    path : str
    attrs : dict
        Root attributes, JSON-decoded where stored as JSON.
    scenario : dict or None
        The scenario, parsed from ``attrs["scenario"]`` (a dict, or JSON or TOML text).
    n_frames, n_particles : int
        Number of complete frames and of particles.
    times, steps : ndarray (n_frames,)
        Simulated time [s] and step of each frame.
    particle_fields : list of str
    static : dict of str -> ndarray (N, ...)
    units : dict of str -> str
        Unit of every dataset by name (``time``, ``step``, fields, scalars, ``wall_forces``).
    wall_names : list of str
    wall_forces : ndarray (n_frames, n_walls, 3)
        Wall reaction forces [N].
    scalars : dict of str -> ndarray (n_frames,)
    """

    def __init__(self, path):
        self.path = os.fspath(path)
        with _open_read(self.path) as f:
            _check_format(f, FORMAT)
            n = self.n_frames = min(d.shape[0] for d in _series(f))
            self.attrs = _get_attrs(f)
            self.n_particles = int(self.attrs["n_particles"])
            self.times, self.steps = f["time"][:n], f["step"][:n]
            self.particle_fields = list(f["particles"])
            self.static = {k: d[()] for k, d in f["static"].items()}
            self.scalars = {k: d[:n] for k, d in f["scalars"].items()}
            self.units = {"time": "s", "step": "1"}
            for group in ("particles", "static", "scalars"):
                self.units.update({k: d.attrs["unit"] for k, d in f[group].items()})
            self.wall_names, self.wall_forces = [], np.zeros((n, 0, 3))
            if "walls/forces" in f:
                self.wall_names = json.loads(f["walls/forces"].attrs["names"])
                self.wall_forces, self.units["wall_forces"] = f["walls/forces"][:n], "N"

    @property
    def scenario(self) -> dict | None:
        s = self.attrs.get("scenario")
        if s is None or isinstance(s, dict):
            return s
        try:
            return json.loads(s)
        except ValueError:
            try:
                import tomllib
            except ImportError:  # Python 3.10
                import tomli as tomllib
            return tomllib.loads(s)

    def frame(self, i: int) -> dict[str, np.ndarray]:
        """Particle fields of complete frame ``i`` (negative counts from the end)."""
        if not -self.n_frames <= i < self.n_frames:
            raise InvalidArgument("frame", i, f"an index in [{-self.n_frames}, {self.n_frames})")
        with _open_read(self.path) as f:
            return {k: f[f"particles/{k}"][i % self.n_frames] for k in self.particle_fields}

    def field(self, name: str) -> np.ndarray:
        """One particle field over all complete frames, ``(n_frames, N, *shape)``."""
        if name not in self.particle_fields:
            raise InvalidArgument("field", name, f"one of {self.particle_fields}")
        with _open_read(self.path) as f:
            return f[f"particles/{name}"][: self.n_frames]

    def __repr__(self) -> str:
        return (f"RunData({self.path!r}, n_frames={self.n_frames}, n_particles={self.n_particles}, "
                f"fields={self.particle_fields})")


def read_run(path) -> RunData:
    """Read a run file (also one whose writer was killed); raises :class:`OutputError`."""
    return RunData(path)


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
            f.attrs.update(format=CHECKPOINT_FORMAT, format_version=FORMAT_VERSION, created=_now(),
                           meta=_to_json(meta))
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
    with _open_read(path) as f:
        _check_format(f, CHECKPOINT_FORMAT)
        f.visititems(lambda name, obj: arrays.__setitem__(name, obj[()])
                     if isinstance(obj, h5py.Dataset) else None)
        return arrays, json.loads(f.attrs["meta"])
