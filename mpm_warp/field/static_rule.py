"""The static baseline: a PST's outcome by weac's stresses at the recorded cut, without any dynamics.

SF where the slab's largest tensile stress at the recorded cut reaches its tensile strength (each layer's
strength from its density, Sigrist 2006, or as given), END otherwise: the rule a static model offers. It
never predicts ARR, which is a dynamic outcome. Scored beside the model (:mod:`.scores`), it says what the
dynamics add.
"""

from __future__ import annotations

from .static_view import static_view

__all__ = ["weac_static_rule", "weac_static_class"]


def weac_static_rule(params) -> dict:
    """weac's static rule for the field column ``params`` (PSTParams) at its recorded cut: ``class`` ("SF" or "END")
    and ``peak_ratio`` (the slab's largest tensile stress over its layer's strength, -); both None without weac.
    The case's :class:`~.static_view.StaticView` holds both."""
    view = static_view(params)
    return {"class": view.static_class, "peak_ratio": view.peak_ratio}


def weac_static_class(params) -> str | None:
    """"SF" or "END" for the field column ``params`` at its recorded cut (:func:`weac_static_rule`); None without
    weac."""
    return weac_static_rule(params)["class"]
