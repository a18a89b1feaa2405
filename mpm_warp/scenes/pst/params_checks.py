"""The limits that tie a PST's parameters together, checked by :meth:`~mpm_warp.scenes.pst.params.PSTParams.validate`.

A layered slab or substratum replaces its homogeneous keys (:func:`check_layers`); a rigid base takes a sticky
bed and no substratum (:func:`check_rigid_base`); a cracking slab's crack band, ``1.5 dx``,
stays below each layer's largest (:func:`check_crack_band`); the interface closure takes layers at least a grid
cell thick (:func:`check_closure_layers`). Each raises InvalidArgument naming ``where.key``, the value and why.
"""

from __future__ import annotations

import dataclasses

from ...errors import InvalidArgument
from ..snowpack import check_stack

__all__ = ["check_layers", "check_rigid_base", "check_crack_band", "check_closure_layers"]


def check_closure_layers(p, where: str) -> None:
    """The laminate closure smears each grid cell's compliance over layers at least a cell thick (docs/model.md
    §5b); a thinner one diverged on a field column: refuse it."""
    stack = [("slab", k, ly.thickness) for k, ly in enumerate(p.slab_stack())]
    stack += [("substratum", k, ly.thickness) for k, ly in enumerate(p.substratum_stack())]
    for part, k, t in stack:
        if t < p.dx:
            raise InvalidArgument(f"{where}.interface_closure", True, (
                f"false where a layer is thinner than a grid cell ({p.dx * 1e3:.2f} mm): {part} layer {k + 1} "
                f"(from the top) is {t * 1e3:.1f} mm"))


def check_layers(p, part: str, where: str) -> None:
    """Check ``{part}_layers``; refuse them beside a ``{part}``/``{part}_thickness`` that is not the default."""
    layers = getattr(p, f"{part}_layers")
    if not layers:
        return
    check_stack(layers, f"{where}.{part}_layers")
    defaults = type(p).__dataclass_fields__
    for name in (part, f"{part}_thickness"):
        d = defaults[name]
        default = d.default_factory() if d.default_factory is not dataclasses.MISSING else d.default
        if getattr(p, name) != default:
            raise InvalidArgument(f"{where}.{name}", getattr(p, name),
                                  f"left out when {where}.{part}_layers are given (the layers define the {part})")


def check_rigid_base(p, where: str) -> None:
    """On a rigid base: a sticky bed, and the substratum's keys at their defaults (there is none)."""
    if not isinstance(p.rigid_base, bool):
        raise InvalidArgument(f"{where}.rigid_base", p.rigid_base, "true or false")
    if not p.rigid_base:
        return
    if p.bed != "sticky":
        raise InvalidArgument(f"{where}.bed", p.bed, f"'sticky' with {where}.rigid_base = true (the weak "
                              "layer is bonded to the rigid base)")
    default = type(p)()
    for key in ("substratum_layers", "substratum_thickness", "substratum"):
        if getattr(p, key) != getattr(default, key):
            raise InvalidArgument(f"{where}.{key}", getattr(p, key), f"its default with {where}.rigid_base "
                                  "= true (there is no substratum on a rigid base)")


def band_limited_dx(p) -> float:
    """The largest grid spacing (m) at which every slab layer's crack band (a fixed number of cells, ``crack_band /
    dx``) stays below its snap-back width ``2 E G_f / sigma_t^2``, with a 1 % margin; inf for a slab that cannot
    break."""
    if not p.slab_fracture:
        return float("inf")
    widths = [layer.cracking(p.crack_band).max_band_width for layer in p.slab_stack()]
    return 0.99 * min(widths) / (p.crack_band / p.dx)


def check_crack_band(p, where: str) -> None:
    """Each slab layer's crack band below its largest, ``2 E G_f / sigma_t^2``."""
    for i, layer in enumerate(p.slab_stack()):
        mat = layer.cracking(p.crack_band)
        name = f"{where}.slab_layers[{i}]" if p.slab_layers else f"{where}.slab"
        if p.crack_band >= mat.max_band_width:
            raise InvalidArgument(f"{where}.dx", p.dx, (
                f"a spacing whose crack band 1.5 dx stays below 2 E G_f / sigma_t^2 = "
                f"{mat.max_band_width:.3g} m for {name} (sigma_t {mat.tensile_strength:.4g} Pa, G_f "
                f"{mat.fracture_energy:.3g} J/m^2): wider, its softening snaps back"))
