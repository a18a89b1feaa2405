"""The static baseline: a PST's outcome by weac's stresses at the recorded cut, without any dynamics.

SF where the slab's largest tensile stress at the recorded cut reaches its tensile strength (each layer's
strength from its density, Sigrist 2006, or as given), END otherwise: the rule a static model offers. It
never predicts ARR, which is a dynamic outcome. Scored beside the model (:mod:`.scores`), it says what the
dynamics add.
"""

from __future__ import annotations

__all__ = ["weac_static_rule", "weac_static_class"]


def weac_static_rule(params) -> dict:
    """weac's static rule for the field column ``params`` (PSTParams) at its recorded cut: ``class`` ("SF" or "END")
    and ``peak_ratio`` (the slab's largest tensile stress over its layer's strength, -); both None without weac."""
    from ..scenes.density_laws import sigrist_tensile_strength
    from ..scenes.pst.static import static_column
    from ..scenes.weac_reference import slab_stress, weac_unavailable

    if weac_unavailable() is not None:
        return {"class": None, "peak_ratio": None}
    strengths = [ly.tensile_strength if ly.tensile_strength > 0 else sigrist_tensile_strength(ly.density)
                 for ly in params.slab_stack()]
    st = slab_stress(static_column(params), float(params.saw.cut_length), strengths, dx=0.01, dz=0.005)
    ratio = float(st["peak_ratio"])
    return {"class": "SF" if ratio >= 1.0 else "END", "peak_ratio": ratio}


def weac_static_class(params) -> str | None:
    """"SF" or "END" for the field column ``params`` at its recorded cut (:func:`weac_static_rule`); None without
    weac."""
    return weac_static_rule(params)["class"]
