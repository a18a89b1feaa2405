"""weac's static answer beside a PST: the same column in weac, its critical cut and energy release rate.

The column (:func:`static_column`): the slab's layers with their E and nu, the weak layer's E, nu and
thickness (weac's bed of springs), the column length, the slope, the end the saw starts from and the end
faces. The energy criterion is ``G = G_c`` with ``G_c`` the weak layer's fracture energy ``w_f`` as given
(docs/weac.md). weac is an optional dependency: without it the answer says so in one line.
"""

from __future__ import annotations

import functools
import math

from ..weac_reference import (
    StaticColumn,
    WeacUnavailable,
    critical_cut_search,
    energy_release_rate,
    weac_unavailable,
    weac_version,
)
from .params import PSTParams

__all__ = ["static_column", "weac_answer"]


def static_column(params: PSTParams) -> StaticColumn:
    """The PST ``params`` as weac sees it (:class:`~mpm_warp.scenes.weac_reference.StaticColumn`)."""
    wl = params.weak_layer
    return StaticColumn(slab=tuple((ly.thickness, ly.density, ly.modulus, ly.nu) for ly in params.slab_stack()),
                        weak_layer_thickness=params.weak_layer_thickness, weak_layer_E=wl.E, weak_layer_nu=wl.nu,
                        length=params.length, slope_angle=params.slope_angle, cut_from=params.saw.cut_from,
                        column_ends=params.column_ends)


def weac_answer(params: PSTParams, calibration, cut: float | None = None) -> dict:
    """weac's critical cut for this PST and its energy release rate at ``cut`` (m; default the saw's cut).

    Returns
    -------
    dict
        ``weac`` (its version, or None), ``G_c`` (J/m^2, the weak layer's ``w_f``), ``critical_cut`` (m, None
        if ``G`` stays below ``G_c`` within the column), ``critical_cut_note``, ``cut`` (m),
        ``energy_release_rate`` and its modes ``G_I``, ``G_II`` (J/m^2) at that cut; without weac only
        ``weac = None`` and ``note``, the one line that says so.
    """
    if weac_unavailable() is not None:
        return {"weac": None, "note": weac_unavailable()}
    G_c = float(calibration.given.get("w_f", calibration.w_f))
    a = float(params.saw.cut_length if cut is None else cut)
    try:
        return dict(_answer(static_column(params), G_c, a))
    except WeacUnavailable as e:
        return {"weac": None, "note": str(e)}


@functools.lru_cache(maxsize=256)
def _answer(column: StaticColumn, G_c: float, cut: float) -> tuple:
    search = critical_cut_search(column, G_c)
    G, G_I, G_II = energy_release_rate(column, cut) if 0.0 < cut < column.length else (math.nan,) * 3
    return (("weac", weac_version()), ("G_c", G_c), ("critical_cut", search.value),
            ("critical_cut_note", search.reason), ("cut", cut), ("energy_release_rate", G), ("G_I", G_I),
            ("G_II", G_II))
