"""A profile's layers from plain columns, whichever library read the file: geometry checked, densities given.

Both readers (:mod:`.caaml` through snowprofile, :mod:`.snowpilot` through snowpylot) hand over the layers'
depths, thicknesses, hardness and grains and the density samples as plain lists (depths in m from the snow
surface); :func:`build_layers` checks that the layers are contiguous from the surface (a gap is not filled:
its snow was not described) and gives each layer its density: the overlap-weighted mean of the samples
that cover it, else an estimate (:func:`~.layer_density.estimate_density`), else none with the reason.
A missing hardness or grain does not refuse the profile: only a layer that the model needs refuses it,
when a PST is set up on it (:mod:`.column`).
"""

from __future__ import annotations

import math

import numpy as np

from .layer_density import estimate_density
from .records import MEASURED, ProfileError, ProfileLayer, metres

__all__ = ["build_layers", "check_samples", "TOLERANCE"]

#: largest mismatch between consecutive layers taken as rounding (m): field profiles are recorded to
#: 0.5-1 cm, so half a millimetre is never snow; a larger gap or overlap is refused
TOLERANCE = 5.0e-4


def check_samples(rows, path: str) -> np.ndarray:
    """Density samples ``(top depth m, thickness m, density kg/m^3)`` as rows (top, bottom, density); checked."""
    out = []
    for k, (d_top, th, rho) in enumerate(rows):
        where = f"{path}: density-profile sample {k} (depth {metres(d_top)} m)"
        th = float("nan") if th is None else float(th)
        if not th > 0.0:
            raise ProfileError(f"{where} thickness", th, "a sample thickness > 0 m")
        if rho is None or not (math.isfinite(float(rho)) and 0.0 < float(rho) <= 917.0):
            raise ProfileError(f"{where} density", rho, "a density in (0, 917] kg/m^3")
        out.append((round(d_top, 6), round(d_top + th, 6), float(rho)))
    return np.array(out, dtype=float).reshape(-1, 3)


def _overlap_means(tops: np.ndarray, bottoms: np.ndarray, samples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per layer: the length covered by samples and the overlap-weighted mean sample density (nan: none).

    Covered length and mass above depth z are sums of ramps, piecewise linear between the samples'
    ends: built once by a sweep, read at the layer boundaries by interpolation (O((n + m) log m)).
    """
    if len(samples) == 0:
        return np.zeros(len(tops)), np.full(len(tops), np.nan)
    st, sb, rho = samples.T
    z = np.concatenate([st, sb])
    order = np.argsort(z, kind="stable")
    z = z[order]
    slope_c = np.cumsum(np.concatenate([np.ones_like(st), -np.ones_like(sb)])[order])
    slope_m = np.cumsum(np.concatenate([rho, -rho])[order])
    dz = np.diff(z)
    C = np.concatenate([[0.0], np.cumsum(slope_c[:-1] * dz)])
    M = np.concatenate([[0.0], np.cumsum(slope_m[:-1] * dz)])
    covered = np.interp(bottoms, z, C) - np.interp(tops, z, C)
    mass = np.interp(bottoms, z, M) - np.interp(tops, z, M)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(covered > TOLERANCE, mass / np.where(covered > 0, covered, 1.0), np.nan)
    return covered, mean


def build_layers(tops, thicknesses, hardness, grain_1, grain_2, samples: np.ndarray, hs: float | None,
                 path: str) -> tuple[ProfileLayer, ...]:
    """The checked layers, top to bottom (module docstring).

    Parameters
    ----------
    tops, thicknesses : sequence of float
        Each layer's top depth below the surface and its thickness (m), top to bottom (nan: not given).
    hardness, grain_1, grain_2 : sequence of str or None
        Hand hardness and grain shapes as recorded.
    samples : numpy.ndarray
        Density samples as rows (top depth, bottom depth, density) (:func:`check_samples`).
    hs : float or None
        The snow depth (m), when the profile gives it.
    path : str
        The file, for messages.

    Raises
    ------
    ProfileError
        No layers, a layer of no thickness, a first layer below the surface, a gap or an overlap between layers,
        layers below the snow depth: one line naming the layer and its depth.
    """
    tops = np.round(np.asarray(tops, dtype=float), 6)
    ths = np.asarray(thicknesses, dtype=float)
    if len(tops) == 0:
        raise ProfileError("profile", path, "a CAAML profile with a stratigraphy (it has no stratigraphy layers)")
    for i, (top, th) in enumerate(zip(tops, ths, strict=True)):
        where = f"{path}: layer {i} (depth {metres(top)}-{metres(top + th)} m)"
        if not th > 0.0:
            raise ProfileError(f"{where} thickness", float(th), "a layer thickness > 0 m")
        expected = 0.0 if i == 0 else tops[i - 1] + ths[i - 1]
        if abs(top - expected) > TOLERANCE:
            if i == 0:
                raise ProfileError(f"{where} depth_top", float(top), "0 m: the first layer starts at the snow surface")
            kind = "a gap" if top > expected else "an overlap"
            raise ProfileError(f"{where} depth_top", float(top), f"{metres(expected)} m, the bottom of layer {i - 1} "
                               f"({kind} of {metres(abs(top - expected))} m: layers must be contiguous; a gap is not "
                               "filled, its snow was not described)")
    if hs is not None and hs > 0 and tops[-1] + ths[-1] > hs + TOLERANCE:
        i = len(tops) - 1
        raise ProfileError(f"{path}: layer {i} (depth {metres(tops[i])}-{metres(tops[i] + ths[i])} m) depth_bottom",
                           float(tops[i] + ths[i]), f"at most the snow depth HS = {metres(hs)} m")
    _, measured = _overlap_means(tops, tops + ths, samples)
    out = []
    for i in range(len(tops)):
        if np.isfinite(measured[i]):
            rho, src = float(measured[i]), MEASURED
        else:
            rho, src = estimate_density(hardness[i], grain_1[i], grain_2[i])
        out.append(ProfileLayer(index=i, depth_top=float(tops[i]), thickness=float(round(ths[i], 6)), density=rho,
                                density_source=src, hardness=hardness[i], grain_1=grain_1[i], grain_2=grain_2[i]))
    return tuple(out)
