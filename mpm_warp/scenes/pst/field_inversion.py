"""A field PST read backwards: the weak layer's fracture energy that a recorded critical cut implies.

A PST record ``PST 32/100 (End) down 48 cm`` says that at a cut of 32 cm the crack ran on its own. weac's
energy release rate of that column at that cut is the weak layer's fracture energy by the energy criterion
``G(a_c) = G_c`` (docs/weac.md, docs/profiles.md): the number to give as ``scene.weak_layer.w_f`` when the
profile is all one knows about the layer. The column is the profile's, expanded as a ``[scene.profile]``
table would be (:func:`~.from_profile.expand_profile`), with the weak layer's other quantities as given.
"""

from __future__ import annotations

import os

from ...loader import from_table
from .from_profile import expand_profile
from .params import PSTParams
from .static import static_column

__all__ = ["field_fracture_energy"]


def field_fracture_energy(profile_file: str, record, scene: dict | None = None) -> dict:
    """weac's energy release rate of a recorded PST's column at its critical cut.

    Parameters
    ----------
    profile_file : str
        The CAAML profile the record comes from.
    record : PSTRecord
        The PST (its cut length, column length and depth; :mod:`mpm_warp.scenes.profile`).
    scene : dict, optional
        ``[scene]`` entries beside the profile (``weak_layer``, ``column_ends``, ``saw.cut_from``, ...); the
        defaults of :class:`~.params.PSTParams` otherwise.

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
    table = dict(scene or {})
    table["profile"] = {"file": os.path.abspath(profile_file), "weak_layer_depth": float(record.depth)}
    table["length"] = float(record.column_length)
    table["saw"] = {**table.get("saw", {}), "cut_length": float(record.cut_length)}
    table = expand_profile(table)
    table.setdefault("dx", table["weak_layer_thickness"] / 4.0)  # weac needs no grid; any that resolves the layer
    params = from_table(PSTParams, table, "scene").validate("scene")
    G, G_I, G_II = energy_release_rate(static_column(params), float(record.cut_length))
    return {"G": G, "G_I": G_I, "G_II": G_II, "cut": float(record.cut_length), "params": params}
