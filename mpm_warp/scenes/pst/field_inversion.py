"""A field PST read backwards: the weak layer's fracture energy that a recorded critical cut implies.

A PST record ``PST 32/100 (End) down 48 cm`` says that at a cut of 32 cm the crack ran on its own. weac's
energy release rate of that column at that cut is the weak layer's fracture energy by the energy criterion
``G(a_c) = G_c`` (docs/weac.md, docs/profiles.md): the number to give as ``scene.weak_layer.w_f`` when the
profile is all one knows about the layer. The column is the profile's, expanded as a ``[scene.profile]``
table would be (:func:`~.from_profile.expand_profile`), with the weak layer's other quantities as given.
"""

from __future__ import annotations

import dataclasses
import os

from ..snowpack import SnowLayer
from .from_profile import expand_profile
from .params import PSTParams
from .static import static_column

__all__ = ["field_fracture_energy"]


def field_fracture_energy(profile_file: str, record, params: PSTParams | None = None) -> dict:
    """weac's energy release rate of a recorded PST's column at its critical cut.

    Parameters
    ----------
    profile_file : str
        The CAAML profile the record comes from.
    record : PSTRecord
        The PST (its cut length, column length and depth; :mod:`mpm_warp.scenes.profile`).
    params : PSTParams, optional
        What the profile does not give: the weak layer's E and nu, ``column_ends``, ``saw.cut_from``; the
        defaults of :class:`~.params.PSTParams` otherwise. Its slab, weak layer thickness, substratum, length,
        slope and cut are the profile's and the record's.

    Returns
    -------
    dict
        ``G``, ``G_I``, ``G_II`` (J/m^2) at the record's cut, ``cut`` (m), ``params`` (the column as PSTParams),
        or ``note`` (one line) when the record lacks a depth or column length, or weac is not installed.
    """
    from ..weac_reference import energy_release_rate, weac_unavailable

    if record.depth is None or record.column_length is None:
        return {"note": f"{record.field_line()}: no depth or column length recorded, nothing to read back"}
    if weac_unavailable() is not None:
        return {"note": weac_unavailable()}
    base = params if params is not None else PSTParams()
    table = expand_profile({"profile": {"file": os.path.abspath(profile_file), "weak_layer_depth": float(record.depth)},
                            "substratum_thickness": base.substratum_thickness})
    weak = base.weak_layer
    if "density" in table.get("weak_layer", {}):
        weak = dataclasses.replace(weak, density=table["weak_layer"]["density"])
    column = dataclasses.replace(
        base, slab_layers=tuple(SnowLayer(**ly) for ly in table["slab_layers"]),
        substratum_layers=tuple(SnowLayer(**ly) for ly in table.get("substratum_layers", ())),
        weak_layer_thickness=table["weak_layer_thickness"], weak_layer=weak, slope_angle=table["slope_angle"],
        length=float(record.column_length), dx=table["weak_layer_thickness"] / 4.0,   # weac needs no grid
        saw=dataclasses.replace(base.saw, cut_length=float(record.cut_length)), profile=base.profile)
    column = column.validate("scene")
    G, G_I, G_II = energy_release_rate(static_column(column), float(record.cut_length))
    return {"G": G, "G_I": G_I, "G_II": G_II, "cut": float(record.cut_length), "params": column}
