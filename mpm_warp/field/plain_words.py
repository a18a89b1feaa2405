"""The model's refusals of a field column, said in field quantities (no internal parameter names).

Building a column checks the scene's parameters and calibrates the weak layer; where either refuses, the
reason is one of the model's own quantities (``kappa_s``, ``scene.dx``, ``tau_p``). :func:`in_field_terms`
says it as the observer's quantities: the slab's load, the weak layer's fracture energy and strength, the
snow's density, with what to change.
"""

from __future__ import annotations

from ..errors import InvalidArgument

__all__ = ["in_field_terms", "INTERNAL_NAMES"]

#: names a user-facing refusal never contains
INTERNAL_NAMES = ("kappa_s", "material[", "margin", "p_bond", "xi", "delta_s", "scene.")


def _load(params) -> str:
    if params is None:
        return "this slab"
    return f"this slab ({params.slab_depth * 100:.0f} cm, {params.sigma_n:.0f} Pa on the weak layer)"


def in_field_terms(e: InvalidArgument, params) -> tuple[str, str]:
    """``(reason class, message)`` for a refusal ``e`` raised while building the field column ``params``."""
    field = str(getattr(e, "field", ""))
    load = _load(params)
    w_f = e.value if field == "w_f" else (None if params is None else params.weak_layer.w_f)
    if field in ("kappa_s", "w_f", "delta_s"):
        reached = getattr(e, "reached", None)
        if reached is not None and w_f is not None and field == "w_f":
            side, bound = ("below the least", "least") if w_f < reached else ("above the most", "most")
            return "fracture energy", (f"a weak-layer fracture energy of {w_f:.3g} J/m^2 is {side} the model's weak "
                                       f"layer dissipates under {load} (about {reached:.2g} J/m^2, its {bound}): "
                                       "outside what the model represents for this column")
        what = "a weak-layer fracture energy" + ("" if w_f is None else f" of {w_f:.3g} J/m^2")
        return "fracture energy", (f"{what} under {load} is outside what the "
                                   "model's weak layer can dissipate under this load (its bond never breaks in the "
                                   "shear test of the calibration)")
    if field in ("tau_p", "p_bond"):
        tau = "its shear strength" if params is None else f"its shear strength of {params.weak_layer.tau_p:g} Pa"
        allowed = str(getattr(e, "allowed", ""))
        if "debonded skeleton" in allowed:
            return "strength", (f"{tau} is below what the broken weak layer still carries under {load}: give the "
                                "layer's measured shear strength")
        if "compaction" in allowed:
            return "strength", (f"under {load} a weak layer of {tau} collapses in compression before it fails in "
                                "shear: the model's weak layer needs a higher shear strength for this load (give the "
                                "layer's measured strength)")
        return "collapse", (f"{load} crushes the weak layer (of {tau}) before any cut: the model's weak layer cannot "
                            "carry it")
    if field in ("h_c", "xi", "sigma_n"):
        return "collapse", (f"{load} crushes the weak layer before any cut (its strength in compression is below "
                            "the load): the model's weak layer cannot carry it")
    if field.endswith(".interface_closure"):
        cell, _, thin = str(getattr(e, "allowed", "")).partition("): ")
        return "thin layer", (f"the laminate closure needs every layer at least a grid cell thick, and {thin}, under "
                              f"the {cell.rsplit('(', 1)[-1]} cell the weak layer sets: run this column without "
                              "--interface-closure")
    if field.endswith(".dx"):
        layer = f"the {params.weak_layer_thickness * 100:.2g} cm weak layer" if params is not None else "its weak layer"
        return "grid", (f"the slab's snow is too brittle for the grid {layer} sets (its crack band would be wider "
                        "than the snow's fracture length)")
    return "model range", f"outside the model's range: {_field_words(e)}"


def _field_words(e: InvalidArgument) -> str:
    text = str(e)
    for name in INTERNAL_NAMES:
        text = text.replace(name, "")
    return text
