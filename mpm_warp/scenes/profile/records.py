"""What a snow profile says, as plain frozen records: its layers top to bottom, its PST results, its site.

:func:`~mpm_warp.scenes.profile.caaml.read_profile` makes them from a CAAML file; they hold only
numbers (SI units) and strings, so a scene builds from them without the CAAML library.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass
from typing import Literal

from ...errors import InvalidArgument, MPMError

__all__ = ["ProfileLayer", "PSTRecord", "SnowProfileData", "ProfileError", "ProfileLibraryMissing", "metres"]

MEASURED = "measured"


class ProfileError(InvalidArgument):
    """A snow profile that cannot be used: the message names the file, the layer (index and depth) and the value.

    ``message``, when given, is the whole line instead of ``field = value is invalid: expected allowed`` (a refusal
    in field terms: "the slab layer at 10-25 cm (RG 1F) has a measured density of 20 kg/m^3, ...").
    """

    def __init__(self, field: str, value, allowed: str, message: str | None = None):
        super().__init__(field, value, allowed)
        if message is not None:
            self.args = (message,)


class ProfileLibraryMissing(MPMError, ImportError):
    """An optional CAAML reader (snowprofile, snowpylot) is not installed.

    ``name`` is the missing package when ``cause``, the failed import, is a :class:`ModuleNotFoundError`.
    """

    def __init__(self, message: str, cause: ImportError | None = None):
        super().__init__(message, name=cause.name if isinstance(cause, ModuleNotFoundError) else None)


def metres(x: float) -> str:
    """A depth or thickness for messages: up to 4 significant digits, in m."""
    return f"{x:.4g}"


@dataclass(frozen=True)
class ProfileLayer:
    """One layer of the stratigraphy.

    Attributes
    ----------
    index : int
        Position from the top (0 = the surface layer).
    depth_top : float
        Depth of its top below the snow surface (m), >= 0.
    thickness : float
        Thickness (m), > 0 (measured vertically, as a profile is recorded).
    density : float or None
        Density (kg/m^3). None only for a layer whose grain form has no density law and that has no
        measured density (e.g. buried surface hoar): such a layer can be the weak layer, whose density
        comes from its own parameters, but not a slab or substratum layer
        (:func:`~mpm_warp.scenes.profile.selection.select_weak_layer` refuses it there).
    density_source : str
        "measured" (from the profile's density profile), or how it was estimated, e.g.
        "Geldsetzer and Jamieson 2000 from hardness 1F and grain RG", or why there is none.
    hardness : str or None
        Hand hardness as the field writes it ("4F", "1F+", "4F-1F").
    grain_1, grain_2 : str or None
        Primary and secondary grain shapes (IACS codes, e.g. "RG", "FCxr", "SH").
    """

    index: int
    depth_top: float
    thickness: float
    density: float | None
    density_source: str
    hardness: str | None
    grain_1: str | None
    grain_2: str | None

    @property
    def depth_bottom(self) -> float:
        """Depth of its bottom below the snow surface (m)."""
        return self.depth_top + self.thickness

    @property
    def measured(self) -> bool:
        """Its density was measured (not estimated)."""
        return self.density_source == MEASURED

    def describe(self) -> str:
        """``"layer 2 (depth 0.48-0.5 m)"``: how messages name the layer."""
        return f"layer {self.index} (depth {metres(self.depth_top)}-{metres(self.depth_bottom)} m)"


@dataclass(frozen=True)
class PSTRecord:
    """A Propagation Saw Test result the profile records (the field line "PST 32/100 (End)").

    Attributes
    ----------
    cut_length : float or None
        Critical cut length (m): the cut at which the crack propagated on its own.
    column_length : float or None
        Column length (m).
    propagation : str or None
        "End", "SF" or "Arr" (the crack reached the end of the column, the slab fractured, the crack
        arrested), as recorded; "X" or None where the observer recorded no outcome.
    depth : float or None
        Depth of the top of the failed layer below the surface (m).
    layer_thickness : float or None
        Thickness of the failed layer (m).
    grain_1 : str or None
        Primary grain shape of the failed layer.
    """

    cut_length: float | None
    column_length: float | None
    propagation: str | None
    depth: float | None
    layer_thickness: float | None
    grain_1: str | None

    def field_line(self) -> str:
        """The line an observer writes: ``"PST 32/100 (End) down 48 cm"`` (lengths in cm)."""
        column = "?" if self.column_length is None else f"{self.column_length * 100:.0f}"
        cut = "?" if self.cut_length is None else f"{self.cut_length * 100:.0f}"
        line = f"PST {cut}/{column} ({self.propagation or '?'})"
        return line if self.depth is None else f"{line} down {self.depth * 100:.0f} cm"


@dataclass(frozen=True)
class SnowProfileData:
    """A snow profile as read from a CAAML file.

    Attributes
    ----------
    layers : tuple of ProfileLayer
        The stratigraphy, top to bottom, contiguous from the surface.
    slope_angle : float or None
        Slope inclination at the pit (deg).
    aspect : float or None
        Slope aspect (deg from north, clockwise).
    location : str
        Name of the site.
    date : datetime.datetime or None
        Time of observation (timezone-aware).
    total_depth : float
        Snow depth HS (m); the bottom of the deepest layer when the profile does not give HS
        (the pit may stop above the ground: the layers then end above ``total_depth``).
    pst_tests : tuple of PSTRecord
        The PSTs the profile records, in file order.
    source : str
        The file it was read from.
    caaml_version : {"5", "6"}
        The CAAML major version of the file.
    country : str or None
        The country code as recorded (not checked: SnowPilot writes codes outside ISO 3166, e.g. "UT").
    """

    layers: tuple[ProfileLayer, ...]
    slope_angle: float | None
    aspect: float | None
    location: str
    date: datetime.datetime | None
    total_depth: float
    pst_tests: tuple[PSTRecord, ...]
    source: str
    caaml_version: Literal["5", "6"]
    country: str | None = None

    @property
    def depth_described(self) -> float:
        """Depth of the bottom of the deepest layer (m)."""
        return self.layers[-1].depth_bottom

    def summary(self) -> str:
        """A few lines: the site, then one line per layer (depth, grains, hardness, density and its source)."""
        slope = "?" if self.slope_angle is None else f"{self.slope_angle:g}"
        aspect = "?" if self.aspect is None else f"{self.aspect:g}"
        when = "" if self.date is None else f", {self.date.isoformat()}"
        out = [f"{self.location}{when}: slope {slope} deg, aspect {aspect} deg, HS {metres(self.total_depth)} m "
               f"(CAAML {self.caaml_version}: {self.source})"]
        for L in self.layers:
            grains = "/".join(g for g in (L.grain_1, L.grain_2) if g) or "?"
            rho = "no density" if L.density is None else f"{L.density:.0f} kg/m^3"
            out.append(f"  {L.index:2d}  {L.depth_top:5.3f}-{L.depth_bottom:5.3f} m  {grains:<10} "
                       f"{L.hardness or '?':<6} {rho} ({L.density_source})")
        out += [f"  {t.field_line()}" for t in self.pst_tests]
        return "\n".join(out)
