"""weac's static answer for a PST column, in plain numbers and SI units (docs/weac.md).

weac (Weissgraeber and Rosendahl 2023) is the field's closed-form model of a layered slab on an elastic
weak layer. It is an optional dependency under its own licence (CC BY-NC-SA 4.0): imported at run time only,
never at package import, and none of its code is copied here. This module builds a :class:`StaticColumn`
in weac 2.6.x, mapping our slope and cut-end convention onto weac's (docs/weac.md §2), and returns the
energy release rate at a cut, the energy-criterion critical cut and the slab's tensile principal stress.
"""

from __future__ import annotations

import importlib
import importlib.metadata as _md
import math
import re
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from ..checks import check_choices, finite_number
from ..errors import InvalidArgument, MPMError
from .density_laws import sigrist_tensile_strength

__all__ = ["StaticColumn", "CriticalCut", "WeacUnavailable", "NOT_INSTALLED", "weac_version", "weac_unavailable",
           "weac_setup", "sigrist_tensile_strength", "energy_release_rate", "critical_cut", "critical_cut_search",
           "slab_stress"]

#: the one line printed when weac is missing
NOT_INSTALLED = "weac is not installed: pip install 'mpm-warp[weac]' (weac 2.6.x, Python >= 3.10)"
_SUPPORTED = ((2, 6), (3, 0))          # weac >= 2.6, < 3
_KAPPA = 5.0 / 6.0                     # shear correction of a rectangular section (Timoshenko)


class WeacUnavailable(MPMError, ImportError):
    """weac is not installed, or its version has another API than weac 2.6.x.

    ``name`` is the missing package (weac, or one weac imports) when one is missing, else None.
    """


def weac_version() -> str | None:
    """The installed weac's version string, or None when weac is not installed (weac is not imported)."""
    try:
        return _md.version("weac")
    except _md.PackageNotFoundError:
        return None


def weac_unavailable() -> str | None:
    """None when a supported weac (2.6.x) is installed; else the one line that says why it cannot be used."""
    v = weac_version()
    if v is None:
        return NOT_INSTALLED
    parts = tuple(int(p) for p in (re.findall(r"\d+", v) + ["0", "0"])[:2])
    if not _SUPPORTED[0] <= parts < _SUPPORTED[1]:
        return (f"weac {v} is installed, but mpm_warp speaks the weac 2.6.x API (weac 3 has another one): "
                "pip install 'weac>=2.6,<3' (Python >= 3.10)")
    return None


def _weac():
    """The weac module (imported here, at first use); :class:`WeacUnavailable` with its one line otherwise."""
    why, missing = weac_unavailable(), None
    if why is None:
        try:
            return importlib.import_module("weac")
        except ImportError as exc:           # metadata present, package broken or hidden
            why = f"{NOT_INSTALLED} (import failed: {exc})"
            missing = exc.name if isinstance(exc, ModuleNotFoundError) else None
    elif weac_version() is None:
        missing = "weac"
    raise WeacUnavailable(why, name=missing)


@dataclass(frozen=True)
class StaticColumn:
    """A PST column as weac sees it (SI units).

    Our frame: ``x`` runs along the column, gravity is ``g (sin theta, -cos theta)``, downslope is ``+x``, so for
    ``slope_angle > 0`` the end ``x = 0`` is the upslope end (and for ``slope_angle < 0`` the end ``x = length``).

    Attributes
    ----------
    slab : tuple of (thickness m, density kg/m^3, E Pa, nu)
        The slab's layers, top to bottom; each layer's E and nu are used exactly as given.
    weak_layer_thickness : float
        m; weac's weak layer is a bed of springs of normal and shear stiffness ``E/(1-nu^2)/t`` and ``G/t``.
    weak_layer_E, weak_layer_nu : float
        Pa, -.
    length : float
        Column length along the slope (m), measured at the weak layer.
    slope_angle : float
        deg, in [-60, 60].
    cut_from : {"upslope", "downslope"}
        The end the saw starts from; on flat ground "upslope" is the end ``x = 0``.
    column_ends : {"slope_normal", "vertical"}
        End faces normal to the slope (European practice) or plumb (the North American standard): weac's
        ``pst`` or ``vpst`` systems.
    """

    slab: tuple
    weak_layer_thickness: float
    weak_layer_E: float
    weak_layer_nu: float
    length: float
    slope_angle: float = 0.0
    cut_from: Literal["upslope", "downslope"] = "upslope"
    column_ends: Literal["slope_normal", "vertical"] = "slope_normal"

    def __post_init__(self):
        layers = self.slab
        if isinstance(layers, (str, bytes)) or not hasattr(layers, "__len__") or len(layers) == 0:
            raise InvalidArgument("column.slab", layers, "one or more layers (thickness m, density kg/m^3, E Pa, nu), "
                                                         "top to bottom")
        for i, ly in enumerate(layers):
            if isinstance(ly, (str, bytes)) or not hasattr(ly, "__len__") or len(ly) != 4:
                raise InvalidArgument(f"column.slab[{i}]", ly, "a layer (thickness m, density kg/m^3, E Pa, nu)")
        object.__setattr__(self, "slab", tuple(tuple(ly) for ly in layers))
        self.validate()

    def validate(self, where: str = "column") -> None:
        """Raise :class:`~mpm_warp.errors.InvalidArgument` naming the first bad field, its value and its range."""
        for i, (h, rho, E, nu) in enumerate(self.slab):
            finite_number(f"{where}.slab[{i}].thickness", h, lo=0.0, hi=10.0, lo_open=True)
            finite_number(f"{where}.slab[{i}].density", rho, lo=0.0, hi=917.0, lo_open=True)
            finite_number(f"{where}.slab[{i}].E", E, lo=0.0, lo_open=True)
            finite_number(f"{where}.slab[{i}].nu", nu, lo=0.0, hi=0.5, hi_open=True)
        finite_number(f"{where}.weak_layer_thickness", self.weak_layer_thickness, lo=0.0, hi=1.0, lo_open=True)
        finite_number(f"{where}.weak_layer_E", self.weak_layer_E, lo=0.0, lo_open=True)
        finite_number(f"{where}.weak_layer_nu", self.weak_layer_nu, lo=0.0, hi=0.5, hi_open=True)
        finite_number(f"{where}.length", self.length, lo=0.0, hi=100.0, lo_open=True)
        finite_number(f"{where}.slope_angle", self.slope_angle, lo=-60.0, hi=60.0)
        check_choices(self, where)
        wedge = self.thickness * math.tan(math.radians(abs(self.slope_angle)))
        if self.column_ends == "vertical" and wedge >= self.length:
            raise InvalidArgument(f"{where}.column_ends", self.column_ends,
                                  f"'slope_normal' for this column: its vertical end wedge (slab thickness x "
                                  f"tan(slope) = {wedge:.3g} m) must be shorter than the column ({self.length:g} m)")

    @property
    def thickness(self) -> float:
        """Slab thickness (m)."""
        return float(sum(ly[0] for ly in self.slab))


def weac_setup(column: StaticColumn) -> tuple[str, float]:
    """weac's system and slope angle phi (deg) for ``column`` (docs/weac.md §2).

    weac's ``x`` is ours and its ``phi`` is counterclockwise positive, so its gravity ``g (-sin phi, -cos phi)``
    is ours for ``phi = -theta``; ``"-pst"`` cuts from its left end (``x = 0``), ``"pst-"`` from its right end.
    A column with ``theta < 0`` is first mirrored (``x -> length - x``, ``theta -> -theta``): then ``x = 0`` is
    always the upslope end, and the cut from the upslope end is weac's left end.
    """
    left = column.cut_from == "upslope"
    base = "pst" if column.column_ends == "slope_normal" else "vpst"
    return ("-" + base if left else base + "-"), -abs(float(column.slope_angle))


def _plate_stiffness(column: StaticColumn) -> tuple[float, float, float, float]:
    """Plane-strain ``A11, B11, D11, kappa A55`` of the layered slab (N/mm, N, N mm, N/mm), about its mid-plane."""
    h = np.array([ly[0] for ly in column.slab]) * 1e3
    z = np.concatenate([[0.0], np.cumsum(h)]) - h.sum() / 2.0              # ply faces, top to bottom, z down
    E = np.array([ly[2] for ly in column.slab]) * 1e-6
    nu = np.array([ly[3] for ly in column.slab])
    Ep = E / (1.0 - nu**2)
    G = E / (2.0 * (1.0 + nu))
    return (float(np.sum(Ep * np.diff(z))), float(np.sum(Ep * np.diff(z**2)) / 2.0),
            float(np.sum(Ep * np.diff(z**3)) / 3.0), float(_KAPPA * np.sum(G * np.diff(z))))


def _model(column: StaticColumn, touchdown: bool = False):
    """weac's ``Layered`` model of ``column`` (mm, MPa), each layer's E and nu as given (not weac's E(rho));
    ``touchdown``: the cut slab's end may rest on the collapsed weak layer (weac's own collapse height)."""
    weac = _weac()
    system, _ = weac_setup(column)
    model = weac.Layered(system=system, layers=[[ly[1], ly[0] * 1e3] for ly in column.slab], touchdown=touchdown)
    model.set_foundation_properties(t=column.weak_layer_thickness * 1e3, E=column.weak_layer_E * 1e-6,
                                    nu=column.weak_layer_nu)
    E = np.array([ly[2] for ly in column.slab]) * 1e-6
    nu = np.array([ly[3] for ly in column.slab])
    model.slab[:, 2], model.slab[:, 3], model.slab[:, 4] = E, E / (2.0 * (1.0 + nu)), nu   # E, G, nu columns
    model.calc_fundamental_system()
    got = (model.A11, model.B11, model.D11, model.kA55)
    want = _plate_stiffness(column)
    scale = max(abs(want[0]) * column.thickness * 1e3, 1.0)               # B11's size, for its zero
    if not all(math.isclose(g, w, rel_tol=1e-9, abs_tol=1e-12 * (scale if i == 1 else abs(w)))
               for i, (g, w) in enumerate(zip(got, want, strict=True))):
        raise MPMError(f"weac {weac_version()} did not take the slab's E and nu (A11, B11, D11, kA55 = {got}, "
                       f"expected {want}): this weac's slab matrix differs from weac 2.6's")
    return model


@dataclass
class _Solved:
    """weac's solution of a column at one cut (weac's units and frame)."""

    model: object
    phi: float
    seg: dict
    C: np.ndarray
    left: bool            # the cut end is weac's x = 0


def _solve(column: StaticColumn, cut: float, model=None, touchdown: bool = False) -> _Solved:
    """Solve ``column`` with a cut of ``cut`` m from its cut end (``model``: reuse a built one)."""
    finite_number("cut", cut, lo=0.0, hi=column.length, hi_open=True)
    model = _model(column, touchdown) if model is None else model
    system, phi = weac_setup(column)
    seg = model.calc_segments(L=column.length * 1e3, a=float(cut) * 1e3, phi=phi)["crack"]
    C = model.assemble_and_solve(phi=phi, **seg)
    return _Solved(model, phi, seg, C, system.startswith("-"))


def energy_release_rate(column: StaticColumn, cut: float, touchdown: bool = False) -> tuple[float, float, float]:
    """weac's differential energy release rate ``(G, G_I, G_II)`` (J/m^2) at a cut of ``cut`` m.

    ``cut`` is measured along the weak layer from the cut end, in [0, length). ``G = G_I + G_II`` at the crack
    tip (weac's ``gdif``), from the weak layer's normal and shear stress there. ``touchdown``: with weac's
    touchdown (the cut slab's end rests on the collapsed layer once it sinks by weac's collapse height, and
    then lies on it; Rosendahl et al. 2025): the G of a crack long past the critical cut, capped.

    weac 2.6 applies touchdown to columns with slope-normal ends only: with vertical ends it switches the
    touchdown mode but keeps the free end and the whole cut span, and its G grows past the free slab's
    (docs/weac.md, "Touchdown"). A vertical-ended column's G with touchdown is therefore its own free G times
    what touchdown leaves of each mode on the same column with slope-normal ends (:func:`_touchdown_share`).
    """
    if touchdown and column.column_ends == "vertical":
        free = _gdif(column, cut, touchdown=False)
        share = _touchdown_share(replace(column, column_ends="slope_normal"), cut)
        G_I, G_II = free[1] * share[0], free[2] * share[1]
        return G_I + G_II, G_I, G_II
    return _gdif(column, cut, touchdown)


def _gdif(column: StaticColumn, cut: float, touchdown: bool) -> tuple[float, float, float]:
    """weac's ``gdif`` ``(G, G_I, G_II)`` (J/m^2) of ``column`` at ``cut`` (m), as weac computes it."""
    s = _solve(column, cut, touchdown=touchdown)
    return tuple(float(g) for g in s.model.gdif(s.C, s.phi, **s.seg, unit="J/m^2"))


def _touchdown_share(column: StaticColumn, cut: float) -> tuple[float, float]:
    """``(G_I, G_II)`` with touchdown over without, on ``column`` (slope-normal ends) at ``cut`` (m): 1 while the
    cut slab hangs free; a mode without a free G keeps its own (a share of 1)."""
    free, rest = _gdif(column, cut, touchdown=False), _gdif(column, cut, touchdown=True)
    return tuple(r / f if f > 0.0 else 1.0 for f, r in zip(free[1:], rest[1:], strict=True))


@dataclass(frozen=True)
class CriticalCut:
    """The energy criterion's critical cut: ``value`` (m, None when not met over the column) and why."""

    value: float | None
    reason: str
    G_c: float


def critical_cut_search(column: StaticColumn, G_c: float, *, max_cut: float | None = None,
                        samples: int = 200) -> CriticalCut:
    """The shortest cut ``a_c`` (m) with ``G(a_c) = G_c`` (J/m^2): a scan of ``samples`` cuts over ``[0, max_cut]``
    (default ``0.999 length``: G grows without bound as the intact part shrinks) for the first crossing, then
    Brent's root in that interval.

    ``value`` is 0 when ``G >= G_c`` already without a cut, None when ``G < G_c`` over the whole scan.
    """
    from scipy.optimize import brentq

    G_c = finite_number("G_c", G_c, lo=0.0, lo_open=True)
    top = 0.999 * column.length if max_cut is None else finite_number(
        "max_cut", max_cut, lo=0.0, hi=column.length, lo_open=True, hi_open=True)
    model = _model(column)

    def excess(a: float) -> float:
        s = _solve(column, a, model)
        return float(model.gdif(s.C, s.phi, **s.seg, unit="J/m^2")[0]) - G_c

    cuts = np.linspace(0.0, top, int(samples) + 1)
    f0 = excess(cuts[0])
    if f0 >= 0.0:
        return CriticalCut(0.0, f"G = {f0 + G_c:.4g} J/m^2 >= G_c = {G_c:.4g} J/m^2 without a cut", G_c)
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        if excess(hi) >= 0.0:
            a = brentq(excess, lo, hi, xtol=1e-12, rtol=1e-13)
            return CriticalCut(float(a), f"G = G_c = {G_c:.4g} J/m^2 at a = {a:.4f} m (first crossing)", G_c)
    return CriticalCut(None, f"G < G_c = {G_c:.4g} J/m^2 for every cut up to {cuts[-1]:.3g} m "
                             f"(G = {excess(cuts[-1]) + G_c:.4g} J/m^2 there)", G_c)


def critical_cut(column: StaticColumn, G_c: float, *, max_cut: float | None = None) -> float | None:
    """The energy criterion's critical cut (m) where ``G(a_c) = G_c`` (J/m^2); None if G stays below G_c up to
    ``max_cut`` (m; :func:`critical_cut_search` says why)."""
    return critical_cut_search(column, G_c, max_cut=max_cut).value


def _layer_of_rows(model, z: np.ndarray) -> np.ndarray:
    """The slab layer (0 = top) of each row of weac's z mesh (each layer's rows end on its faces)."""
    faces = model.get_ply_coordinates()
    idx = np.searchsorted(faces, z, side="right") - 1
    idx[:-1][z[:-1] == z[1:]] -= 1            # a face's first row belongs to the layer above it
    return np.clip(idx, 0, len(faces) - 2)


def slab_stress(column: StaticColumn, cut: float, strengths=None, *, dx: float = 0.005, dz: float = 0.002,
                raw_weac: bool = False) -> dict:
    """The slab's maximum principal (tensile) stress in weac's static solution at a cut of ``cut`` m.

    Parameters
    ----------
    strengths : sequence of float, optional
        Each layer's tensile strength (Pa), top to bottom (for example :func:`sigrist_tensile_strength`):
        then the field is also given divided by its layer's strength.
    dx, dz : float
        Spacing (m) along the column (the crack tip is added) and through the slab (weac's z mesh).
    raw_weac : bool
        False: over the cut, where the slab's base is free, the shear and transverse stress come from the
        equations without the weak layer (docs/weac.md §3). True: weac 2.6's ``principal_stress_slab`` as is,
        which uses the weak layer's equations there too.

    Returns
    -------
    dict
        ``x`` (m from the cut end), ``depth`` (m below the slab surface; a row at each layer face on each side),
        ``layer`` (per depth row), ``cracked`` (per x: over the cut), ``sigma_1`` (Pa, depth x x), ``peak_sigma_1``,
        ``peak_x``, ``peak_depth``, ``peak_layer``; with ``strengths`` also ``ratio`` and ``peak_ratio``,
        ``peak_ratio_x``, ``peak_ratio_depth``, ``peak_ratio_layer``.
    """
    dx = finite_number("dx", dx, lo=0.0, lo_open=True)
    dz = finite_number("dz", dz, lo=0.0, lo_open=True)
    if strengths is not None:
        if isinstance(strengths, (str, bytes)) or not hasattr(strengths, "__len__") or len(strengths) != len(
                column.slab):
            raise InvalidArgument("strengths", strengths, f"{len(column.slab)} tensile strengths (Pa), top to bottom")
        strengths = np.array([finite_number(f"strengths[{i}]", s, lo=0.0, lo_open=True)
                              for i, s in enumerate(strengths)])
    s = _solve(column, cut)
    m, L = s.model, column.length * 1e3
    a = float(cut) * 1e3
    x = np.unique(np.concatenate([np.linspace(0.0, L, int(math.ceil(L / (dx * 1e3))) + 1), [a]]))
    xw = x if s.left else L - x                                    # weac's x
    li, ki = np.asarray(s.seg["li"], dtype=float), np.asarray(s.seg["ki"], dtype=bool)
    starts = np.concatenate([[0.0], np.cumsum(li)[:-1]])
    j = np.clip(np.searchsorted(starts, xw, side="right") - 1, 0, len(li) - 1)
    tip = np.isclose(x, a, rtol=0.0, atol=1e-9)
    j[tip] = int(np.flatnonzero(ki)[0])                           # the crack tip: the bedded side
    zmesh = m.get_zmesh(dz=dz * 1e3)
    sigma = np.empty((zmesh.shape[0], x.size))
    for seg in np.unique(j):
        cols = np.flatnonzero(j == seg)
        Z = m.z(list(xw[cols] - starts[seg]), s.C[:, [seg]], li[seg], s.phi, bed=bool(ki[seg]))
        springs = (m.kn, m.kt)
        if not ki[seg] and not raw_weac:
            m.kn, m.kt = 0.0, 0.0                                 # the free slab's equations: no weak layer
        try:
            sigma[:, cols] = m.principal_stress_slab(Z, s.phi, dz=dz * 1e3, unit="kPa", val="max") * 1e3
        finally:
            m.kn, m.kt = springs
    z = zmesh[:, 0]
    layer = _layer_of_rows(m, z)
    out = {"x": x / 1e3, "depth": (z + m.h / 2.0) / 1e3, "layer": layer, "cracked": x < a, "sigma_1": sigma,
           "raw_weac": raw_weac}
    out["peak_sigma_1"], out["peak_x"], out["peak_depth"], out["peak_layer"] = _peak(sigma, out)
    if strengths is not None:
        out["ratio"] = sigma / strengths[layer][:, None]
        out["peak_ratio"], out["peak_ratio_x"], out["peak_ratio_depth"], out["peak_ratio_layer"] = _peak(
            out["ratio"], out)
    return out


def _peak(field: np.ndarray, out: dict) -> tuple[float, float, float, int]:
    """Value, x (m), depth (m) and layer of the maximum of ``field`` (depth x x)."""
    r, c = np.unravel_index(int(np.argmax(field)), field.shape)
    return float(field[r, c]), float(out["x"][c]), float(out["depth"][r]), int(out["layer"][r])
