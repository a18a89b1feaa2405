"""A PST column cut from a profile at the recorded failure depth: the slab above it, a weak layer, the snow below.

The slab ends where the observer saw the failure: at the PST's recorded depth, splitting the profile layer
that holds it. The weak layer under it is thin, as weak layers are: its thickness is (docs/profiles.md, "The
weak layer"):

1. given (a PST record or the user);
2. the profile layer's, when the layer that holds the depth is at most :data:`WEAK_LAYER_DEFAULT` thick:
   a thin layer the observer described as its own layer (at least :data:`WEAK_LAYER_MIN`, the resolution
   of a profile). The slab then ends at that layer's top, at most 3 cm above the recorded depth (which a
   profile gives to 1 cm);
3. otherwise :data:`WEAK_LAYER_DEFAULT`, the weak-layer thickness weac assumes (30 mm), for every grain
   form: a profile layer of 12-88 cm (the development set's median and largest) is where the failure
   lies, not how thick the failing layer is.

The snow below the weak layer down to the substratum depth is the substratum. Every length here is as the
profile records it (vertical); the scene converts to bed-normal. A layer the column needs and cannot use
is refused in one line in field terms (:class:`~.records.ProfileError`).
"""

from __future__ import annotations

from dataclasses import dataclass

from .layer_density import FALLBACK
from .records import ProfileError, ProfileLayer, SnowProfileData

__all__ = ["ColumnPart", "ProfileColumn", "profile_column", "WEAK_LAYER_DEFAULT", "WEAK_LAYER_MIN", "DENSITY_RANGE"]

#: weak-layer thickness where the profile gives none thinner (m): weac's default weak layer, 30 mm
WEAK_LAYER_DEFAULT = 0.03
#: thinnest weak layer taken from a profile (m): profiles record depths to 0.5-1 cm, so a thinner layer's
#: thickness is below what the record resolves
WEAK_LAYER_MIN = 0.01
#: densities the slab and substratum may have (kg/m^3): seasonal dry snow; outside, the entry is doubted
DENSITY_RANGE = (50.0, 600.0)
#: how close (m) the recorded depth must lie to a layer's top to name that layer (field records are to 1 cm)
_AT_TOP = 0.005
#: slab or substratum pieces thinner than this (m) are the rounding of a split, not snow
_SLIVER = 1e-3


def _cm(x: float) -> str:
    return f"{x * 100:.3g}"


@dataclass(frozen=True)
class ColumnPart:
    """A piece of a profile layer in the column: its vertical thickness (m), density (kg/m^3) and description."""

    thickness: float
    density: float
    name: str
    measured: bool


@dataclass(frozen=True)
class ProfileColumn:
    """The column of a PST record: slab, weak layer and substratum (vertical lengths in m).

    Attributes
    ----------
    depth : float
        The slab's thickness (m): the recorded failure depth, or the top of the thin layer that holds it.
    slab, substratum : tuple of ColumnPart
        Top to bottom; the substratum may be empty (the scene's default old snow then).
    weak_layer_thickness : float
        Vertical thickness of the weak layer (m).
    weak_layer_choice : str
        Why this thickness (which of the module's rules).
    weak_layer : ProfileLayer
        The profile layer that holds the failure depth.
    notes : tuple of str
        Flags in field terms: estimated densities, a substratum cut short.
    """

    depth: float
    slab: tuple[ColumnPart, ...]
    weak_layer_thickness: float
    weak_layer_choice: str
    weak_layer: ProfileLayer
    substratum: tuple[ColumnPart, ...]
    notes: tuple[str, ...]


def _span(top: float, bottom: float) -> str:
    return f"{_cm(top)}-{_cm(bottom)} cm"


def _grains(ly: ProfileLayer) -> str:
    return "/".join(g for g in (ly.grain_1, ly.grain_2) if g) or "no grain"


def _part(ly: ProfileLayer, top: float, bottom: float, role: str) -> ColumnPart:
    """The piece ``[top, bottom]`` of ``ly`` as a column part; ProfileError where its density cannot be used."""
    what = f"the {role} layer at {_span(top, bottom)} ({_grains(ly)}, hardness {ly.hardness or 'not recorded'})"
    if ly.density is None:
        allowed = "a density: record its hand hardness and grain form, or its density"
        raise ProfileError(what, None, allowed, f"{what} has no density ({ly.density_source}): record its hand "
                                                "hardness and grain form, or its density")
    lo, hi = DENSITY_RANGE
    if not lo <= ly.density <= hi:
        how = "measured" if ly.measured else "estimated"
        allowed = f"a density in [{lo:g}, {hi:g}] kg/m^3, that of seasonal dry snow"
        raise ProfileError(what, ly.density, allowed, f"{what} has a {how} density of {ly.density:.0f} kg/m^3, "
                                                      f"outside the {lo:g}-{hi:g} kg/m^3 of seasonal dry snow: "
                                                      "check the entry")
    name = f"{_grains(ly)} {ly.hardness or ''}".strip()
    return ColumnPart(bottom - top, float(ly.density), f"{name}, {ly.density:.0f} kg/m3 "
                                                       f"({'measured' if ly.measured else 'estimated'})", ly.measured)


def _pieces(layers, top: float, bottom: float):
    """``(layer, piece top, piece bottom)`` of the layers within ``[top, bottom]``, top to bottom."""
    for ly in layers:
        a, b = max(ly.depth_top, top), min(ly.depth_bottom, bottom)
        if b - a > _SLIVER:
            yield ly, a, b


def _weak_layer(weak: ProfileLayer, depth: float, given: float | None) -> tuple[float, float, str]:
    """``(slab depth, weak-layer thickness, why)``: the module's rules (m, vertical)."""
    if given:
        return depth, float(given), "given"
    if weak.thickness <= WEAK_LAYER_DEFAULT + 1e-9:
        top = weak.depth_top
        at = "" if abs(depth - top) <= _AT_TOP else f"; the failure recorded at {_cm(depth)} cm lies in it"
        if weak.thickness < WEAK_LAYER_MIN:
            return top, WEAK_LAYER_MIN, (f"the profile layer's ({_grains(weak)}, {weak.thickness * 100:.3g} cm) taken "
                                         f"as {WEAK_LAYER_MIN * 100:g} cm, the resolution of a profile{at}")
        return top, weak.thickness, f"the profile layer's own ({_grains(weak)}, {weak.thickness * 100:.3g} cm{at})"
    return depth, WEAK_LAYER_DEFAULT, (f"the default {WEAK_LAYER_DEFAULT * 100:g} cm (weac's): the profile layer "
                                       f"{_span(weak.depth_top, weak.depth_bottom)} ({_grains(weak)}) is where the "
                                       "failure lies, not its thickness")


def profile_column(profile: SnowProfileData, depth: float, weak_layer_thickness: float | None = None,
                   substratum_depth: float = 0.15) -> ProfileColumn:
    """The column of a PST that failed at ``depth`` (module docstring).

    Parameters
    ----------
    profile : SnowProfileData
    depth : float
        The recorded failure depth (m below the surface, vertical), inside the described layers.
    weak_layer_thickness : float, optional
        The weak layer's thickness (m, vertical) when known; None: by the module's rules.
    substratum_depth : float
        How much snow under the weak layer to take (m, vertical), >= 0.

    Raises
    ------
    ProfileError
        A depth at the surface or below the described layers, a slab layer without a usable density (one line
        naming the layer by its depth in cm, its grains and hardness, and what to change).
    """
    layers = profile.layers
    bottom = layers[-1].depth_bottom
    if not 0.0 < depth < bottom:
        allowed = f"a depth in (0, {_cm(bottom)}) cm: inside the described layers, with a slab above it"
        where = ("at the surface: there is no slab above it" if depth <= 0.0 else
                 f"at or below the bottom of the described layers ({_cm(bottom)} cm): the weak layer was not "
                 "described")
        raise ProfileError("the failure depth", depth, allowed, f"the failure depth {_cm(depth)} cm is {where}")
    weak = max((ly for ly in layers if ly.depth_top <= depth + 1e-9), key=lambda ly: ly.depth_top)
    depth, d_wl, choice = _weak_layer(weak, depth, weak_layer_thickness)
    if depth <= 0.0:
        allowed = "a weak layer with a slab above it"
        raise ProfileError("the failure depth", depth, allowed, f"the failing layer {_grains(weak)} is the surface "
                                                                "layer: there is no slab above it")
    slab = tuple(_part(ly, a, b, "slab") for ly, a, b in _pieces(layers, 0.0, depth))
    notes = [f"slab layer {_span(a, b)}: {ly.density:.0f} kg/m^3 by {ly.density_source}"
             for ly, a, b in _pieces(layers, 0.0, depth) if ly.density_source.startswith(FALLBACK)]
    sub, end = [], depth + d_wl + substratum_depth
    for ly, a, b in _pieces(layers, depth + d_wl, end):
        try:
            sub.append(_part(ly, a, b, "substratum"))
        except ProfileError as e:
            notes.append(f"the substratum ends at {_cm(a)} cm: {e}")
            break
    return ProfileColumn(depth=float(depth), slab=slab, weak_layer_thickness=float(d_wl), weak_layer_choice=choice,
                         weak_layer=weak, substratum=tuple(sub), notes=tuple(notes))


def describe(col: ProfileColumn) -> str:
    """One line: ``slab 80 cm (4 layers), weak layer 3 cm (why)``."""
    n = len(col.slab)
    return (f"slab {_cm(col.depth)} cm ({n} layer{'s' if n != 1 else ''}), weak layer "
            f"{col.weak_layer_thickness * 100:.3g} cm "
            f"({col.weak_layer_choice}), substratum {_cm(sum(p.thickness for p in col.substratum))} cm")


__all__ += ["describe"]
