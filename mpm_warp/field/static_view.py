"""weac's static view of a field column, solved once per case: G at the recorded cut, the critical cut, the stress.

Three parts of the field batch read weac's static model of a case's column (docs/weac.md): the set-up reads the
weak layer's fracture energy back from the energy release rate at the recorded cut (:mod:`.fracture_energy`),
the protocol pre-cuts the column a share of the critical cut at that fracture energy (:mod:`.protocol`), and the
static rule calls SF or END from the slab's stress at the recorded cut (:mod:`.static_rule`). :func:`static_view`
gives all three in one :class:`StaticView`, each solved once per column: the views are kept by what weac sees
of the column (the column, the cut, the fracture energy, the slab's strengths), so a case set up again, or a
copy of it with another slab, gets the view of its own column.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from ..scenes import weac_reference as wr
from ..scenes.density_laws import sigrist_tensile_strength
from ..scenes.pst.static import static_column

__all__ = ["StaticView", "static_view", "energy_release_at", "slab_strengths", "clear_static_views", "STRESS_DX",
           "STRESS_DZ"]

#: spacing (m) of the slab's stress along the column and through the slab, for the static rule
STRESS_DX, STRESS_DZ = 0.01, 0.005


@dataclass(frozen=True)
class StaticView:
    """weac's static answer for one field column (all None where weac is not installed).

    Attributes
    ----------
    cut : float
        The recorded cut (m): the saw's ``cut_length`` of the case.
    w_f : float
        The weak layer's fracture energy of the case (J/m^2), the ``G_c`` of the critical cut.
    G, G_I, G_II : float or None
        weac's energy release rate at the recorded cut and its modes (J/m^2).
    critical_cut : float or None
        The shortest cut at which ``G = w_f`` (m); None where G stays below it over the column.
    peak_ratio : float or None
        The slab's largest tensile principal stress at the recorded cut over its layer's tensile strength (-).
    unavailable : str or None
        Why weac gave no answer (the one line: not installed, another version); None when it did.
    """

    cut: float
    w_f: float
    G: float | None = None
    G_I: float | None = None
    G_II: float | None = None
    critical_cut: float | None = None
    peak_ratio: float | None = None
    unavailable: str | None = None

    @property
    def static_class(self) -> str | None:
        """The static rule's call: "SF" where the slab's stress reaches its strength, else "END"; None without
        weac."""
        if self.peak_ratio is None:
            return None
        return "SF" if self.peak_ratio >= 1.0 else "END"


def slab_strengths(params) -> tuple[float, ...]:
    """Each slab layer's tensile strength (Pa), top to bottom: as given, else from its density (Sigrist 2006)."""
    return tuple(ly.tensile_strength if ly.tensile_strength > 0 else sigrist_tensile_strength(ly.density)
                 for ly in params.slab_stack())


def static_view(params) -> StaticView:
    """weac's static view of the field column ``params`` (PSTParams) at its recorded cut (``saw.cut_length``),
    with its critical cut at the weak layer's ``w_f``; solved once per column (module docstring)."""
    cut, w_f = float(params.saw.cut_length), float(params.weak_layer.w_f)
    why = wr.weac_unavailable()
    if why is not None:
        return StaticView(cut, w_f, unavailable=why)
    return _view(static_column(params), cut, w_f, slab_strengths(params))


def energy_release_at(params, cut: float) -> tuple[float, float, float]:
    """weac's ``(G, G_I, G_II)`` (J/m^2) of the column ``params`` at a cut of ``cut`` m: the solve its
    :class:`StaticView` reads at the recorded cut (weac must be installed)."""
    return _energy_release_rate(static_column(params), float(cut))


def clear_static_views() -> None:
    """Forget every view solved so far (a test counting weac's solves starts from none)."""
    _view.cache_clear()
    _energy_release_rate.cache_clear()


@functools.lru_cache(maxsize=4096)
def _energy_release_rate(column, cut: float) -> tuple[float, float, float]:
    return wr.energy_release_rate(column, cut)


@functools.lru_cache(maxsize=4096)
def _view(column, cut: float, w_f: float, strengths: tuple) -> StaticView:
    G, G_I, G_II = _energy_release_rate(column, cut)
    a_c = wr.critical_cut(column, w_f)
    stress = wr.slab_stress(column, cut, list(strengths), dx=STRESS_DX, dz=STRESS_DZ)
    return StaticView(cut, w_f, G, G_I, G_II, a_c, float(stress["peak_ratio"]))
