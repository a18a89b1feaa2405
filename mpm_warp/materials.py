"""Constitutive models: elastic snow/ice, cohesive Cam-Clay snow and the bonded weak layer (docs/model.md §1-3b).

Materials are plain dataclasses; the engine turns them into kernel arguments.
Every model uses St Venant-Kirchhoff elasticity in Hencky strain.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from .camclay_forms import hardening_collapse
from .checks import finite_number
from .errors import InvalidArgument
from .kernels.camclay import initial_log_jp

__all__ = ["Elastic", "CamClaySnow", "BondedCamClay", "CrackingSnow", "Material", "MATERIAL_MODELS", "lame_parameters",
           "hardening_collapse"]


def lame_parameters(E, nu):
    """Shear modulus, first Lame parameter and bulk modulus ``(mu, lam, K)`` (Pa) of ``E`` (Pa) and ``nu`` (-).

    ``mu = E / (2 (1 + nu))``, ``lam = E nu / ((1 + nu)(1 - 2 nu))``, ``K = lam + 2 mu / 3``
    (docs/model.md §1). Floats or NumPy arrays; the one home of these formulas (a material's
    :attr:`Elastic.mu`, :attr:`Elastic.lam` and :attr:`Elastic.bulk` call it).
    """
    mu = E / (2.0 * (1.0 + nu))
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    return mu, lam, lam + 2.0 * mu / 3.0


@dataclass(frozen=True)
class Elastic:
    """Hencky St Venant-Kirchhoff elastic solid.

    Parameters
    ----------
    E : float
        Young's modulus (Pa), > 0.
    nu : float
        Poisson's ratio (-), in [0, 0.5).
    density : float
        Mass density (kg/m^3), > 0.
    """

    E: float
    nu: float
    density: float
    model: str = field(default="elastic", init=False)
    plastic = False

    def validate(self, where: str = "material") -> Elastic:
        """Check every parameter; raise InvalidArgument naming ``where.field``."""
        finite_number(f"{where}.E", self.E, lo=0.0, lo_open=True)
        finite_number(f"{where}.nu", self.nu, lo=0.0, hi=0.5, hi_open=True)
        finite_number(f"{where}.density", self.density, lo=0.0, lo_open=True)
        return self

    @property
    def mu(self) -> float:
        """Shear modulus (Pa), :func:`lame_parameters`."""
        return lame_parameters(self.E, self.nu)[0]

    @property
    def lam(self) -> float:
        """First Lame parameter (Pa), :func:`lame_parameters`."""
        return lame_parameters(self.E, self.nu)[1]

    @property
    def bulk(self) -> float:
        """Bulk modulus K = lam + 2 mu / 3 (Pa), :func:`lame_parameters`."""
        return lame_parameters(self.E, self.nu)[2]

    @property
    def p_wave_speed(self) -> float:
        """c_p = sqrt((lam + 2 mu) / rho) (m/s)."""
        return math.sqrt((self.lam + 2.0 * self.mu) / self.density)

    @property
    def s_wave_speed(self) -> float:
        """c_s = sqrt(mu / rho) (m/s)."""
        return math.sqrt(self.mu / self.density)

    @property
    def rayleigh_speed(self) -> float:
        """Rayleigh wave speed c_R ~ c_s (0.862 + 1.14 nu) / (1 + nu) (m/s), docs/model.md §7."""
        return self.s_wave_speed * (0.862 + 1.14 * self.nu) / (1.0 + self.nu)

    def to_dict(self) -> dict:
        """Plain dict (for scenario files and output attributes)."""
        return asdict(self)


@dataclass(frozen=True)
class CamClaySnow(Elastic):
    """Cohesive modified Cam-Clay snow with hardening and softening (docs/model.md §2-3).

    Parameters
    ----------
    E, nu, density : float
        Elasticity as in :class:`Elastic`.
    M : float
        Slope of the critical state line (-), > 0.
    beta : float
        Cohesion ratio (-): tensile strength is ``beta p0``; >= 0.
    xi : float
        Hardening factor (-) in ``p0 = K sinh(xi max(-log_Jp, 0))``; > 0.
    p0_ini : float
        Initial consolidation pressure (Pa), >= 0; sets ``log_Jp(0) = -asinh(p0_ini/K)/xi``.
    p0_floor_ratio : float
        Floor of p0 relative to K (-), keeps the return defined for fully
        softened material; default 1e-5 (docs/model.md §3).
    """

    M: float = 1.0
    beta: float = 0.3
    xi: float = 1.0
    p0_ini: float = 0.0
    p0_floor_ratio: float = 1e-5
    model: str = field(default="camclay", init=False)
    plastic = True

    def validate(self, where: str = "material") -> CamClaySnow:
        """Check every parameter; raise InvalidArgument naming ``where.field``."""
        super().validate(where)
        finite_number(f"{where}.M", self.M, lo=0.0, lo_open=True)
        finite_number(f"{where}.beta", self.beta, lo=0.0)
        finite_number(f"{where}.xi", self.xi, lo=0.0, lo_open=True)
        finite_number(f"{where}.p0_ini", self.p0_ini, lo=0.0)
        finite_number(f"{where}.p0_floor_ratio", self.p0_floor_ratio, lo=0.0, hi=1e-2, lo_open=True)
        return self

    @property
    def p0_floor(self) -> float:
        """Floor of the consolidation pressure (Pa)."""
        return self.p0_floor_ratio * self.bulk

    @property
    def initial_log_jp(self) -> float:
        """``log_Jp(0) = -asinh(p0_ini / K) / xi`` (docs/model.md §3; :func:`.kernels.camclay.initial_log_jp`)."""
        return initial_log_jp(self.p0_ini, self.bulk, self.xi)

    def collapse_at(self, p) -> float:
        """Collapse ``1 - J_P / J_P,ini`` (-) consolidating from ``p0_ini`` to the pressure ``p`` (Pa),
        :func:`hardening_collapse`."""
        return hardening_collapse(p, self.bulk, self.xi, self.p0_ini)


@dataclass(frozen=True)
class BondedCamClay(Elastic):
    """Bonded (structured) Cam-Clay weak layer: strength lost over a set plastic work, then collapse.

    The yield ellipse of docs/model.md §2 with ``p0 = p0_int(log_Jp) + b p_bond`` and
    cohesion ratio ``beta b``, ``b = max(0, 1 - kappa / kappa_s)`` the bond,
    ``kappa`` the plastic work done per unit volume (J/m^3, layer-column mean: the
    layer is debonded once it dissipated ``kappa_s D_wl`` per unit area) and ``p0_int =
    K sinh(xi max(-log_Jp, 0))`` the intrinsic hardening (docs/model.md §3b;
    :mod:`mpm_warp.kernels.bonded_camclay`). Kernel state: ``(log_jp, kappa)``.
    Build it from field measurements with :func:`mpm_warp.scenes.weak_layer.calibration.weak_layer_material`.

    Parameters
    ----------
    E, nu, density : float
        Elasticity as in :class:`Elastic`.
    M : float
        Slope of the critical state line (-), > 0.
    beta : float
        Cohesion ratio of the intact layer (-), in [0, 1]: tensile strength ``beta p0``.
    xi : float
        Intrinsic hardening factor (-), > 0.
    p0_int_ini : float
        Initial intrinsic consolidation pressure (Pa), >= 0 (0: a loose skeleton
        that collapses once debonded); ``log_Jp(0) = -asinh(p0_int_ini / K) / xi``.
    p0_floor_ratio : float
        Floor of ``p0_int`` relative to K (-), in (0, 1e-2]; default 1e-5 (docs/model.md §3).
    p_bond : float
        Bonded part of the consolidation pressure of the intact layer (Pa), >= 0.
    kappa_s : float
        Plastic work per unit volume at which the bond is gone (J/m^3), > 0; ``inf`` keeps the bond.
    """

    M: float = 1.2
    beta: float = 0.3
    xi: float = 0.01
    p0_int_ini: float = 0.0
    p0_floor_ratio: float = 1e-5
    p_bond: float = 0.0
    kappa_s: float = 30.0
    model: str = field(default="bonded_camclay", init=False)
    plastic = True

    def validate(self, where: str = "material") -> BondedCamClay:
        """Check every parameter; raise InvalidArgument naming ``where.field``."""
        super().validate(where)
        finite_number(f"{where}.M", self.M, lo=0.0, lo_open=True)
        finite_number(f"{where}.beta", self.beta, lo=0.0, hi=1.0)
        finite_number(f"{where}.xi", self.xi, lo=0.0, lo_open=True)
        finite_number(f"{where}.p0_int_ini", self.p0_int_ini, lo=0.0)
        finite_number(f"{where}.p0_floor_ratio", self.p0_floor_ratio, lo=0.0, hi=1e-2, lo_open=True)
        finite_number(f"{where}.p_bond", self.p_bond, lo=0.0)
        if self.kappa_s != math.inf:  # inf: a bond that never breaks (structured Cam-Clay without destructuring)
            finite_number(f"{where}.kappa_s", self.kappa_s, lo=0.0, lo_open=True)
        return self

    @property
    def p0_floor(self) -> float:
        """Floor of the intrinsic consolidation pressure (Pa)."""
        return self.p0_floor_ratio * self.bulk

    @property
    def initial_log_jp(self) -> float:
        """``log_Jp(0) = -asinh(p0_int_ini / K) / xi`` (docs/model.md §3)."""
        return initial_log_jp(self.p0_int_ini, self.bulk, self.xi)

    @property
    def p0_ini(self) -> float:
        """Consolidation pressure of the intact layer, ``max(p0_int_ini, p0_floor) + p_bond`` (Pa)."""
        return max(self.p0_int_ini, self.p0_floor) + self.p_bond

    @property
    def initial_kappa(self) -> float:
        """``kappa(0) = 0``: the layer starts intact (a saw cut sets ``kappa >= kappa_s``)."""
        return 0.0


@dataclass(frozen=True)
class CrackingSnow(Elastic):
    """Elastic snow that cracks in tension: a slab that can break (docs/model.md §9; ``kernels/cracking.py``).

    Hencky elasticity as :class:`Elastic` until the largest principal stress reaches the tensile strength;
    then the tensile stress softens linearly to nothing while the fracture energy is spent over a crack band
    of width ``band_width`` (Bazant and Oh 1983): the effective stress at full damage is
    :attr:`failure_stress` ``= 2 E G_f / (sigma_t h)``. Compression is carried throughout (a crack closes).
    Kernel state: ``kappa``, the largest effective tensile stress so far (Pa).

    Parameters
    ----------
    E, nu, density : float
        Elasticity as in :class:`Elastic`.
    tensile_strength : float
        Tensile strength ``sigma_t`` (Pa), > 0.
    fracture_energy : float
        Mode-I fracture energy ``G_f`` (J/m^2), > 0.
    band_width : float
        Width ``h`` of the band a crack localises in (m), > 0: 1.5 grid spacings at 2 particles per cell, the
        width a crack breaks (docs/model.md §9). At most
        ``2 E G_f / sigma_t^2``, the width beyond which the softening would snap back.
    """

    tensile_strength: float = 5.0e3
    fracture_energy: float = 0.1
    band_width: float = 0.01
    model: str = field(default="tensile_cracking", init=False)
    plastic = False

    @property
    def failure_stress(self) -> float:
        """Effective tensile stress at full damage, ``2 E G_f / (sigma_t h)`` (Pa)."""
        return 2.0 * self.E * self.fracture_energy / (self.tensile_strength * self.band_width)

    @property
    def max_band_width(self) -> float:
        """The widest band without snap-back, ``2 E G_f / sigma_t^2`` (m)."""
        return 2.0 * self.E * self.fracture_energy / self.tensile_strength**2

    @property
    def initial_kappa(self) -> float:
        """``kappa(0) = 0``: never loaded beyond its strength."""
        return 0.0

    def damage(self, kappa):
        """Damage ``d`` (-, 0 intact to 1 a traction-free crack) at the largest effective tensile stress ``kappa``
        (Pa, float or array): the host mirror of ``kernels/cracking.py``'s ``damage``."""
        k = np.asarray(kappa, dtype=np.float64)
        st, sf = self.tensile_strength, self.failure_stress
        with np.errstate(divide="ignore", invalid="ignore"):
            d = np.where(k <= st, 0.0, np.where(k >= sf, 1.0, 1.0 - (st / k) * (sf - k) / (sf - st)))
        return float(d) if d.ndim == 0 else d

    def validate(self, where: str = "material") -> CrackingSnow:
        """Check every parameter; raise InvalidArgument naming ``where.field``."""
        super().validate(where)
        finite_number(f"{where}.tensile_strength", self.tensile_strength, lo=0.0, lo_open=True)
        finite_number(f"{where}.fracture_energy", self.fracture_energy, lo=0.0, lo_open=True)
        h = finite_number(f"{where}.band_width", self.band_width, lo=0.0, lo_open=True)
        if h >= self.max_band_width:
            raise InvalidArgument(f"{where}.band_width", h, (
                f"a crack band narrower than 2 E G_f / sigma_t^2 = {self.max_band_width:.3g} m (wider, the softening "
                "snaps back): refine the grid, or raise the fracture energy or lower the tensile strength"))
        return self


Material = Elastic | CamClaySnow | BondedCamClay | CrackingSnow
MATERIAL_MODELS = {"elastic": Elastic, "camclay": CamClaySnow, "bonded_camclay": BondedCamClay,
                   "tensile_cracking": CrackingSnow}

