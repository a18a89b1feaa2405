"""Reading a SnowPilot export (CAAML 6.0.3) with snowpylot, the parser written for exactly these files.

snowpylot (MIT, the optional extra ``profile``) reads what SnowPilot writes without judging it: a country
code outside ISO 3166 (``UT``, ``SJ``), a PST outcome ``X``, an empty site name or a layer without a hand
hardness do not stop it. What the model needs is checked later, per PST (:mod:`.column`). On the 3,220
pits of the development set it reads every file and every PST result, about 14x faster than snowprofile,
which refuses 401 of them (docs/profiles.md, "Which library reads a file").
"""

from __future__ import annotations

import datetime
import io
import xml.etree.ElementTree as ET

from .records import ProfileError, ProfileLibraryMissing, PSTRecord, SnowProfileData
from .stratigraphy import build_layers, check_samples

__all__ = ["is_snowpilot", "read_snowpilot"]

#: the CAAML namespace SnowPilot writes and snowpylot reads
NAMESPACE = b"http://caaml.org/Schemas/SnowProfileIACS/v6.0.3"
_TO_M = {"cm": 0.01, "mm": 0.001, "m": 1.0}
_ASPECTS = {d: 22.5 * i for i, d in enumerate(("N", "NNE", "NE", "ENE", "E", "ESE", "SE", "SSE", "S", "SSW", "SW",
                                               "WSW", "W", "WNW", "NW", "NNW"))}


def is_snowpilot(data: bytes) -> bool:
    """True for a SnowPilot CAAML 6.0.3 export (its namespace and a SnowPilot element or id)."""
    head = data[:4096]
    return NAMESPACE in head and (b"snowpilot" in head.lower())


def _metres(value, path: str, what: str) -> float | None:
    """``[number, unit]`` as snowpylot gives a length, in m; None when absent."""
    if value is None or value[0] is None:
        return None
    unit = value[1] or "cm"
    if unit not in _TO_M:
        raise ProfileError(f"{path}: {what} unit", unit, "cm, mm or m")
    return float(value[0]) * _TO_M[unit]


def _number(text) -> float | None:
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def _aspect(text) -> float | None:
    if text is None:
        return None
    v = _number(text)
    return v if v is not None else _ASPECTS.get(str(text).strip().upper())


def _grain(g) -> str | None:
    return None if g is None or not g.grain_form else str(g.grain_form)


def _psts(pit, path: str) -> tuple[PSTRecord, ...]:
    out = []
    for t in pit.stability_tests.PST:
        out.append(PSTRecord(cut_length=_metres(t.cut_length, path, "PST cut length"),
                             column_length=_metres(t.column_length, path, "PST column length"),
                             propagation=t.fracture_prop or None,
                             depth=_metres(t.depth_top, path, "PST depth"), layer_thickness=None, grain_1=None))
    return tuple(out)


def read_snowpilot(data: bytes, path: str) -> SnowProfileData:
    """A SnowPilot CAAML 6.0.3 export (its bytes) as :class:`SnowProfileData`.

    Raises
    ------
    ProfileError
        A profile whose layers are not contiguous from the surface, or whose depths are measured bottom up
        (one line naming the file and the layer).
    ProfileLibraryMissing
        snowpylot is not installed.
    """
    try:
        from snowpylot import caaml_parser
    except ImportError as e:
        raise ProfileLibraryMissing(f"reading a SnowPilot profile needs the snowpylot library ({e}): "
                                    "pip install 'mpm-warp[profile]'", e) from None
    try:
        pit = caaml_parser(io.BytesIO(data))
    except (ET.ParseError, AttributeError, ValueError, TypeError, IndexError) as e:
        raise ProfileError("profile", path, f"a SnowPilot CAAML export that snowpylot reads ({type(e).__name__}: "
                                            f"{' '.join(str(e).split())[:200]})") from None
    prof = pit.snow_profile
    if prof.measurement_direction not in (None, "top down"):
        raise ProfileError(f"{path}: measurement direction", prof.measurement_direction, "'top down' (SnowPilot's)")
    layers = prof.layers
    tops = [_metres(ly.depth_top, path, "layer depth") for ly in layers]
    ths = [_metres(ly.thickness, path, "layer thickness") for ly in layers]
    samples = check_samples([(_metres(s.depth_top, path, "density depth") or 0.0,
                              _metres(s.thickness, path, "density thickness"),
                              None if s.density is None else s.density[0]) for s in prof.density_profile], path)
    hs = _metres(prof.hs, path, "snow depth") or _metres(prof.profile_depth, path, "profile depth")
    built = build_layers([float("nan") if t is None else t for t in tops],
                         [float("nan") if t is None else t for t in ths],
                         [ly.hardness or None for ly in layers], [_grain(ly.grain_form_primary) for ly in layers],
                         [_grain(ly.grain_form_secondary) for ly in layers], samples, hs, path)
    loc, core = pit.core_info.location, pit.core_info
    slope = None if loc.slope_angle is None else _number(loc.slope_angle[0])
    date = None
    if core.date:
        try:
            date = datetime.datetime.fromisoformat(core.date)
        except ValueError:
            date = None
    name = core.pit_name or (f"SnowPilot pit {core.pit_id}" if core.pit_id else "")
    return SnowProfileData(layers=built, slope_angle=slope, aspect=_aspect(loc.aspect), location=name, date=date,
                           total_depth=float(hs) if hs else built[-1].depth_bottom, pst_tests=_psts(pit, path),
                           source=path, caaml_version="6", country=loc.country or None)
