"""Closed-form readings of a field column's slab: candidate mechanisms for why some slabs break in a PST.

Each takes a field column (PSTParams) and returns one number, from independent published laws only (no fitted
factor), so that its power to tell the observers' SF records from their END records can be measured
(benchmarks/field/mechanisms.py; docs/field.md, "Why thin, light slabs break"):

- :func:`touchdown_distance`: Heierli's touchdown distance of the slab over its collapsed weak layer (Heierli,
  Gumbsch and Zaiser 2008), with the layered slab's plane-strain bending stiffness and weac's collapse height
  (Rosendahl and Weissgraeber 2020). A slab whose touchdown distance is shorter than the column lands on the
  collapsed layer inside the column, and is bent there, before the crack reaches the far end.
- :func:`brittleness`: the slab's depth over its characteristic length ``E G_f / sigma_t^2`` (Hillerborg et al.
  1976), with ``G_f = K_Ic^2 (1 - nu^2) / E`` (Schweizer, Michot and Kirchner 2004) and Sigrist's strength: the
  larger, the more a notch-free slab fails by its strength rather than by its toughness.
"""

from __future__ import annotations

import math

import numpy as np

from ..scenes.density_laws import fracture_toughness, sigrist_tensile_strength
from ..scenes.references import GRAVITY, weac_collapse_height

__all__ = ["slab_bending_stiffness", "touchdown_distance", "brittleness"]


def slab_bending_stiffness(params) -> float:
    """The layered slab's plane-strain bending stiffness about its neutral axis, ``D11 - B11^2 / A11`` (N m)."""
    slab = params.slab_stack()
    z = np.concatenate([[0.0], np.cumsum([ly.thickness for ly in slab])])
    Ep = np.array([ly.modulus / (1.0 - ly.nu**2) for ly in slab])
    A = float(np.sum(Ep * np.diff(z)))
    B = float(np.sum(Ep * np.diff(z**2))) / 2.0
    D = float(np.sum(Ep * np.diff(z**3))) / 3.0
    return D - B * B / A


def touchdown_distance(params) -> float:
    """Heierli's touchdown distance ``2.331 (2 h_f D / q)^(1/4)`` (m) of the column's slab: ``D`` its bending
    stiffness (:func:`slab_bending_stiffness`), ``q`` its weight per unit area normal to the slope (Pa), ``h_f``
    weac's collapse height of the weak layer's thickness (m)."""
    slab = params.slab_stack()
    q = sum(ly.thickness * ly.density for ly in slab) * GRAVITY * math.cos(math.radians(params.slope_angle))
    h_f = weac_collapse_height(params.weak_layer_thickness)
    return 2.331 * (2.0 * h_f * slab_bending_stiffness(params) / q) ** 0.25


def brittleness(params) -> float:
    """The slab's depth over its thickness-weighted characteristic length ``K_Ic^2 (1 - nu^2) / sigma_t^2`` (-)."""
    slab = params.slab_stack()
    depth = sum(ly.thickness for ly in slab)
    l_ch = sum(ly.thickness * fracture_toughness(ly.density) ** 2 * (1.0 - ly.nu**2)
               / sigrist_tensile_strength(ly.density) ** 2 for ly in slab) / depth
    return depth / l_ch
