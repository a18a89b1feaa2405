"""Naming the layer that stops the CAAML library: a walk over the raw XML layers after a failed read.

snowprofile checks a whole table at once ("Unauthorized value for key hardness"); to refuse in one
line that names the layer, the stratigraphy and density layers are looked at one by one here, in
file order, with the codes of :mod:`..density_laws`.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from ..density_laws import GRAIN_CLASS, HARDNESS_INDEX
from .records import ProfileError, metres

__all__ = ["diagnose_layers"]

#: values CAAML allows for a datum that is not given (read as absent)
_ABSENT = {"inapplicable", "missing", "template", "unknown", "withheld"}


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _child_text(elem: ET.Element, name: str) -> str | None:
    for c in elem:
        if _local(c.tag) == name:
            t = (c.text or "").strip()
            return None if not t or t in _ABSENT else t
    return None


def _number(text: str | None) -> float | None:
    try:
        v = float(text)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _layers_of(root: ET.Element, profile: str):
    for prof in root.iter():
        if _local(prof.tag) == profile:
            yield from (e for e in prof if _local(e.tag) == "Layer")


def diagnose_layers(data: bytes, path: str) -> None:
    """Raise :class:`ProfileError` for the first stratigraphy or density layer with a bad value; else return."""
    try:
        root = ET.fromstring(data)
    except (ET.ParseError, ValueError, LookupError, RecursionError):
        return
    for i, layer in enumerate(_layers_of(root, "stratProfile")):
        top = _number(_child_text(layer, "depthTop"))
        th = _number(_child_text(layer, "thickness"))
        depth = "?" if top is None else metres(top / 100.0)
        where = f"{path}: layer {i} in the file (depth {depth} m)"
        if top is None:
            raise ProfileError(f"{where} depthTop", _child_text(layer, "depthTop"), "a depth in cm")
        if th is None:
            raise ProfileError(f"{where} thickness", _child_text(layer, "thickness"), "a thickness in cm")
        hardness = _child_text(layer, "hardness")
        if hardness is not None and hardness not in HARDNESS_INDEX:
            raise ProfileError(f"{where} hardness", hardness, "a hand hardness: F, 4F, 1F, P, K, I, e.g. '4F-1F', "
                                                              "'1F+'")
        for name in ("grainFormPrimary", "grainFormSecondary"):
            grain = _child_text(layer, name)
            if grain is not None and grain not in GRAIN_CLASS:
                raise ProfileError(f"{where} {name}", grain, "an IACS grain shape code, e.g. 'RG', 'FCxr', 'SH'")
    for k, layer in enumerate(_layers_of(root, "densityProfile")):
        top = _number(_child_text(layer, "depthTop"))
        where = f"{path}: density-profile sample {k} in the file (depth {'?' if top is None else metres(top / 100)} m)"
        for name in ("depthTop", "thickness"):
            if _number(_child_text(layer, name)) is None:
                raise ProfileError(f"{where} {name}", _child_text(layer, name), "a length in cm")
        rho = _number(_child_text(layer, "density"))
        if rho is None or not 0.0 < rho <= 917.0:
            raise ProfileError(f"{where} density", _child_text(layer, "density"), "a density in (0, 917] kg/m^3")
