"""Reading HDF5 run files (also while they are written, or after their writer was killed)."""

from __future__ import annotations

import json
import os

import numpy as np

from ..errors import InvalidArgument
from .hdf5 import FORMAT, check_format, get_attrs, series_datasets
from .opening import open_read, reading

__all__ = ["RunData", "read_run"]


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
        if not isinstance(path, (str, os.PathLike)) or not os.fspath(path):
            raise InvalidArgument("path", path, "a run file path (str or os.PathLike)")
        self.path = os.fspath(path)
        with open_read(self.path) as f, reading(self.path, "reading its layout and series"):
            self._swmr = f.swmr_mode      # later reads open the file the same way, without a new probe
            check_format(f, FORMAT)
            n = self.n_frames = min(d.shape[0] for d in series_datasets(f))
            self.attrs = get_attrs(f)
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
            with reading(self.path, "its scenario attribute"):
                return tomllib.loads(s)

    def frame(self, i: int) -> dict[str, np.ndarray]:
        """Particle fields of complete frame ``i`` (negative counts from the end)."""
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not -self.n_frames <= i < self.n_frames:
            raise InvalidArgument("frame", i, f"an index in [{-self.n_frames}, {self.n_frames})")
        with open_read(self.path, self._swmr, probed=True) as f, reading(self.path, f"frame {i}"):
            return {k: f[f"particles/{k}"][i % self.n_frames] for k in self.particle_fields}

    def field(self, name: str) -> np.ndarray:
        """One particle field over all complete frames, ``(n_frames, N, *shape)``."""
        if name not in self.particle_fields:
            raise InvalidArgument("field", name, f"one of {self.particle_fields}")
        with open_read(self.path, self._swmr, probed=True) as f, reading(self.path, f"field {name}"):
            return f[f"particles/{name}"][: self.n_frames]

    def __repr__(self) -> str:
        return (f"RunData({self.path!r}, n_frames={self.n_frames}, n_particles={self.n_particles}, "
                f"fields={self.particle_fields})")


def read_run(path) -> RunData:
    """Read a run file (also one being written, or whose writer was killed); raises :class:`OutputError`.

    A damaged file (flipped or missing bytes) raises at once, never hangs (:mod:`mpm_warp.io.opening`).
    """
    return RunData(path)
