"""The equivalent weak layer: a thin weak layer shown on a grid too coarse for it, as a thicker layer that acts alike.

A field column's grid resolves its weak layer with 3-4 cells (:mod:`.protocol`); a thin layer (0.5-2 cm) then
needs a grid so fine that the column exceeds the per-case particle budget. Such a column is run with an
**equivalent layer** of thickness ``t_eq > t`` (the thinnest the budget's grid resolves) that keeps what the slab
feels of the real layer of thickness ``t``:

- the fracture energy ``w_f`` (J/m^2; or the softening slip ``delta_s``, m) and the shear strength ``tau_p`` (Pa;
  or the bond pressure ``p_bond``): quantities per unit area and stresses, which no thickness enters;
- the collapse height ``h_c`` (m): the real layer's, given explicitly (its own value, else weac's fit of the real
  thickness, :func:`~mpm_warp.scenes.references.weac_collapse_height`), not the fit of ``t_eq``;
- the normal and shear stiffness per unit area, ``E/t`` and ``G/t`` (Pa/m): ``E_eq = E t_eq / t`` at the same
  Poisson's ratio; the floor of the debonded skeleton's consolidation, a pressure given relative to the bulk
  modulus (``p0_floor_ratio``), is scaled by ``t / t_eq`` so that it stays the same pressure (Pa);
- the slab: its depth, layers and load. On the protocol's rigid base the column grows by ``t_eq - t`` under the
  weak layer, where nothing is (the base is rigid, the slab's load is its own weight); on old snow the extra
  thickness comes out of the old snow's top, so the slab's base stays where it was.

weac (an elastic slab on a bed of springs of stiffness ``E/(1 - nu^2)/t`` and ``G/t``) sees the real and the
equivalent layer alike but for where the layer's shear acts: at the lever arm ``(h + t)/2`` from the slab's
mid-plane (``h`` the slab depth). That arm changes by ``(t_eq - t)/(h + t)`` relative to its length, the first-order
bound of the change in weac's critical cut (:attr:`EquivalentLayer.geometry_error`); the equivalence is used only
while that stays within :data:`MAX_GEOMETRY_ERROR`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from ..scenes.pst import PSTParams
from ..scenes.references import weac_collapse_height
from ..scenes.weak_layer import WeakLayer

__all__ = ["EquivalentLayer", "MAX_GEOMETRY_ERROR", "equivalent_weak_layer", "equivalent_params", "thinnest_layer",
           "equivalent_layer", "column_particles",
           "particle_estimate"]

#: the largest lever-arm change (t_eq - t)/(h + t) the equivalence is used at (-): the field studies' tolerance
#: for a grid change, twice the snow ladder's critical-cut error at 6 cells (docs/results/field.md)
MAX_GEOMETRY_ERROR = 0.10
#: the equivalent thickness is rounded up to this (m)
ROUND = 1e-4


@dataclass(frozen=True)
class EquivalentLayer:
    """A real weak layer and the equivalent layer a column is run with (SI units).

    Attributes
    ----------
    thickness : float
        The real layer's thickness ``t`` (m).
    equivalent_thickness : float
        The equivalent layer's thickness ``t_eq`` (m), > ``t``.
    cells : int
        Grid cells across the equivalent layer (-).
    E, E_eq : float
        Young's modulus of the real and of the equivalent layer (Pa): ``E_eq = E t_eq / t``.
    h_c : float
        The collapse height both keep (m): the real layer's.
    slab_depth : float
        The slab's bed-normal depth ``h`` (m).
    """

    thickness: float
    equivalent_thickness: float
    cells: int
    E: float
    E_eq: float
    h_c: float
    slab_depth: float

    @property
    def ratio(self) -> float:
        """``t_eq / t`` (-): the factor on E and on the layer's thickness."""
        return self.equivalent_thickness / self.thickness

    @property
    def dx(self) -> float:
        """The grid spacing (m): ``t_eq / cells``."""
        return self.equivalent_thickness / self.cells

    @property
    def geometry_error(self) -> float:
        """``(t_eq - t)/(h + t)`` (-): the relative change of the lever arm of the layer's shear about the slab's
        mid-plane, the first-order bound of what the equivalence changes in weac's critical cut."""
        return (self.equivalent_thickness - self.thickness) / (self.slab_depth + self.thickness)

    def key(self) -> dict:
        """What identifies the equivalence in a case's key: the thicknesses (m) and the cells."""
        return {"thickness": self.thickness, "equivalent_thickness": self.equivalent_thickness, "cells": self.cells}

    def note(self) -> str:
        """One phrase for the case's setup line."""
        return (f"equivalent weak layer {self.equivalent_thickness * 100:.2f} cm for {self.thickness * 100:.2f} cm "
                f"(E {self.E_eq / 1e6:.3g} MPa for {self.E / 1e6:.3g} MPa, collapse height {self.h_c * 1e3:.2f} mm "
                f"kept)")


def equivalent_weak_layer(layer: WeakLayer, thickness: float, equivalent_thickness: float) -> WeakLayer:
    """The weak layer ``layer`` of ``thickness`` (m) as the equivalent layer of ``equivalent_thickness`` (m).

    ``E`` scaled by ``t_eq / t`` and ``p0_floor_ratio`` by ``t / t_eq``; ``h_c`` the real layer's (its own, else
    :func:`~mpm_warp.scenes.references.weac_collapse_height` of ``thickness``); everything else as given.

    Raises
    ------
    ValueError
        A layer whose collapse is given by ``xi``: its collapse height depends on the thickness, so there is no
        height to keep.
    """
    if layer.xi > 0:
        raise ValueError("the weak layer's collapse is given by xi, not a collapse height: no height to keep")
    r = equivalent_thickness / thickness
    h_c = layer.h_c if layer.h_c > 0 else weac_collapse_height(thickness)
    return dataclasses.replace(layer, E=layer.E * r, h_c=h_c, p0_floor_ratio=layer.p0_floor_ratio / r)


def equivalent_params(params: PSTParams, equivalent_thickness: float) -> PSTParams:
    """``params`` with its weak layer replaced by the equivalent one of ``equivalent_thickness`` (m); on old snow
    the extra thickness is taken from the old snow's top (its depth may then fall below what the grid allows:
    :meth:`~mpm_warp.scenes.pst.PSTParams.validate` says so)."""
    t = params.weak_layer_thickness
    out = dataclasses.replace(params, weak_layer_thickness=equivalent_thickness,
                              weak_layer=equivalent_weak_layer(params.weak_layer, t, equivalent_thickness))
    if params.rigid_base:
        return out
    extra = equivalent_thickness - t
    if not params.substratum_layers:
        return dataclasses.replace(out, substratum_thickness=max(params.substratum_thickness - extra, 1e-6))
    layers = list(params.substratum_layers)       # top to bottom: whole layers go while the extra exceeds them
    while len(layers) > 1 and extra >= layers[0].thickness:
        extra -= layers.pop(0).thickness
    layers[0] = dataclasses.replace(layers[0], thickness=max(layers[0].thickness - extra, 1e-6))
    return dataclasses.replace(out, substratum_layers=tuple(layers))


def particle_estimate(p: PSTParams) -> int:
    """Particles of the 2D column ``p`` (-): its area over the particle spacing squared."""
    height = p.slab_depth + p.weak_layer_thickness + p.substratum_depth
    spacing = p.dx / p.particles_per_cell
    return int(math.ceil(p.length * height / spacing ** 2))


def column_particles(params: PSTParams, t_eq: float, cells: int) -> int:
    """Particles (-) of the column ``params`` with an equivalent layer of ``t_eq`` (m) at ``cells`` cells across it."""

    p = equivalent_params(params, t_eq)
    return particle_estimate(dataclasses.replace(p, dx=t_eq / cells))


def thinnest_layer(params: PSTParams, cells: int, max_particles: int) -> float | None:
    """The thinnest equivalent layer (m, rounded up to 0.1 mm) whose column fits ``max_particles`` with ``cells``
    grid cells across it; None when none up to the slab's depth does (the particles fall as the layer thickens:
    bisection)."""
    lo, hi = params.weak_layer_thickness, max(params.slab_depth, params.weak_layer_thickness)
    if column_particles(params, hi, cells) > max_particles:
        return None
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if column_particles(params, mid, cells) > max_particles else (lo, mid)
    t_eq = math.ceil(hi / ROUND - 1e-9) * ROUND
    while column_particles(params, t_eq, cells) > max_particles:
        t_eq += ROUND
    return t_eq


def equivalent_layer(params: PSTParams, cells_options, max_particles: int) -> EquivalentLayer | str:
    """The equivalent layer the column ``params`` runs with under a budget of ``max_particles``: the thinnest that
    fits at the first of ``cells_options`` (e.g. the protocol's 4 cells, then 3) whose lever-arm change stays
    within :data:`MAX_GEOMETRY_ERROR`; else one line saying why there is none."""
    t, h = params.weak_layer_thickness, params.slab_depth
    if params.weak_layer.xi > 0:
        return "its weak layer's collapse is given by xi, so an equivalent layer has no collapse height to keep"
    t_max = t + MAX_GEOMETRY_ERROR * (h + t)
    tried = []
    for cells in cells_options:
        t_eq = thinnest_layer(params, cells, max_particles)
        if t_eq is not None and t_eq <= t_max:
            layer = equivalent_weak_layer(params.weak_layer, t, t_eq)
            return EquivalentLayer(t, t_eq, cells, params.weak_layer.E, layer.E, layer.h_c, h)
        tried.append(f"{t_eq * 100:.2f} cm at {cells} cells" if t_eq is not None else f"none at {cells} cells")
    return (f"no equivalent weak layer fits either: the thinnest ({', '.join(tried)}) would move the layer's shear "
            f"by more than {MAX_GEOMETRY_ERROR:.0%} of its lever arm (thicker than {t_max * 100:.2f} cm)")
