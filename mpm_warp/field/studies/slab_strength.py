"""The slab's tensile strength as a what-if: every layer scaled, or only those of faceted snow.

The model takes a slab layer's tensile strength from its density (Sigrist 2006, docs/model.md §9), which has no
grain form; in situ, faceted snow was about half as strong in tension as rounded snow of the same density
(Jamieson and Johnston 1990, docs/field.md). :func:`weaker` scales a field case's slab strengths, no default
changes; :func:`faceted_share` says how much of a slab is faceted.
"""

from __future__ import annotations

import dataclasses

from ...scenes.density_laws import sigrist_tensile_strength

__all__ = ["FACETED", "faceted", "faceted_share", "weaker"]

#: primary grain forms of faceted snow (IACS classes FC and DH, every subclass)
FACETED = ("FC", "DH")


def faceted(layer) -> bool:
    """Whether a field column's slab layer is of faceted snow: its name starts with its grains, primary first
    (``"FCxr/RG 4F, 180 kg/m3 (estimated)"``, docs/profiles.md)."""
    return (layer.name or "").startswith(FACETED)


def faceted_share(params) -> float:
    """The share of a column's slab thickness that is faceted snow (-)."""
    layers = params.slab_stack()
    return sum(ly.thickness for ly in layers if faceted(ly)) / sum(ly.thickness for ly in layers)


def weaker(case, scale: float, facets: float = 1.0):
    """``case`` with every slab layer's tensile strength ``scale`` times its density law's (Pa), ``facets`` times
    more for a layer of faceted snow, and nothing else changed; a layer given its own strength keeps it scaled the
    same way."""
    def scaled(layer):
        base = layer.tensile_strength or sigrist_tensile_strength(layer.density)
        return dataclasses.replace(layer, tensile_strength=scale * base * (facets if faceted(layer) else 1.0))

    p = case.params
    if p.slab_layers:
        p = dataclasses.replace(p, slab_layers=tuple(scaled(ly) for ly in p.slab_layers))
    else:
        p = dataclasses.replace(p, slab=scaled(p.slab))
    return dataclasses.replace(case, params=p.validate("scene"))
