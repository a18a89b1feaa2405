"""The off-screen view of a film: fixed camera, colour bar, scale bar and labels (PyVista)."""

from __future__ import annotations

import numpy as np

__all__ = ["View", "fixed_camera", "spacing", "FRONT_COLOR", "DEFLECTION_COLOR", "SAW_COLOR", "BELOW_COLOR",
           "INERT_COLOR", "CMAP"]

FRONT_COLOR = (255, 0, 255)              # magenta, solid: the damage front (absent from the viridis colour map)
DEFLECTION_COLOR = (230, 97, 1)          # dark orange, dashed: the slab-deflection front (absent from viridis too)
SAW_COLOR = (70, 70, 70)                 # dark grey, dotted: the saw blade
BELOW_COLOR = (190, 190, 190)            # particles below the colour range (e.g. a sawn weak layer)
INERT_COLOR = (222, 222, 222)            # particles without the field (NaN): the elastic slab and old snow under
                                         # "collapse", lighter than BELOW_COLOR
CMAP = "viridis"
#: the vertical lines of a frame: name -> (colour, segments over the height (1: solid), depth offset in spacings);
#: drawn in this order, nearer the camera down the list (where they coincide the damage front shows)
LINES = {"saw": (SAW_COLOR, 60, 0.0), "deflection": (DEFLECTION_COLOR, 24, 0.3), "front": (FRONT_COLOR, 1, 0.6)}


def _nice(length: float) -> float:
    """Largest 1, 2 or 5 x 10^k not above ``length``."""
    e = 10.0 ** np.floor(np.log10(length))
    return max(m * e for m in (1, 2, 5) if m * e <= length * (1 + 1e-9))


def spacing(run, lo, hi) -> float:
    dx = (run.attrs.get("grid") or {}).get("dx")
    if dx:
        return 0.5 * float(dx)                # 2 particles per cell and axis by default
    ext = [e for e in np.asarray(hi) - np.asarray(lo) if e > 0]
    return float(np.prod(ext) / run.n_particles) ** (1.0 / max(len(ext), 1)) if ext else 1.0


def fixed_camera(preset: str, lo, hi, size) -> dict:
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


class View:
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
        pl.add_mesh(self.cloud, scalars=field, cmap=CMAP, clim=clim, render_points_as_spheres=spheres,
                    lighting=spheres, point_size=float(size), scalar_bar_args=bar,
                    below_color=BELOW_COLOR if below else None, nan_color=INERT_COLOR)
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
        self.z_pad = spacing
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

    def shoot(self, png: str, x, values, text: str, front: float | None, deflection: float | None = None,
              saw: float | None = None, note: str = "") -> tuple[float | None, float | None]:
        """Render one frame to ``png`` with its vertical lines at x [m] (None: not drawn): the damage front
        solid magenta, the slab-deflection front dashed orange, the saw blade dotted grey (:data:`LINES`);
        ``text`` (the time) on the top line, ``note`` (the lines' positions) under the title.

        Returns the image columns of the damage and the deflection front (None where not drawn).
        """
        pl, (w, h) = self.pl, self.size
        self.cloud.points = x
        self.cloud.point_data[self.field] = values
        cols = {}
        for name, xf in (("saw", saw), ("deflection", deflection), ("front", front)):
            color, segments, dz = LINES[name]
            if xf is None:
                pl.remove_actor(name, reset_camera=False)
                cols[name] = None
                continue
            z = self.z + dz * self.z_pad
            ys = np.linspace(self.y_span[0], self.y_span[1], 2 * segments)
            pts = np.column_stack([np.full(len(ys), xf), ys, np.full(len(ys), z)])
            line = self._pv.PolyData(pts, lines=np.array([[2, i, i + 1] for i in range(0, len(ys), 2)]).ravel())
            pl.add_mesh(line, color=color, line_width=3 if segments < 50 else 2, lighting=False, name=name,
                        reset_camera=False)
            cols[name] = _to_pixel(pl.renderer, (xf, self.y_mid, z), h)[0]
        pl.add_text(text, position=(12, h - 2.4 * self._fs(14)), font_size=self._fs(14), color="black", name="time")
        pl.add_text(note, position=(12, h - 2.4 * self._fs(14) - 4 * self._fs(11)), font_size=self._fs(11),
                    color="black", name="note")
        pl.renderer.ResetCameraClippingRange()
        pl.screenshot(png, window_size=(w, h))
        return cols["front"], cols["deflection"]

    def close(self) -> None:
        self.pl.close()
