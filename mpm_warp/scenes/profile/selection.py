"""Naming the weak layer of a profile: by its depth or its index, and the slab above and layers below it."""

from __future__ import annotations

import math
import numbers

from .records import ProfileError, ProfileLayer, SnowProfileData, metres

__all__ = ["select_weak_layer"]


def _check_density(layers: tuple[ProfileLayer, ...], role: str, source: str) -> None:
    for L in layers:
        if L.density is None:
            raise ProfileError(f"{source}: {L.describe()} density", None,
                               f"a density for a {role} layer: give it a measured density "
                               f"({L.density_source})")


def select_weak_layer(profile: SnowProfileData, depth: float | None = None, index: int | None = None
                      ) -> tuple[tuple[ProfileLayer, ...], ProfileLayer, tuple[ProfileLayer, ...]]:
    """Split a profile at its weak layer, named by ``depth`` or by ``index`` (exactly one).

    Parameters
    ----------
    profile : SnowProfileData
    depth : float, optional
        A depth below the snow surface (m): the weak layer is the layer containing it,
        ``depth_top <= depth < depth_bottom`` (a PST's recorded depth, the top of its failed layer,
        names that layer). Allowed: from the bottom of the surface layer to the bottom of the deepest.
    index : int, optional
        The weak layer's index from the top: 1 to ``len(profile.layers) - 1`` (the surface layer has no slab).

    Returns
    -------
    slab, weak_layer, below : tuple of ProfileLayer, ProfileLayer, tuple of ProfileLayer
        The slab's layers top to bottom (at least one), the weak layer, and the layers under it top
        to bottom (empty when the pit ends at the weak layer).

    Raises
    ------
    ProfileError
        Neither or both of ``depth`` and ``index``; a value outside the allowed range (the line names it
        and the range); a slab or lower layer without a density (a grain form with no density law
        and no measured density: only the weak layer may lack one, its density comes from its own
        parameters).
    """
    layers, src = profile.layers, profile.source
    n = len(layers)
    if (depth is None) == (index is None):
        raise ProfileError("weak layer", {"depth": depth, "index": index}, "exactly one of depth (m) and index")
    if index is not None:
        if isinstance(index, bool) or not isinstance(index, numbers.Integral) or not 1 <= index <= n - 1:
            allowed = f"an integer in [1, {n - 1}]" if n > 1 else "none: the profile has only a surface layer"
            raise ProfileError(f"{src}: weak layer index", index, f"{allowed} (0 is the surface layer, which "
                                                                  "has no slab above it)")
        k = int(index)
    else:
        # layer i holds [its top, the next layer's top): a boundary depth names the layer below it
        lo, hi = (layers[1].depth_top if n > 1 else layers[0].depth_bottom), layers[-1].depth_bottom
        ok = isinstance(depth, numbers.Real) and not isinstance(depth, bool) and math.isfinite(depth)
        if not ok or not lo <= depth < hi:
            raise ProfileError(f"{src}: weak layer depth", depth, f"a depth in [{metres(lo)}, {metres(hi)}) m below "
                                                                  "the surface (below the surface layer, within the "
                                                                  "described layers)")
        k = max(i for i, L in enumerate(layers) if L.depth_top <= depth)
    slab, weak, below = layers[:k], layers[k], layers[k + 1:]
    _check_density(slab, "slab", src)
    _check_density(below, "substratum", src)
    return slab, weak, below
