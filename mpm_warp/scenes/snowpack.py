"""Layered snow: a slab or a substratum as a stack of elastic layers, top to bottom (docs/model.md §8).

A :class:`SnowLayer` has a thickness, a density and E, nu; an omitted E (0) comes from the density
through the power law of Bergfeld et al. (2023) that weac uses (:mod:`.density_laws`). A stack's load on
the layer below it, its bending-equivalent homogeneous slab (for the closed-form references) and its layer
boundaries are functions of the stack here.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..checks import finite_number
from ..errors import InvalidArgument
from ..materials import CrackingSnow
from .density_laws import RHO_ICE, bergfeld_modulus, fracture_toughness, sigrist_tensile_strength
from .snow import Slab, slab_normal_stress

__all__ = ["SnowLayer", "stack_thickness", "stack_normal_stress", "equivalent_slab", "check_stack"]

@dataclass(frozen=True)
class SnowLayer:
    """One elastic snow layer of a slab or a substratum.

    Attributes
    ----------
    thickness : float
        Bed-normal thickness (m), > 0.
    density : float
        Density (kg/m^3), in (0, RHO_ICE].
    E : float
        Young's modulus (Pa), >= 0; 0 = from the density, :func:`bergfeld_modulus`.
    nu : float
        Poisson's ratio (-), in [0, 0.5).
    tensile_strength : float
        Tensile strength (Pa) of a slab that can break, >= 0; 0 = from the density (Sigrist 2006) when the
        scene's slab fracture is on, unused otherwise.
    fracture_energy : float
        Mode-I fracture energy (J/m^2) of a slab that can break, >= 0; 0 = from the density when the scene's
        slab fracture is on, unused otherwise.
    name : str
        A label (e.g. the grain type and hardness of a profile layer), shown in summaries.
    """

    thickness: float
    density: float = 250.0
    E: float = 0.0
    nu: float = 0.3
    tensile_strength: float = 0.0
    fracture_energy: float = 0.0
    name: str = ""

    @property
    def strength(self) -> float:
        """Tensile strength (Pa): ``tensile_strength``, or :func:`sigrist_tensile_strength` of the density."""
        return float(self.tensile_strength) if self.tensile_strength > 0.0 else sigrist_tensile_strength(self.density)

    @property
    def toughness_energy(self) -> float:
        """Mode-I fracture energy (J/m^2): ``fracture_energy``, or ``K_Ic^2 (1 - nu^2) / E`` with
        :func:`fracture_toughness` of the density."""
        if self.fracture_energy > 0.0:
            return float(self.fracture_energy)
        return fracture_toughness(self.density) ** 2 * (1.0 - self.nu**2) / self.modulus

    def cracking(self, band_width: float) -> CrackingSnow:
        """The layer as a slab that can break, its crack band ``band_width`` (m) wide."""
        return CrackingSnow(self.modulus, self.nu, self.density, tensile_strength=self.strength,
                            fracture_energy=self.toughness_energy, band_width=float(band_width))

    @property
    def modulus(self) -> float:
        """Young's modulus (Pa): ``E``, or :func:`bergfeld_modulus` of the density when ``E`` is 0."""
        return float(self.E) if self.E > 0.0 else bergfeld_modulus(self.density)

    def slab(self) -> Slab:
        """The layer's elastic material as a :class:`~mpm_warp.scenes.snow.Slab` (E resolved)."""
        return Slab(E=self.modulus, nu=self.nu, density=self.density, tensile_strength=self.tensile_strength,
                    fracture_energy=self.fracture_energy)

    def validate(self, where: str = "layer") -> SnowLayer:
        """Check every value (InvalidArgument naming ``where.field``); return self."""
        finite_number(f"{where}.thickness", self.thickness, lo=0.0, lo_open=True)
        finite_number(f"{where}.density", self.density, lo=0.0, hi=RHO_ICE, lo_open=True)
        finite_number(f"{where}.E", self.E, lo=0.0)
        finite_number(f"{where}.nu", self.nu, lo=0.0, hi=0.5, hi_open=True)
        finite_number(f"{where}.tensile_strength", self.tensile_strength, lo=0.0)
        finite_number(f"{where}.fracture_energy", self.fracture_energy, lo=0.0)
        if not isinstance(self.name, str):
            raise InvalidArgument(f"{where}.name", self.name, "a string")
        return self


def check_stack(layers: Sequence[SnowLayer], where: str) -> tuple[SnowLayer, ...]:
    """Check a stack (a non-empty sequence of :class:`SnowLayer`, top to bottom); return it as a tuple."""
    if isinstance(layers, (str, bytes)) or not isinstance(layers, Sequence) or not layers:
        raise InvalidArgument(where, layers, "a non-empty list of layers, top to bottom")
    for i, layer in enumerate(layers):
        if not isinstance(layer, SnowLayer):
            raise InvalidArgument(f"{where}[{i}]", layer, "a SnowLayer (thickness, density, E, nu)")
        layer.validate(f"{where}[{i}]")
    return tuple(layers)


def stack_thickness(layers: Sequence[SnowLayer]) -> float:
    """Total thickness of a stack (m)."""
    return float(sum(layer.thickness for layer in layers))


def stack_normal_stress(layers: Sequence[SnowLayer], slope_deg: float = 0.0) -> float:
    """Bed-normal stress of a stack's weight on what lies below it (Pa): ``sum rho_i g h_i cos(theta)``."""
    return float(sum(slab_normal_stress(layer.density, layer.thickness, slope_deg) for layer in layers))


def equivalent_slab(layers: Sequence[SnowLayer]) -> Slab:
    """The homogeneous slab of the same thickness, weight and bending stiffness as a stack (docs/model.md §8).

    ``E_eq = 12 D / H^3`` with the laminate's bending stiffness about its neutral axis,
    ``D = sum E_i (h_i^3 / 12 + h_i (z_i - z_n)^2)``, ``z_n = sum E_i h_i z_i / sum E_i h_i`` (``z_i`` the layer
    centres); density the mean ``sum rho_i h_i / H``; ``nu`` the stiffness-weighted mean ``sum E_i h_i nu_i /
    sum E_i h_i``. One layer gives itself back exactly.
    """
    if len(layers) == 1:
        return layers[0].slab()
    H = stack_thickness(layers)
    z, top = [], 0.0
    for layer in layers:
        z.append(top + 0.5 * layer.thickness)
        top += layer.thickness
    Eh = [layer.modulus * layer.thickness for layer in layers]
    zn = sum(e * zi for e, zi in zip(Eh, z, strict=True)) / sum(Eh)
    D = sum(layer.modulus * (layer.thickness**3 / 12.0 + layer.thickness * (zi - zn) ** 2)
            for layer, zi in zip(layers, z, strict=True))
    rho = sum(layer.density * layer.thickness for layer in layers) / H
    nu = sum(e * layer.nu for e, layer in zip(Eh, layers, strict=True)) / sum(Eh)
    return Slab(E=12.0 * D / H**3, nu=nu, density=rho)
