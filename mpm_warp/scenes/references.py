"""Closed-form references of the snow experiments (docs/model.md §3b, 6-7), in SI units: one home for each formula.

- Heierli (2005), elastic slab on a collapsing layer, ``D_f = E h^3 / 12``: crack speed
  ``c = (g D_f / (2 h_f rho h))^(1/4)``, touchdown distance ``l = 2.331 (2 h_f D_f / (g rho h))^(1/4)``.
- Critical cut length on flat ground (Gaume et al. 2017): ``a_c = sqrt(2 tau_p E' D_wl / (G_wl rho g))``,
  ``E' = E / (1 - nu^2)``.

The slab's Rayleigh and shear-wave speeds are properties of its material
(:attr:`mpm_warp.materials.Elastic.rayleigh_speed`), the weak layer's collapse under a load the
hardening law (:func:`mpm_warp.materials.hardening_collapse`).
"""

from __future__ import annotations

import math

from .snow import GRAVITY

__all__ = ["heierli_speed", "heierli_touchdown", "critical_cut_length_formula", "weac_collapse_height"]


def heierli_speed(E: float, h: float, rho: float, h_f: float, g: float = GRAVITY) -> float:
    """Heierli's anticrack speed ``(g D_f / (2 h_f rho h))^(1/4)`` (m/s); inf for ``h_f <= 0``."""
    if h_f <= 0:
        return math.inf
    D_f = E * h**3 / 12.0
    return (g * D_f / (2.0 * h_f * rho * h)) ** 0.25


def heierli_touchdown(E: float, h: float, rho: float, h_f: float, g: float = GRAVITY) -> float:
    """Heierli's touchdown distance ``2.331 (2 h_f D_f / (g rho h))^(1/4)`` (m)."""
    D_f = E * h**3 / 12.0
    return 2.331 * (2.0 * max(h_f, 0.0) * D_f / (g * rho * h)) ** 0.25


def critical_cut_length_formula(tau_p: float, E: float, nu: float, D_wl: float, G_wl: float, rho: float,
                                g: float = GRAVITY) -> float:
    """Flat-ground critical cut length ``sqrt(2 tau_p E' D_wl / (G_wl rho g))`` (m), ``E' = E/(1-nu^2)``."""
    return math.sqrt(2.0 * tau_p * E / (1.0 - nu**2) * D_wl / (G_wl * rho * g))


def weac_collapse_height(D_wl: float) -> float:
    """WEAC fit of the weak-layer collapse height ``h_c = 4.70 (1 - exp(-D_wl / 7.78 mm)) mm`` (m; ``D_wl`` in m).

    Rosendahl and Weissgraeber (2020), fitted to the PST collapse heights of van Herwijnen et al. (2016).
    """
    return 4.70e-3 * (1.0 - math.exp(-D_wl / 7.78e-3))
