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
"""

from __future__ import annotations

import ctypes.util
import glob
import json
import os
import shutil
import subprocess
import sys

import numpy as np

from .errors import InvalidArgument, RenderingUnavailable
from .io import read_run

__all__ = ["FIELDS", "CAMERAS", "RenderingUnavailable", "Rendered", "render_run", "parse_frames",
           "choose_gl_backend", "add_cli"]

#: field -> (colour bar label, unit, particle fields it needs)
FIELDS = {
    "collapse": ("collapse 1 - J_P", "-", ("log_jp",)),
    "displacement": ("displacement", "m", ("x",)),       # |x - x0|
    "p": ("pressure p", "Pa", ("p",)),
    "q": ("Mises stress q", "Pa", ("q",)),
    "velocity": ("speed", "m/s", ("v",)),                 # |v|
}
#: camera presets: "side" looks along -z at the x-y plane (PSTs), "oblique" is an isometric view
CAMERAS = ("auto", "side", "oblique")
FRONT_COLOR = (255, 0, 255)              # magenta: absent from the viridis colour map
BELOW_COLOR = (190, 190, 190)            # particles below the colour range (e.g. a sawn weak layer)
_CMAP = "viridis"


def _has_lib(name: str) -> bool:
    return ctypes.util.find_library(name) is not None


def choose_gl_backend(environ=None) -> tuple[str | None, str | None]:
    """VTK OpenGL window class for off-screen rendering in ``environ`` (default ``os.environ``).

    Returns ``(window_class, problem)``: the class to put in ``VTK_DEFAULT_OPENGL_WINDOW`` (None:
    leave VTK's default) and, when nothing can render, a message saying what is missing (else None).
    """
    env = os.environ if environ is None else environ
    if env.get("VTK_DEFAULT_OPENGL_WINDOW") or not sys.platform.startswith("linux"):
        return None, None
    egl_vendor = (_has_lib("EGL_mesa") or _has_lib("EGL_nvidia")
                  or bool(glob.glob("/usr/share/glvnd/egl_vendor.d/*.json")))
    if _has_lib("EGL") and egl_vendor:
        return "vtkEGLRenderWindow", None
    if _has_lib("OSMesa"):
        return "vtkOSOpenGLRenderWindow", None
    if env.get("DISPLAY"):
        return None, None
    return None, ("off-screen rendering is unavailable: VTK needs an X display (DISPLAY is not set), "
                  "EGL (libEGL.so.1 with a vendor library such as libEGL_mesa.so.0; Debian/Ubuntu: "
                  "apt install libegl1 libegl-mesa0) or OSMesa (libOSMesa; apt install libosmesa6), "
                  "and none was found; or install VTK's self-contained OSMesa wheel: "
                  "pip install --extra-index-url https://wheels.vtk.org vtk-osmesa")


def _setup_gl() -> None:
    """Set ``VTK_DEFAULT_OPENGL_WINDOW`` (read when VTK creates a window) or raise what is missing."""
    window, problem = choose_gl_backend()
    if problem:
        raise RenderingUnavailable(problem)
    if window:
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = window


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
            else:
                items.append(int(p))
    except (TypeError, ValueError) as e:
        raise InvalidArgument("frames", spec, "'all', indices '0,5,-1' or a slice '0:20:2'") from e
    if not items or not all(-n_frames <= i < n_frames for i in items):
        raise InvalidArgument("frames", spec, f"one or more indices in [{-n_frames}, {n_frames})")
    return [i % n_frames for i in items]


def _values(field: str, fr: dict, x0) -> np.ndarray:
    if field == "collapse":
        return 1.0 - np.exp(fr["log_jp"].astype(np.float64))
    if field == "displacement":
        return np.linalg.norm(fr["x"].astype(np.float64) - x0, axis=1)
    if field == "velocity":
        return np.linalg.norm(fr["v"].astype(np.float64), axis=1)
    return fr[field].astype(np.float64).reshape(-1)


def _front_and_saw_x(run) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Crack front and saw blade as x [m] per frame, NaN where there is none.

    ``front_position`` / ``saw_position`` are x already; a PST's ``front`` / ``saw`` are
    distances from the saw's starting end (``scene.saw.from_end``), 0 before there is any.
    """
    scene = (run.scenario or {}).get("scene") or {}
    length = float(scene.get("length", run.static["x0"][:, 0].max() if "x0" in run.static else 0.0))
    right = (scene.get("saw") or {}).get("from_end") == "right"
    out = []
    for x_name, s_name in (("front_position", "front"), ("saw_position", "saw")):
        if x_name in run.scalars:
            out.append(run.scalars[x_name])
        elif s_name in run.scalars:
            s = np.where(run.scalars[s_name] > 0, run.scalars[s_name], np.nan)
            out.append(length - s if right else s)
        else:
            out.append(None)
    return out[0], out[1]


def _nice(length: float) -> float:
    """Largest 1, 2 or 5 x 10^k not above ``length``."""
    e = 10.0 ** np.floor(np.log10(length))
    return max(m * e for m in (1, 2, 5) if m * e <= length * (1 + 1e-9))


def _spacing(run, lo, hi) -> float:
    dx = (run.attrs.get("grid") or {}).get("dx")
    if dx:
        return 0.5 * float(dx)                # 2 particles per cell and axis by default
    ext = [e for e in np.asarray(hi) - np.asarray(lo) if e > 0]
    return float(np.prod(ext) / run.n_particles) ** (1.0 / max(len(ext), 1)) if ext else 1.0


def _camera(preset: str, lo, hi, size) -> dict:
    """Fixed camera (parallel projection) framing the box ``lo``-``hi`` [m] for a whole film.

    The box's projection fills at most 90 % of the width and the band 0.28-0.87 of the height
    (scale bar and colour bar below it, labels above).
    """
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c, ext = 0.5 * (lo + hi), np.maximum(hi - lo, 1e-6)
    back = np.array([0.0, 0.0, 1.0]) if preset == "side" else np.array([0.8, 0.6, 1.0])
    d = -back / np.linalg.norm(back)                       # viewing direction
    right = np.cross(d, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, d)
    corners = np.array([[(lo, hi)[k >> j & 1][j] for j in range(3)] for k in range(8)]) - c
    r, u = corners @ right, corners @ up
    aspect = size[0] / size[1]
    scale = max((r.max() - r.min()) / (2 * 0.9 * aspect), (u.max() - u.min()) / (2 * 0.59))
    # content centre at 0.575 h: 0.075 h above the middle, i.e. 0.15 scale in world units
    focal = c + 0.5 * (r.max() + r.min()) * right + (0.5 * (u.max() + u.min()) - 0.15 * scale) * up
    return dict(position=list(focal - 10 * float(np.linalg.norm(ext)) * d), focal_point=list(focal),
                view_up=list(up), parallel_scale=float(scale))


def _to_pixel(renderer, xyz, height: int) -> tuple[float, float]:
    """World point -> (image column, image row from the top) through the renderer's transform."""
    renderer.SetWorldPoint(float(xyz[0]), float(xyz[1]), float(xyz[2]), 1.0)
    renderer.WorldToDisplay()
    x, y, _ = renderer.GetDisplayPoint()
    return x - 0.5, height - y - 0.5


def render_run(path, field: str = "collapse", frames=None, out_dir=None, video=False,
               size=(1280, 720), camera: str = "auto", fps: float = 10.0, clim=None) -> Rendered:
    """Render the particles of a run file, coloured by ``field``, one PNG per frame.

    Each image has a colour bar with units (limits fixed over the film), the time, the crack
    front (a magenta vertical line at ``front_position``, or a PST's ``front``, when stored), a
    scale bar in metres and an orientation triad.

    Parameters
    ----------
    path : str or os.PathLike
        Run file (HDF5) written by :class:`mpm_warp.io.RunWriter`.
    field : {"collapse", "displacement", "p", "q", "velocity"}
        ``1 - exp(log_jp)`` [-], ``|x - x0|`` [m], pressure or Mises stress [Pa], ``|v|`` [m/s].
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
        isometric view; ``"auto"``: side for ``scene.kind == "pst"``, else oblique.
    fps : float
        Frames per second of the film.
    clim : (float, float), optional
        Colour limits; default the min and max of the field over the frames rendered (for
        ``collapse`` clipped to [0, 1]: dilation and sawn cuts, ``1 - J_P < 0``, are drawn grey).

    Returns
    -------
    Rendered
        A list of the PNG paths (then the film's), with ``clim``, ``metadata`` and more.
    """
    if field not in FIELDS:
        raise InvalidArgument("field", field, f"one of {sorted(FIELDS)}")
    if camera not in CAMERAS:
        raise InvalidArgument("camera", camera, f"one of {list(CAMERAS)}")
    if video not in (False, True, "gif", "mp4", None):
        raise InvalidArgument("video", video, "False, True, 'gif' or 'mp4'")
    w, h = (int(s) for s in size)
    if w < 64 or h < 64:
        raise InvalidArgument("size", size, "(width, height) of at least 64 x 64 pixels")
    _setup_gl()
    if video == "mp4":
        _ffmpeg()                             # fail before rendering, not after
    run = read_run(path)
    label, unit, needs = FIELDS[field]
    missing = [n for n in ("x", *needs) if n not in run.particle_fields]
    if field == "displacement" and "x0" not in run.static:
        missing.append("static x0")
    if missing:
        raise InvalidArgument("field", field, f"a field this run stores: {missing} missing; the run has "
                              f"{run.particle_fields} (set output.fields in the scenario)")
    idx = parse_frames(frames, run.n_frames)
    load, data_range, lo, hi = _scan(run, field, idx)
    if clim is None and field == "collapse":
        # 1 - J_P < 0 is dilation (a sawn cut stores log_jp >> 0): kept out of the range, drawn grey
        clim = (max(data_range[0], 0.0), min(data_range[1], 1.0))
        clim = clim if clim[0] < clim[1] else (clim[0], clim[0] + 1e-3)
    clim = data_range if clim is None else (float(clim[0]), float(clim[1]))
    if not clim[0] < clim[1]:
        raise InvalidArgument("clim", clim, "(low, high) with low < high")
    kind = str(((run.scenario or {}).get("scene") or {}).get("kind", "blocks"))
    preset = camera if camera != "auto" else ("side" if kind == "pst" else "oblique")
    front, saw = _front_and_saw_x(run)
    out_dir = os.fspath(out_dir) if out_dir is not None else os.path.splitext(run.path)[0] + "_render"
    os.makedirs(out_dir, exist_ok=True)
    cam = _camera(preset, lo, hi, (w, h))
    title = f"{(run.scenario or {}).get('name') or os.path.basename(run.path)}: {label}"
    view = _View(load(idx[0])[0], field, f"{label} [{unit}]", clim, data_range[0] < clim[0], cam, lo, hi,
                 _spacing(run, lo, hi), (w, h), title)
    pngs, meta_frames = [], []
    try:
        for i in idx:
            x, val = load(i)
            t = float(run.times[i])
            xf = float(front[i]) if front is not None and np.isfinite(front[i]) else None
            text = f"t = {t:.4f} s" + (f"   front x = {xf:.3f} m" if xf is not None else "")
            if saw is not None and np.isfinite(saw[i]):
                text += f"   saw x = {float(saw[i]):.3f} m"
            png = os.path.join(out_dir, f"{field}_{i:04d}.png")
            col = view.shoot(png, x, val, text, xf)
            pngs.append(png)
            meta_frames.append(dict(index=i, time=t, png=png, front_position=xf, front_px=col))
    finally:
        view.close()
    film = _film(pngs, os.path.join(out_dir, field), "gif" if video is True else video, fps) if video else None
    meta = dict(run=run.path, field=field, label=label, unit=unit, clim=list(clim), data_range=list(data_range),
                camera_preset=preset, camera=cam, size=[w, h], colormap=_CMAP, front_color=list(FRONT_COLOR),
                frames=meta_frames, video=film, gl_window=os.environ.get("VTK_DEFAULT_OPENGL_WINDOW"))
    meta_path = os.path.join(out_dir, f"{field}.json")
    with open(meta_path, "w") as f:
        json.dump(meta, f, indent=1)
    return Rendered(pngs, film, meta, meta_path)


def _scan(run, field: str, idx: list[int], cache_limit: int = 20_000_000):
    """First pass over the frames: ``(load(i) -> (x, values), (min, max) of values, lo, hi)``.

    Frames are kept in memory when ``N * frames <= cache_limit``, else read again by ``load``.
    """
    x0 = run.static.get("x0", np.zeros((run.n_particles, 3))).astype(np.float64)
    keep = run.n_particles * len(idx) <= cache_limit

    def read(i):
        fr = run.frame(i)
        return fr["x"].astype(np.float64), _values(field, fr, x0)

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


class _View:
    """One off-screen plotter for a whole film: fixed camera, colour bar, scale bar and labels."""

    def __init__(self, x, field, bar_title, clim, below, cam, lo, hi, spacing, size, title):
        import pyvista as pv

        self._pv, self.field, (w, h) = pv, field, size
        self.size = (w, h)
        ppm = h / (2 * cam["parallel_scale"])              # pixels per metre
        pl = self.pl = pv.Plotter(off_screen=True, window_size=(w, h))
        pl.set_background("white")
        self.cloud = pv.PolyData(x)
        self.cloud.point_data[field] = np.zeros(len(x))
        bar = dict(title=bar_title, color="black", fmt="%.3g", n_labels=5, vertical=False, position_x=0.2,
                   position_y=0.04, width=0.6, height=0.08, label_font_size=self._fs(16))
        # shaded spheres when particles span >= 10 pixels, else flat unlit squares that tile the body
        spheres = spacing * ppm >= 10
        size = min(1.3 * spacing * ppm, 40.0) if spheres else np.ceil(spacing * ppm) + 1
        if below:                                          # values under the range: grey, own swatch
            bar["below_label"] = f"< {clim[0]:.3g}"
        pl.add_mesh(self.cloud, scalars=field, cmap=_CMAP, clim=clim, render_points_as_spheres=spheres,
                    lighting=spheres, point_size=float(size), scalar_bar_args=bar,
                    below_color=BELOW_COLOR if below else None)
        pl.camera_position = [cam["position"], cam["focal_point"], cam["view_up"]]
        pl.camera.parallel_projection = True
        pl.camera.parallel_scale = cam["parallel_scale"]
        pl.scalar_bar.SetTextPositionToPrecedeScalarBar()  # tick labels below the bar
        pl.scalar_bar.SetTitle("")                         # the title goes above the bar, apart
        bar_title = pl.add_text(bar_title, position=(0.5 * w, 0.125 * h), font_size=self._fs(13), color="black")
        bar_title.GetTextProperty().SetJustificationToCentered()
        pl.add_axes(color="black", line_width=3, viewport=(0.0, 0.0, 0.14, 0.22))
        # scale bar: a round length along x, 28 pixels below the particles, its label under it
        self.z, pad = hi[2] + 2 * spacing, 1.0 / ppm
        self.y_span, self.y_mid = (lo[1] - 12 * pad, hi[1] + 12 * pad), 0.5 * (lo[1] + hi[1])
        length, y_bar = _nice(0.3 * (hi[0] - lo[0]) or 1.0), lo[1] - 28 * pad
        pl.add_mesh(pv.Line((lo[0], y_bar, self.z), (lo[0] + length, y_bar, self.z)), color="black",
                    line_width=4, lighting=False)
        pl.render()
        ends = [_to_pixel(pl.renderer, (xe, y_bar, self.z), h) for xe in (lo[0], lo[0] + length)]
        below = h - max(ends[0][1], ends[1][1]) - 2 * self._fs(12)
        txt = pl.add_text(f"{length:g} m", position=(0.5 * (ends[0][0] + ends[1][0]), below),
                          font_size=self._fs(12), color="black")
        txt.GetTextProperty().SetJustificationToCentered()
        pl.add_text(title, position=(12, h - 2.4 * self._fs(14) - 2 * self._fs(11)), font_size=self._fs(11),
                    color="black")                 # under the time label

    def _fs(self, points: int) -> int:
        """Font size scaled with the image height (sizes are given for 720 pixels)."""
        return max(9, round(points * self.size[1] / 720))

    def shoot(self, png: str, x, values, text: str, front: float | None) -> float | None:
        """Render one frame to ``png``; return the front marker's image column (None: no front)."""
        pl, (w, h) = self.pl, self.size
        self.cloud.points = x
        self.cloud.point_data[self.field] = values
        col = None
        if front is not None:
            line = self._pv.Line((front, self.y_span[0], self.z), (front, self.y_span[1], self.z))
            pl.add_mesh(line, color=FRONT_COLOR, line_width=3, lighting=False, name="front", reset_camera=False)
            col = _to_pixel(pl.renderer, (front, self.y_mid, self.z), h)[0]
        else:
            pl.remove_actor("front", reset_camera=False)
        pl.add_text(text, position=(12, h - 2.4 * self._fs(14)), font_size=self._fs(14), color="black", name="time")
        pl.renderer.ResetCameraClippingRange()
        pl.screenshot(png, window_size=(w, h))
        return col

    def close(self) -> None:
        self.pl.close()


def _ffmpeg() -> str:
    """Path of an ffmpeg executable (PATH, then imageio-ffmpeg's) or :class:`RenderingUnavailable`."""
    exe = shutil.which("ffmpeg")
    if exe is None:
        try:
            import imageio_ffmpeg

            exe = imageio_ffmpeg.get_ffmpeg_exe()
        except (ImportError, RuntimeError):
            raise RenderingUnavailable("an MP4 film needs ffmpeg: none on PATH and imageio-ffmpeg is not "
                                       "installed (pip install imageio-ffmpeg); or ask for a GIF "
                                       "(video='gif', --video gif)") from None
    return exe


def _film(pngs: list[str], stem: str, fmt: str, fps: float) -> str:
    """Join PNG frames into ``stem.gif`` (Pillow) or ``stem.mp4`` (ffmpeg)."""
    if fmt == "gif":
        from PIL import Image

        images = [Image.open(p).convert("RGB") for p in pngs]
        images[0].save(stem + ".gif", save_all=True, append_images=images[1:], loop=0,
                       duration=max(int(round(1000 / fps)), 20))
        return stem + ".gif"
    exe, listing = _ffmpeg(), stem + "_frames.txt"
    with open(listing, "w") as f:
        for p in pngs:
            f.write(f"file '{os.path.abspath(p)}'\nduration {1.0 / fps}\n")
    cmd = [exe, "-y", "-loglevel", "error", "-f", "concat", "-safe", "0", "-i", listing, "-vf",
           "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", "-r", str(fps), stem + ".mp4"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    os.remove(listing)
    if res.returncode != 0:
        raise RenderingUnavailable(f"ffmpeg failed ({res.returncode}): {res.stderr.strip()}")
    return stem + ".mp4"


def _cmd_render(a) -> int:
    out = render_run(a.run, field=a.field, frames=a.frames, out_dir=a.out, video=a.video or False,
                     size=tuple(a.size), camera=a.camera, fps=a.fps)
    print(f"{len(out.pngs)} frames of {out.field} [{out.unit}], colour range {out.clim[0]:.4g} .. "
          f"{out.clim[1]:.4g}, in {os.path.dirname(out.pngs[0]) or '.'}")
    if out.video:
        print(f"film: {out.video}")
    return 0


def add_cli(subparsers) -> None:
    """Add ``mpm-warp render RUN.h5 [--field F] [--frames ...] [--out DIR] [--video [gif|mp4]]``."""
    r = subparsers.add_parser("render", help="render a run's particles to PNG frames (and a film), off screen")
    r.add_argument("run", help="HDF5 run file")
    r.add_argument("--field", default="collapse", choices=sorted(FIELDS),
                   help="colour: collapse 1-J_P [-], displacement |x-x0| [m], p, q [Pa], velocity |v| [m/s]")
    r.add_argument("--frames", default="all", help="'all' (default), indices '0,10,-1' or a slice '0:50:5'")
    r.add_argument("--out", default=None, help="output folder (default: RUN_render beside the run)")
    r.add_argument("--video", nargs="?", const="gif", default=None, choices=["gif", "mp4"],
                   help="also make a film (default gif; mp4 needs ffmpeg)")
    r.add_argument("--size", nargs=2, type=int, default=[1280, 720], metavar=("W", "H"), help="pixels")
    r.add_argument("--camera", default="auto", choices=CAMERAS, help="side (PSTs), oblique, auto")
    r.add_argument("--fps", type=float, default=10.0, help="film frames per second")
    r.set_defaults(func=_cmd_render)
