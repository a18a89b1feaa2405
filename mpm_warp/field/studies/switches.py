"""The what-ifs of the field studies: each one named switch of how a field case is set up or run.

A :class:`Switch` either sets one field of the :class:`~mpm_warp.field.protocol.FieldProtocol` (the closure, the
base, the pre-cut, the grid: the batch's own choices) or changes the case before it runs (the weak layer's
modulus, the slab's strength: what-ifs on what a pit does not record). :data:`SWITCHES` is the registry the
driver (:mod:`.what_if`) and the report read; no switch changes a default.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from dataclasses import dataclass

from ...scenes.pst import PSTParams
from ..cases import FieldCase, field_base, field_case
from ..protocol import FieldProtocol
from .slab_strength import faceted_share, weaker

__all__ = ["Switch", "SWITCHES", "compliance_ratio", "softer", "WEAC_MODULUS_MPA"]

#: weac's default weak-layer modulus (MPa), the weak-modulus what-if's default
WEAC_MODULUS_MPA = 0.25


def _same(case, value, data):
    return case


def _none(before, after, value) -> dict:
    return {}


@dataclass(frozen=True)
class Switch:
    """One what-if: what it changes, its values and how each reads.

    Attributes
    ----------
    name : str
        Its name in the registry and in a result's ``switch``.
    what : str
        What it changes, a phrase for the report ("the laminate closure at the layer interfaces").
    default : object
        The what-if value a script runs without an option.
    baseline : object
        The value of the batch's run (the protocol's default, or the scene's).
    label : callable
        ``label(value) -> str``: how a side reads ("with the closure").
    check : callable
        ``check(value) -> str | None``: why a value is invalid, None where it is valid.
    field : str or None
        The protocol field it sets; None where it changes the case instead.
    change : callable
        ``change(case, value, data) -> FieldCase | FieldRefusal``: the case the what-if runs (``data``: the pits'
        folder, for a case set up again); the case itself for a protocol switch.
    detail : callable
        ``detail(before, after, value) -> dict``: what each row adds (the cases before and after the change).
    option : tuple or None
        A script's option for the value: ``(flag, type, help)``; None: the value is fixed.
    """

    name: str
    what: str
    default: object
    baseline: object
    label: Callable
    check: Callable
    field: str | None = None
    change: Callable = _same
    detail: Callable = _none
    option: tuple | None = None

    def protocol(self, base: FieldProtocol, value) -> FieldProtocol:
        """The protocol the what-if runs under: ``base`` with :attr:`field` set to ``value`` (where it has one)."""
        return (base if self.field is None else dataclasses.replace(base, **{self.field: value})).validate()


def _constrained_modulus(E: float, nu: float) -> float:
    """Constrained (oedometric) modulus (Pa) of Young's modulus ``E`` (Pa) and Poisson's ratio ``nu``."""
    return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))


def compliance_ratio(p: PSTParams) -> float:
    """The substratum's compliance under a normal load over the weak layer's (-): ``sum d / M`` over ``D_wl / M``,
    M the constrained modulus: what a rigid base leaves out."""
    sub = sum(ly.thickness / _constrained_modulus(ly.modulus, ly.nu) for ly in p.substratum_stack())
    return sub / (p.weak_layer_thickness / _constrained_modulus(p.weak_layer.E, p.weak_layer.nu))


def softer(case: FieldCase, data: str, modulus: float):
    """``case`` set up again from its pit in ``data`` with the weak layer's Young's modulus ``modulus`` (Pa), as the
    batch sets a column up (the fracture energy read back, the layer calibrated): a FieldCase, or the FieldRefusal
    that says why the model cannot take it. Nothing but the weak layer may change (checked)."""
    from ...scenes.profile import read_profile

    base = field_base()
    base = dataclasses.replace(base, weak_layer=dataclasses.replace(base.weak_layer, E=modulus))
    new = field_case(read_profile(os.path.join(data, case.pit)), case.record, base=base)
    if isinstance(new, FieldCase) and dataclasses.replace(new.params, weak_layer=case.params.weak_layer) != case.params:
        raise AssertionError(f"{case.test}: more than the weak layer changed with its modulus")
    return new


def _critical_cut(p: PSTParams) -> float | None:
    from ...scenes.pst.static import static_column
    from ...scenes.weac_reference import critical_cut

    return critical_cut(static_column(p), p.weak_layer.w_f)


def _pre_cut_detail(before, after, value) -> dict:
    static = _critical_cut(before.params)
    pre = min(value * static, 0.5 * float(before.params.length)) if static else 0.0
    return {"static_cut": static, "pre_cut": pre}


def _cells_detail(before, after, value) -> dict:
    cells = [FieldProtocol.cells_across, value]
    return {"cells": cells, "dx": [before.params.weak_layer_thickness / n for n in cells]}


def _factor(name: str, lo: float = 0.0, hi: float = 1.0) -> Callable:
    return lambda v: None if lo < v <= hi else f"{name} = {v:g} is invalid: expected a factor in ({lo:g}, {hi:g}]"


def _flag(v) -> str | None:
    return None if isinstance(v, bool) else f"{v!r} is invalid: expected true or false"


_SWITCHES = (
    Switch("interface_closure", "the laminate closure at the layer interfaces (docs/model.md §5b)", True, False,
           lambda v: "with the closure" if v else "without the closure", _flag, field="interface_closure"),
    Switch("rigid_base", "the base under the weak layer: a rigid base, or the profile's old snow", False, True,
           lambda v: "on the rigid base" if v else "on the old snow", _flag, field="rigid_base",
           detail=lambda b, a, v: {"compliance_ratio": compliance_ratio(b.params),
                                   "substratum_m": b.params.substratum_depth}),
    Switch("pre_cut_share", "the saw's pre-cut, a share of weac's critical cut", 0.0, FieldProtocol.pre_cut_share,
           lambda v: "without the pre-cut" if v == 0 else f"with a pre-cut of {v:.2f} times weac's critical cut",
           lambda v: None if 0.0 <= v <= 0.9 else f"--share = {v:g} is invalid: expected 0-0.9",
           field="pre_cut_share", detail=_pre_cut_detail,
           option=("--share", float, "the pre-cut over weac's critical cut (0: none, the default; the batch's 0.5)")),
    Switch("cells_across", "the grid cells across the weak layer", 6, FieldProtocol.cells_across,
           lambda v: f"at {v} cells", lambda v: None if 3 <= v <= 16 else f"--cells = {v} is invalid: expected 3-16",
           field="cells_across", detail=_cells_detail,
           option=("--cells", int, "grid cells across the weak layer (default 6; the batch's 4)")),
    Switch("weak_modulus", "the weak layer's Young's modulus (MPa)", WEAC_MODULUS_MPA, field_base().weak_layer.E / 1e6,
           lambda v: f"at {v:.2f} MPa",
           lambda v: None if 0.05 <= v < 1.0 else f"--modulus = {v:g} is invalid: expected 0.05-1 MPa (below the "
                                                 "scene's 1 MPa)",
           change=lambda c, v, data: softer(c, data, v * 1e6),
           option=("--modulus", float, f"the weak layer's Young's modulus (MPa, default {WEAC_MODULUS_MPA:g}: "
                                       "weac's)")),
    Switch("slab_strength", "every slab layer's tensile strength, a factor on its density law's", 0.5, 1.0,
           lambda v: "at the law's strength" if v == 1 else f"at {v:.2f} of the law's strength", _factor("--scale"),
           change=lambda c, v, data: weaker(c, v), detail=lambda b, a, v: {"faceted_share": faceted_share(b.params)},
           option=("--scale", float, "the slab's tensile strength over its law's (default 0.5)")),
    Switch("faceted_strength", "the tensile strength of the slab's faceted layers (FC, DH), a factor on the law's",
           0.5, 1.0,
           lambda v: "at the law's strength" if v == 1 else f"faceted layers at {v:.2f} of the law's strength",
           _factor("--faceted"), change=lambda c, v, data: weaker(c, 1.0, v),
           detail=lambda b, a, v: {"faceted_share": faceted_share(b.params)},
           option=("--faceted", float, "a faceted layer's (FC, DH) strength over the law's (default 0.5, in situ)")),
)

#: every what-if, by name
SWITCHES = {s.name: s for s in _SWITCHES}
