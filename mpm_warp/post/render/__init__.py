"""Off-screen rendering of run files with PyVista: one PNG per frame and a film (GIF or MP4).

Headless machines
-----------------
The pip ``vtk`` wheel (>= 9.4) loads its OpenGL back end at run time: an X display
(``vtkXOpenGLRenderWindow``), EGL (``vtkEGLRenderWindow``, e.g. Mesa's llvmpipe through
``libEGL.so.1`` + ``libEGL_mesa.so.0``, or the NVIDIA driver) or OSMesa. Left alone on a machine
without a display it tries X, then OSMesa, then EGL, printing warnings on the way. Before VTK
makes its first window :func:`render_run` picks EGL when ``libEGL`` and a vendor library are found,
else OSMesa, else VTK's default when a display is set; if none exists,
:class:`RenderingUnavailable` says what to install. A ``VTK_DEFAULT_OPENGL_WINDOW`` set by the
user is respected.

2D runs
-------
A 2D (plane-strain) run is drawn as the flat x-y section it is, from the side: the weak layer
coloured by its collapse, the elastic slab and old snow light grey (they have no plastic volume
to lose), the damage front a solid magenta line, the slab-deflection front a dashed orange one and the saw
blade a dotted grey one.
"""

from __future__ import annotations

import json
import math
import os

import numpy as np

from ...errors import InvalidArgument, RenderingUnavailable
from ...io import read_run
from ..fields import FIELDS, FieldReader
from ..fronts import fronts_x
from .film import ffmpeg, make_film
from .gl import choose_gl_backend, setup_gl
from .view import (
    BELOW_COLOR,
    CMAP,
    DEFLECTION_COLOR,
    FRONT_COLOR,
    INERT_COLOR,
    SAW_COLOR,
    View,
    fixed_camera,
    spacing,
)

__all__ = ["FIELDS", "CAMERAS", "RenderingUnavailable", "Rendered", "render_run", "parse_frames",
           "choose_gl_backend", "FRONT_COLOR", "DEFLECTION_COLOR", "SAW_COLOR", "BELOW_COLOR",
           "INERT_COLOR"]

#: camera presets: "side" looks along -z at the x-y plane (PSTs), "oblique" is an isometric view
CAMERAS = ("auto", "side", "oblique")


class Rendered(list):
    """PNG paths of the rendered frames, then the film's path when one was made.

    Attributes: ``pngs`` (list of str), ``video`` (str or None), ``field``, ``unit``, ``clim`` (the
    colour range used for every frame, field units), ``metadata`` (dict, also written to
    ``metadata_path`` = ``<field>.json``: camera, size, per frame the time, front position [m] and
    the front marker's image column ``front_px``, 0 = left).
    """

    def __init__(self, pngs, video, metadata, metadata_path):
        super().__init__([*pngs, *([video] if video else [])])
        self.pngs, self.video = list(pngs), video
        self.metadata, self.metadata_path = metadata, metadata_path
        self.field, self.unit = metadata["field"], metadata["unit"]
        self.clim = tuple(metadata["clim"])


def parse_frames(spec, n_frames: int) -> list[int]:
    """Frame indices from ``None``/``"all"``, an int, a list, ``"0,5,-1"`` or a slice ``"0:20:2"``."""
    if spec is None or (isinstance(spec, str) and spec.strip() in ("", "all")):
        return list(range(n_frames))
    items = []
    try:
        for p in spec.split(",") if isinstance(spec, str) else np.atleast_1d(spec).tolist():
            if isinstance(p, str) and ":" in p:
                items += list(range(n_frames))[slice(*[int(s) if s.strip() else None for s in p.split(":")])]
            elif isinstance(p, (bool, float)):
                raise TypeError("a frame index is a whole number")
            else:
                items.append(int(p))
    except (TypeError, ValueError) as e:
        raise InvalidArgument("frames", spec, "'all', indices '0,5,-1' or a slice '0:20:2'") from e
    if not items or not all(-n_frames <= i < n_frames for i in items):
        raise InvalidArgument("frames", spec, f"one or more indices in [{-n_frames}, {n_frames})")
    return [i % n_frames for i in items]


def render_run(path, field: str = "collapse", frames=None, out_dir=None, video=False,
               size=(1280, 720), camera: str = "auto", fps: float = 10.0, clim=None) -> Rendered:
    """Render the particles of a run file, coloured by ``field``, one PNG per frame.

    Each image has a colour bar with units (limits fixed over the film), the time, the crack
    front (a magenta vertical line at ``front_position``, or a PST's ``front``, when stored), a
    PST's slab-deflection front (a dashed orange line), a scale bar in metres and an orientation
    triad. A 2D run is drawn as its flat x-y section (module docstring); under ``collapse`` the
    particles of elastic materials are drawn light grey (``INERT_COLOR``).

    Parameters
    ----------
    path : str or os.PathLike
        Run file (HDF5) written by :class:`mpm_warp.io.RunWriter`.
    field : str
        A derived field of :data:`mpm_warp.post.fields.FIELDS` (definition and reference state there):
        "collapse" [-], "displacement" [m], "p", "q", "sigma_xy", "sigma_yy" [Pa], "velocity" [m/s].
    frames : None, "all", int, str or sequence of int
        Frames to render (see :func:`parse_frames`); all by default.
    out_dir : str, optional
        Folder of the images (created); default ``<run>_render`` beside the run file.
    video : bool or {"gif", "mp4"}
        Also make a film of the frames: ``True`` or ``"gif"`` (Pillow), ``"mp4"`` (needs ffmpeg).
    size : (int, int)
        Image width and height [pixels].
    camera : {"auto", "side", "oblique"}
        ``"side"``: along -z at the x-y plane, parallel projection (PSTs); ``"oblique"``: an
        isometric view (3D runs only); ``"auto"``: side for a 2D run or ``scene.kind == "pst"``, else
        oblique.
    fps : float
        Frames per second of the film, > 0.
    clim : (float, float), optional
        Colour limits; default the min and max of the field over the frames rendered (for
        ``collapse`` clipped to [0, 1]: dilation and sawn cuts, ``collapse < 0``, are drawn grey).

    Returns
    -------
    Rendered
        A list of the PNG paths (then the film's), with ``clim``, ``metadata`` and more.
    """
    fps = _positive_fps(fps)
    if field not in FIELDS:
        raise InvalidArgument("field", field, f"one of {sorted(FIELDS)}")
    if camera not in CAMERAS:
        raise InvalidArgument("camera", camera, f"one of {list(CAMERAS)}")
    if video not in (False, True, "gif", "mp4", None):
        raise InvalidArgument("video", video, "False, True, 'gif' or 'mp4'")
    w, h = _size(size)
    setup_gl()
    if video == "mp4":
        ffmpeg()                              # fail before rendering, not after
    run = read_run(path)
    reader = FieldReader(run)
    label, unit = FIELDS[field].label, FIELDS[field].unit
    missing = [n for n in ("x",) if n not in run.particle_fields] + reader.missing(field)
    if missing:
        raise InvalidArgument("field", field, f"a field this run stores: {missing} missing; the run has "
                              f"{run.particle_fields} (set output.fields in the scenario)")
    idx = parse_frames(frames, run.n_frames)
    dim = _dimension(run)
    if dim == 2 and camera == "oblique":
        raise InvalidArgument("camera", camera, "'side' or 'auto' for a 2D run (it is drawn as its flat x-y "
                              "section)")
    load, data_range, lo, hi = _scan(run, reader, field, idx, _inert(run) if field == "collapse" else None)
    if clim is None and field == "collapse":
        # 1 - J_P < 0 is dilation (a sawn cut stores log_jp >> 0): kept out of the range, drawn grey
        clim = (max(data_range[0], 0.0), min(data_range[1], 1.0))
        clim = clim if clim[0] < clim[1] else (clim[0], clim[0] + 1e-3)
    clim = data_range if clim is None else _pair("clim", clim)
    if not clim[0] < clim[1]:
        raise InvalidArgument("clim", clim, "(low, high) with low < high")
    kind = str(((run.scenario or {}).get("scene") or {}).get("kind", "blocks"))
    preset = camera if camera != "auto" else ("side" if kind == "pst" or dim == 2 else "oblique")
    fr_x = fronts_x(run)
    front, deflection, saw = fr_x["damage"], fr_x["deflection"], fr_x["saw"]
    out_dir = os.fspath(out_dir) if out_dir is not None else os.path.splitext(run.path)[0] + "_render"
    os.makedirs(out_dir, exist_ok=True)
    cam = fixed_camera(preset, lo, hi, (w, h))
    title = f"{(run.scenario or {}).get('name') or os.path.basename(run.path)}: {label}"
    if dim == 2:
        title += " (2D plane-strain section x-y)"
    view = View(load(idx[0])[0], field, f"{label} [{unit}]", clim, data_range[0] < clim[0], cam, lo, hi,
                spacing(run, lo, hi), (w, h), title)
    pngs, meta_frames = [], []
    try:
        for i in idx:
            x, val = load(i)
            t = float(run.times[i])
            xf, xd = (float(a[i]) if a is not None and np.isfinite(a[i]) else None for a in (front, deflection))
            xs = float(saw[i]) if saw is not None and np.isfinite(saw[i]) else None
            note = ", ".join(f"{what} {v:.3f} m ({how})" for what, v, how in (
                ("damage", xf, "magenta"), ("deflection", xd, "orange, dashed"), ("saw", xs, "grey, dotted"))
                if v is not None)
            png = os.path.join(out_dir, f"{field}_{i:04d}.png")
            col, dcol = view.shoot(png, x, val, f"t = {t:.4f} s", xf, xd, xs, "fronts at x: " + note if note else "")
            pngs.append(png)
            meta_frames.append(dict(index=i, time=t, png=png, front_position=xf, front_px=col,
                                    deflection_position=xd, deflection_px=dcol))
    finally:
        view.close()
    movie = make_film(pngs, os.path.join(out_dir, field), "gif" if video is True else video, fps) if video else None
    meta = dict(run=run.path, field=field, label=label, unit=unit, clim=list(clim), data_range=list(data_range),
                camera_preset=preset, camera=cam, size=[w, h], colormap=CMAP, front_color=list(FRONT_COLOR),
                deflection_color=list(DEFLECTION_COLOR), dimension=dim,
                frames=meta_frames, video=movie, gl_window=os.environ.get("VTK_DEFAULT_OPENGL_WINDOW"))
    meta_path = os.path.join(out_dir, f"{field}.json")
    with open(meta_path, "w") as f:
        json.dump(meta, f, indent=1)
    return Rendered(pngs, movie, meta, meta_path)


def _size(size) -> tuple[int, int]:
    try:
        w, h = (int(s) for s in size)
        ok = all(float(s) == int(s) for s in size)
    except (TypeError, ValueError):
        ok = False
    if not ok or w < 64 or h < 64:
        raise InvalidArgument("size", size, "(width, height): whole numbers of pixels, at least 64 x 64")
    return w, h


def _pair(field: str, value) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InvalidArgument(field, value, "(low, high), two numbers") from None
    return lo, hi


def _positive_fps(fps) -> float:
    try:
        ok = float(fps) > 0 and math.isfinite(float(fps))
    except (TypeError, ValueError):
        ok = False
    if isinstance(fps, bool) or not ok:
        raise InvalidArgument("fps", fps, "a finite number of film frames per second > 0")
    return float(fps)


def _dimension(run) -> int:
    """2 or 3: the run's spatial dimension (its grid origin, else the stored positions)."""
    origin = (run.attrs.get("grid") or {}).get("origin")
    return len(origin) if origin else int(run.frame(0)["x"].shape[1])


def _inert(run) -> np.ndarray | None:
    """Particles of elastic materials (no plastic volume to lose: drawn grey under "collapse"), or None."""
    groups, mats = run.attrs.get("groups"), (run.scenario or {}).get("materials") or {}
    if not isinstance(groups, list) or not isinstance(mats, dict):
        return None
    mask = np.zeros(run.n_particles, dtype=bool)
    for g in groups:
        if (mats.get(g.get("material")) or {}).get("model") == "elastic":
            mask[int(g["start"]):int(g["end"])] = True
    return mask if mask.any() and not mask.all() else None


def _scan(run, reader: FieldReader, field: str, idx: list[int], inert=None, cache_limit: int = 20_000_000):
    """First pass over the frames: ``(load(i) -> (x (N, 3), values), (min, max) of values, lo, hi)``.

    2D positions get z = 0; the values of ``inert`` particles are NaN (drawn grey). Frames are kept in
    memory when ``N * frames <= cache_limit``, else read again by ``load``.
    """
    keep = run.n_particles * len(idx) <= cache_limit

    def read(i):
        fr = run.frame(i)
        x = fr["x"].astype(np.float64)
        if x.shape[1] < 3:                    # a 2D run: the x-y section at z = 0
            x = np.pad(x, ((0, 0), (0, 3 - x.shape[1])))
        val = reader.values(field, fr)
        if inert is not None:
            val[inert] = np.nan
        return x, val

    cache, vmin, vmax, lo, hi = {}, np.inf, -np.inf, np.full(3, np.inf), np.full(3, -np.inf)
    for i in idx:
        x, val = read(i)
        if np.isfinite(val).any():
            vmin, vmax = min(vmin, float(np.nanmin(val))), max(vmax, float(np.nanmax(val)))
        lo, hi = np.minimum(lo, x.min(0)), np.maximum(hi, x.max(0))
        if keep:
            cache[i] = (x, val)
    if not vmin <= vmax:
        vmin, vmax = 0.0, 1.0
    elif vmin == vmax:                        # a uniform field: a narrow range starting at its value
        vmax = vmin + (1e-3 * abs(vmin) or 1e-3)
    return (lambda i: cache[i] if keep else read(i)), (vmin, vmax), lo, hi
