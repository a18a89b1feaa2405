"""The weak layer's fracture energy a field PST implies, given only where a critical cut can be read.

A PST record ``PST 32/100 (End)`` says that at a cut of 32 cm the crack ran on its own: weac's energy
release rate of the column at that cut is then the weak layer's fracture energy (``G(a_c) = w_f``,
docs/weac.md). Two limits make that reading a measurement or not (docs/profiles.md, "Reading w_f back"):

- the cut is at most half the column (:data:`MAX_CUT_FRACTION`). Gauthier and Jamieson (2008) and the
  North American guidelines (Greene et al. 2016) read a PST's propagation propensity from cuts up to half
  the column only: beyond it the short intact part and the far end decide, and G grows without bound as the
  cut nears the end;
- the value lies in :data:`PLAUSIBLE` J/m^2, the span of weak-layer fracture energies from field and
  laboratory tests (0.01-10 J/m^2 covers them by an order of magnitude on each side).

Outside these, the record is still a field observation, but it gives no w_f: the column runs with the weak
layer's default fracture energy and says so.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ImpliedFractureEnergy", "implied_fracture_energy", "MAX_CUT_FRACTION", "PLAUSIBLE"]

MAX_CUT_FRACTION = 0.5
PLAUSIBLE = (0.01, 10.0)


@dataclass(frozen=True)
class ImpliedFractureEnergy:
    """What a record says of the weak layer's fracture energy.

    Attributes
    ----------
    value : float or None
        w_f (J/m^2) when it can be read; None otherwise.
    G : float or None
        weac's energy release rate at the recorded cut (J/m^2), also where it is not a measurement.
    G_I, G_II : float or None
        Its modes (J/m^2).
    reason : str
        Why it is or is not read, in field terms.
    """

    value: float | None
    G: float | None
    G_I: float | None
    G_II: float | None
    reason: str


def implied_fracture_energy(params, cut: float) -> ImpliedFractureEnergy:
    """The fracture energy a PST column ``params`` (PSTParams, the field column) implies at its recorded ``cut`` (m).

    weac (optional) computes G, the solve the case's :func:`~.static_view.static_view` reads at the recorded cut;
    without it, ``value`` is None and the reason says how to install it.
    """
    from ..scenes.weac_reference import weac_unavailable
    from .static_view import energy_release_at

    frac = cut / params.length
    if frac > MAX_CUT_FRACTION:
        return ImpliedFractureEnergy(None, None, None, None, (
            f"the cut is {frac:.0%} of the column: propagation at a long cut, where the column's end decides, not "
            f"a measure of the weak layer (cuts up to {MAX_CUT_FRACTION:.0%} of the column are read)"))
    if weac_unavailable() is not None:
        return ImpliedFractureEnergy(None, None, None, None, weac_unavailable())
    G, G_I, G_II = energy_release_at(params, cut)
    lo, hi = PLAUSIBLE
    if not lo <= G <= hi:
        return ImpliedFractureEnergy(None, G, G_I, G_II, (
            f"weac's G at the cut, {G:.3g} J/m^2, is outside the {lo:g}-{hi:g} J/m^2 of weak layers: not a "
            "measure of this one (check the slab and the cut)"))
    return ImpliedFractureEnergy(G, G, G_I, G_II, "weac's G at the recorded cut")
