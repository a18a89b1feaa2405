"""Parameters of the snow scenes' weak layer, in what snow scientists measure.

The layer is a bonded (structured) Cam-Clay (:class:`~mpm_warp.materials.BondedCamClay`,
``kernels/bonded_camclay.py``): strong while its bonds hold, softening over a set plastic slip
that costs a fracture energy, then collapsing under the slab. Its parameters are given as field
quantities and converted in one place, :func:`~.calibration.weak_layer_material`: shear strength
``tau_p`` (or the bond pressure), fracture energy ``w_f`` (or the softening slip ``delta_s``),
collapse height ``h_c`` (or ``xi``; default the WEAC fit of ``D_wl``). A value of 0 means "not
given": exactly one of ``tau_p``/``p_bond`` and of ``w_f``/``delta_s`` must be positive.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from ...checks import finite_number
from ...errors import InvalidArgument
from ...materials import BondedCamClay
from .calibration import CalibratedWeakLayer, weak_layer_material

__all__ = ["WeakLayer"]


@dataclass(frozen=True)
class WeakLayer:
    """The weak layer in field quantities (SI units; see the module docstring).

    Defaults: a persistent weak layer of density 150 (E 1 MPa: 0.93 rho^2.8 capped at the field
    range 0.05-1 MPa; nu 0.3), M 1.2 (a 30 deg friction angle), beta 0.3; shear strength 1 kPa
    under a 0.5 m slab (Jamieson and Johnston 2001: 0.5-2 kPa for persistent weak layers); fracture
    energy 0.79 J/m^2, the mode-II toughness G_IIc of Weissgraeber and Rosendahl (2023), WEAC's
    default (field 0.1-1.7 J/m^2: van Herwijnen et al. 2016; Bergfeld et al. 2021, 2023); with this
    strength it softens over ~1.2 mm of slip (SI Note 2's experiment: ~2 mm; McClung 1977; 3.5 mm
    in Bazant et al. 2003); collapse height from the WEAC fit (4.6 mm for 3 cm). The layer's
    debonding work is the same in compaction (:mod:`mpm_warp.kernels.bonded_camclay`).

    Attributes
    ----------
    E, nu, density : float
        Elasticity (Pa, -) and density (kg/m^3) of the layer.
    M, beta : float
        Critical-state slope (-, > 0) and cohesion ratio of the intact layer (-, in [0, 1]).
    tau_p : float
        Shear strength under the slab (Pa): first yield in simple shear; 0 if ``p_bond`` is given.
    p_bond : float
        Bonded part of the consolidation pressure (Pa), instead of ``tau_p``; 0 = not given.
    w_f : float
        Fracture energy (J/m^2): shear work above the residual over the softening; 0 if ``delta_s``.
    delta_s : float
        Softening (critical sliding) displacement (m), instead of ``w_f``; 0 = not given.
    h_c : float
        Collapse height (m) of the debonded layer under the slab; 0 = the WEAC fit of the thickness.
    xi : float
        Intrinsic hardening factor (-), instead of ``h_c``; 0 = not given.
    p0_int_ini : float
        Intrinsic consolidation of the debonded skeleton (Pa), >= 0 (0: loose).
    p0_floor_ratio : float
        Floor of the intrinsic consolidation relative to the bulk modulus (-).
    """

    E: float = 1.0e6
    nu: float = 0.3
    density: float = 150.0
    M: float = 1.2
    beta: float = 0.3
    tau_p: float = 1000.0
    p_bond: float = 0.0
    w_f: float = 0.79
    delta_s: float = 0.0
    h_c: float = 0.0
    xi: float = 0.0
    p0_int_ini: float = 0.0
    p0_floor_ratio: float = 1e-5

    def validate(self, where: str = "weak_layer") -> WeakLayer:
        """Check every value and the choices (InvalidArgument naming ``where.field``); return self."""
        for k in ("tau_p", "p_bond", "w_f", "delta_s", "h_c", "xi", "p0_int_ini"):
            finite_number(f"{where}.{k}", getattr(self, k), lo=0.0)
        for a, b in (("tau_p", "p_bond"), ("w_f", "delta_s")):
            if (getattr(self, a) > 0) == (getattr(self, b) > 0):
                raise InvalidArgument(f"{where}.{a}/{b}", (getattr(self, a), getattr(self, b)),
                                      f"exactly one of {a} and {b} positive (0 = not given)")
        if self.h_c > 0 and self.xi > 0:
            raise InvalidArgument(f"{where}.h_c/xi", (self.h_c, self.xi), "at most one of h_c and xi positive")
        BondedCamClay(self.E, self.nu, self.density, M=self.M, beta=self.beta,
                      p0_floor_ratio=self.p0_floor_ratio).validate(where)
        return self

    def calibrate(self, D_wl: float, slab_density: float, slab_thickness: float, slope_angle: float = 0.0,
                  slab_E: float | None = None, slab_nu: float | None = None) -> CalibratedWeakLayer:
        """The calibrated layer of thickness ``D_wl`` (m) under a slab (kg/m^3, m, deg; ``E``, ``nu`` for the
        references): :func:`~.calibration.weak_layer_material`, run once per set of values."""
        return _calibrate(self, float(D_wl), float(slab_density), float(slab_thickness), float(slope_angle),
                          None if slab_E is None else float(slab_E), None if slab_nu is None else float(slab_nu))

    def material(self, D_wl: float, slab_density: float, slab_thickness: float, slope_angle: float = 0.0):
        """The layer's :class:`~mpm_warp.materials.BondedCamClay` under that slab."""
        return self.calibrate(D_wl, slab_density, slab_thickness, slope_angle).material


def _given(value: float) -> float | None:
    return float(value) if value > 0 else None


@functools.lru_cache(maxsize=64)
def _calibrate(layer: WeakLayer, D_wl, slab_density, slab_thickness, slope_angle, slab_E, slab_nu):
    """Calibration on the CPU in float64 (deterministic: a resumed run rebuilds the same material)."""
    layer.validate()
    return weak_layer_material(
        E=layer.E, nu=layer.nu, density=layer.density, D_wl=D_wl, M=layer.M, beta=layer.beta,
        slab_density=slab_density, slab_thickness=slab_thickness, slope_angle=slope_angle,
        tau_p=_given(layer.tau_p), p_bond=_given(layer.p_bond), w_f=_given(layer.w_f),
        delta_s=_given(layer.delta_s), h_c=_given(layer.h_c), xi=_given(layer.xi), p0_int_ini=layer.p0_int_ini,
        p0_floor_ratio=layer.p0_floor_ratio, slab_E=slab_E, slab_nu=slab_nu)
