"""A ``[scene] kind = "pst"`` table of an older release in today's keys (``SceneType.upgrade`` of the PST).

Read before the parameters are built: the names and meanings a stored table may still carry.
"""

from __future__ import annotations

from ...errors import InvalidArgument

__all__ = ["upgrade_table"]


def upgrade_table(table: dict) -> dict:
    """A ``[scene]`` table of an older release in today's keys: ``saw.from_end = "left" | "right"`` (the end
    ``x = 0`` or ``x = L``) becomes ``saw.cut_from``, the upslope or downslope end of that slope. A negative
    slope angle must come with either: it once named the saw's end (the cut from the downslope end), now it
    only mirrors the column."""
    saw = table.get("saw")
    slope = table.get("slope_angle", 0.0)
    if isinstance(slope, (int, float)) and slope < 0.0 and not (isinstance(saw, dict) and saw.keys() & {
            "from_end", "cut_from"}):
        raise InvalidArgument("scene.slope_angle", slope, "given with scene.saw.cut_from = 'upslope' | 'downslope' "
                              "when negative (before cut_from, a negative angle meant the cut from the downslope end)")
    if isinstance(saw, dict) and "from_end" in saw:
        end = saw.pop("from_end")
        if "cut_from" in saw:
            raise InvalidArgument("scene.saw.from_end", end, "left out beside scene.saw.cut_from (its older name)")
        if end not in ("left", "right"):
            raise InvalidArgument("scene.saw.from_end", end, "'left' or 'right' (older name of scene.saw.cut_from = "
                                  "'upslope' | 'downslope')")
        slope = table.get("slope_angle", 0.0)
        up_at_origin = not isinstance(slope, (int, float)) or slope >= 0.0
        saw["cut_from"] = "upslope" if (end == "left") == up_at_origin else "downslope"
    return table
