"""Every PST record of a field profile as a runnable column, or refused in one line in field terms.

:func:`field_cases` reads a CAAML file and gives, for each PST record, a :class:`FieldCase` (the column as
:class:`~mpm_warp.scenes.pst.PSTParams`, calibrated, with the fracture energy the record implies) or a
:class:`FieldRefusal` (the pit, the field line and the reason, e.g. ``PST 98/100 (End) down 55 cm: the cut
is 98 % of the column: the saw reached the end``). The rules, and why each refusal is one, are in
docs/profiles.md ("From a field record to a column").
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass

from ..errors import InvalidArgument
from ..scenes.profile import ProfileError, PSTRecord, SnowProfileData, read_profile
from ..scenes.profile.column import ProfileColumn, describe, profile_column
from ..scenes.pst import PSTParams, Saw
from ..scenes.pst.from_profile import CELLS_ACROSS
from ..scenes.pst.params_checks import band_limited_dx
from ..scenes.snowpack import SnowLayer
from .fracture_energy import ImpliedFractureEnergy, implied_fracture_energy
from .plain_words import in_field_terms

__all__ = ["FieldCase", "FieldRefusal", "field_case", "field_cases", "field_base", "OUTCOMES", "column_ends_for",
           "pit_name"]

OUTCOMES = ("End", "SF", "Arr")
#: countries whose standard PST has vertical ends (the North American guidelines, Greene et al. 2016)
VERTICAL_ENDS = ("US", "CA")
#: longest column the field batch builds (m): PSTs are 1-2 m, extended columns up to about 10 m
MAX_COLUMN = 10.0
#: a weak layer's shear strength raised to carry its slab is this factor above the least that does (-)
STRENGTH_MARGIN = 1.1


@dataclass(frozen=True)
class FieldRefusal:
    """A record (or a whole file, ``test == ""``) that cannot become a column: ``reason`` is its class, ``message``
    the one line in field terms."""

    pit: str
    test: str
    reason: str
    message: str
    outcome: str | None = None

    def line(self) -> str:
        """``pit: PST 98/100 (End) down 55 cm: message``."""
        return ": ".join(s for s in (self.pit, self.test, self.message) if s)


@dataclass(frozen=True)
class FieldCase:
    """A PST record set up as a column (``params``: validated; the weak layer calibrated when asked)."""

    pit: str
    test: str
    outcome: str
    record: PSTRecord
    params: PSTParams
    column: ProfileColumn
    fracture_energy: ImpliedFractureEnergy
    notes: tuple[str, ...]

    def line(self) -> str:
        """``pit: PST 38/100 (End) down 80 cm: slab ..., weak layer ..., w_f ...``."""
        wf = self.fracture_energy
        how = "given" if wf.reason == "given" else "weac's G at the recorded cut"
        w = (f"w_f {wf.value:.3g} J/m^2 ({how})" if wf.value is not None else
             f"w_f {self.params.weak_layer.w_f:g} J/m^2, the default: {wf.reason}")
        return f"{self.pit}: {self.test}: {describe(self.column)}; {w}"


def field_base() -> PSTParams:
    """What a field column takes where the profile says nothing (the weak layer's E, nu, strength, collapse; the
    saw): a PST whose slab can break, sawn from the upslope end."""
    return PSTParams(slab_fracture=True, saw=Saw(cut_from="upslope"))


def column_ends_for(country: str | None) -> str:
    """The column ends of the observer's standard: "vertical" in the US and Canada, else "slope_normal"."""
    return "vertical" if (country or "").strip().upper() in VERTICAL_ENDS else "slope_normal"


def pit_name(source: str) -> str:
    """The pit's name in the records: a CAAML file's base name, or ``table.csv#id`` for a table's row (its id
    whole, ``a/b`` included: only a file name made of it is sanitised)."""
    file, _, rid = str(source).partition("#")
    if rid and file.lower().endswith(".csv") and os.path.basename(file) == file:
        return str(source)
    return os.path.basename(str(source))


def _refuse(pit, rec, reason, message) -> FieldRefusal:
    return FieldRefusal(pit, rec.field_line(), reason, message, rec.propagation)


def _triage(rec: PSTRecord, profile: SnowProfileData) -> tuple[str, str] | None:
    """``(reason, message)`` for a record the model cannot take, before the column is built; None if it can."""
    if rec.propagation not in OUTCOMES:
        return "no outcome", f"no outcome recorded ({rec.propagation or 'empty'}: End, SF or Arr are read)"
    if rec.depth is None:
        return "no depth", "no failure depth recorded"
    if rec.column_length is None or not rec.column_length > 0.0:
        return "no column", "no column length recorded"
    if rec.column_length > MAX_COLUMN:
        return "column length", f"a column of {rec.column_length:g} m: the batch builds columns up to {MAX_COLUMN:g} m"
    if rec.cut_length is None or not rec.cut_length > 0.0:
        return "no cut", "a cut of 0 cm: no critical cut recorded"
    if rec.cut_length >= rec.column_length:
        return "cut at column", (f"the cut is {rec.cut_length / rec.column_length:.0%} of the column: the saw reached "
                                 "the end, there is no critical cut to read back")
    if profile.slope_angle is None:
        return "no slope", "no slope angle recorded: the slab's load on the weak layer depends on it"
    if not 0.0 <= profile.slope_angle <= 60.0:
        return "slope", f"a slope of {profile.slope_angle:g} deg: the model takes 0-60 deg"
    return None


def _params(profile: SnowProfileData, rec: PSTRecord, col: ProfileColumn, base: PSTParams) -> PSTParams:
    """The column as PSTParams: bed-normal layers, the grid from the weak layer, the record's column and cut."""
    slope = float(profile.slope_angle)
    c = math.cos(math.radians(slope))
    d_wl = col.weak_layer_thickness * c
    weak = base.weak_layer
    if col.weak_layer.density is not None and 50.0 <= col.weak_layer.density <= 600.0:
        weak = dataclasses.replace(weak, density=float(col.weak_layer.density))
    dx = d_wl / CELLS_ACROSS
    sub = [SnowLayer(p.thickness * c, p.density, name=p.name) for p in col.substratum]
    depth = sum(ly.thickness for ly in sub)
    if sub and depth < base.substratum_thickness:     # the pit ends just under the weak layer: its last snow goes on
        sub[-1] = dataclasses.replace(sub[-1], thickness=sub[-1].thickness + base.substratum_thickness - depth)
    kw = {"substratum_layers": tuple(sub)}
    params = dataclasses.replace(
        base, dx=dx, margin=max(0.05, 2.0 * dx), length=float(rec.column_length), slope_angle=slope,
        column_ends=column_ends_for(profile.country), weak_layer_thickness=d_wl, weak_layer=weak,
        slab_layers=tuple(SnowLayer(p.thickness * c, p.density, name=p.name) for p in col.slab),
        saw=dataclasses.replace(base.saw, cut_length=float(rec.cut_length)), **kw)
    fine = band_limited_dx(params)      # a brittle slab's crack band needs a finer grid than the weak layer's
    return params if dx <= fine else dataclasses.replace(params, dx=fine, margin=max(0.05, 2.0 * fine))


def field_case(profile: SnowProfileData, rec: PSTRecord, *, base: PSTParams | None = None,
               calibrate: bool = True, w_f: float | None = None) -> FieldCase | FieldRefusal:
    """The record ``rec`` of ``profile`` as a column, or why not (module docstring).

    Parameters
    ----------
    profile : SnowProfileData
    rec : PSTRecord
        One of ``profile.pst_tests``.
    base : PSTParams, optional
        What the profile does not give (the weak layer's E, nu, strength, collapse; the saw); default
        :func:`field_base`.
    calibrate : bool
        Calibrate the weak layer under this slab (as building the scene does): a column the calibration refuses
        is refused here.
    w_f : float, optional
        The weak layer's fracture energy (J/m^2) when known (a table gives it); else read back from the cut.
    """
    pit = pit_name(profile.source)
    why = _triage(rec, profile)
    if why is not None:
        return _refuse(pit, rec, *why)
    try:
        col = profile_column(profile, rec.depth, rec.layer_thickness)
    except ProfileError as e:
        msg = str(e)
        kind = ("failure depth" if msg.startswith("the failure depth") else
                "slab density range" if "density of" in msg else "slab layer without density")
        return _refuse(pit, rec, kind, msg)
    slab_normal = col.depth * math.cos(math.radians(profile.slope_angle))
    if rec.column_length <= slab_normal:
        return _refuse(pit, rec, "column shorter than slab", (
            f"the column ({rec.column_length * 100:.0f} cm) is not longer than the slab is deep "
            f"({slab_normal * 100:.0f} cm, normal to the slope): the model counts a crack as at the far end within one "
            "slab depth of it, so such a column leaves the crack no room to run"))
    base = base if base is not None else field_base()
    params, notes = None, list(col.notes)
    try:
        params = _params(profile, rec, col, base).validate("scene")
        wf = (implied_fracture_energy(params, rec.cut_length) if w_f is None else
              ImpliedFractureEnergy(float(w_f), None, None, None, "given"))
        if wf.value is not None:
            params = dataclasses.replace(params, weak_layer=dataclasses.replace(params.weak_layer, w_f=wf.value))
        params = _carries_its_slab(params, notes)
        if calibrate:
            params.calibrated()
    except InvalidArgument as e:
        return _refuse(pit, rec, *in_field_terms(e, params))
    return FieldCase(pit, rec.field_line(), rec.propagation, rec, params, col, wf, tuple(notes))


def _carries_its_slab(params: PSTParams, notes: list[str]) -> PSTParams:
    """``params`` with a weak layer strong enough to carry its slab intact, as the pit showed it (docs/profiles.md).

    A layer of the default shear strength under a heavy slab would yield in compaction: the slab would crush it
    before any cut, which the observer did not see. Its strength is then raised to :data:`STRENGTH_MARGIN` times
    the least at which it carries the slab and fails in shear (the least the observation allows), and noted.
    """
    from ..scenes.weak_layer.calibration import carries_slab, least_shear_strength

    wl = params.weak_layer
    layer = {"E": wl.E, "nu": wl.nu, "density": wl.density, "D_wl": params.weak_layer_thickness, "M": wl.M,
             "beta": wl.beta, "sigma_n": params.sigma_n, "h_c": wl.h_c or None, "p0_int_ini": wl.p0_int_ini,
             "p0_floor_ratio": wl.p0_floor_ratio}
    if not wl.tau_p > 0.0 or carries_slab(wl.tau_p, **layer):
        return params
    least = least_shear_strength(wl.tau_p, **layer)
    if least is None:
        return params               # no strength carries it: the calibration refuses the column, in field terms
    tau = math.ceil(STRENGTH_MARGIN * least / 10.0) * 10.0
    notes.append(f"weak layer's shear strength {tau:.0f} Pa, not the default {wl.tau_p:.0f} Pa: under "
                 f"{params.sigma_n:.0f} Pa the default would be crushed by the slab the pit showed it carrying; "
                 f"{STRENGTH_MARGIN:g} x the least strength that carries it ({least:.0f} Pa)")
    return dataclasses.replace(params, weak_layer=dataclasses.replace(wl, tau_p=tau))


def field_cases(path, *, base: PSTParams | None = None, calibrate: bool = True) -> list[FieldCase | FieldRefusal]:
    """Every PST record of the CAAML file ``path``: a case or a refusal each; one refusal for a file that cannot
    be read (``test == ""``)."""
    pit = os.path.basename(str(path))
    try:
        profile = read_profile(path)
    except ProfileError as e:
        text = str(e).replace(f"{os.fspath(path)}: ", "").replace(f"{os.fspath(path)!r}", repr(pit))
        return [FieldRefusal(pit, "", "unreadable", text)]
    if not profile.pst_tests:
        return [FieldRefusal(pit, "", "no PST", "the profile records no PST")]
    return [field_case(profile, rec, base=base, calibrate=calibrate) for rec in profile.pst_tests]
