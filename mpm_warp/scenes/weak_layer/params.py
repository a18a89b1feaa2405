"""Parameters of the snow scenes' weak layer: Cam-Clay snow plus the brittle failure rule's settings."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from ...checks import choice, finite_number
from ...materials import CamClaySnow

__all__ = ["WeakLayer", "FAILURE_RULES"]

#: failure rules of the weak layer: "brittle" (:mod:`.kernels`) or "none" (the engine's Cam-Clay only)
FAILURE_RULES = ("brittle", "none")


@dataclass(frozen=True)
class WeakLayer:
    """The weak layer: cohesive Cam-Clay snow (MODEL.md 2-3) and its failure rule.

    Defaults: see ``scenarios/pst_flat.toml`` for the reasoning behind each value.

    Attributes
    ----------
    E : float
        Young's modulus (Pa), > 0.
    nu : float
        Poisson's ratio (-), in [0, 0.5).
    density : float
        Density (kg/m^3), > 0.
    M : float
        Slope of the critical state line (-), > 0.
    beta : float
        Cohesion ratio (-), >= 0.
    xi : float
        Hardening factor (-), > 0.
    consolidation_ratio : float
        ``p0_ini = consolidation_ratio * sigma_n`` when ``p0_ini`` < 0 (-), >= 0: the layer
        consolidated by the slab it carries.
    p0_ini : float
        Initial consolidation pressure (Pa); < 0 (default) derives it from ``consolidation_ratio``.
    p0_floor_ratio : float
        Floor of p0 relative to the bulk modulus (-).
    failure : {"brittle", "none"}
        "brittle": a particle loses its cohesion at first yield after settling (:mod:`.kernels`);
        "none": the engine's Cam-Clay alone.
    failure_log_jp : float
        Hardening state given at failure (-): ``log_jp = max(log_jp, failure_log_jp)``; 0 puts p0 at its floor.
    """

    E: float = 1.0e6
    nu: float = 0.3
    density: float = 150.0
    M: float = 1.2
    beta: float = 0.3
    xi: float = 0.0066
    consolidation_ratio: float = 3.0
    p0_ini: float = -1.0
    p0_floor_ratio: float = 1e-5
    failure: Literal["brittle", "none"] = "brittle"
    failure_log_jp: float = 0.0

    def consolidation(self, sigma_n: float) -> float:
        """Initial consolidation pressure (Pa): ``p0_ini``, or ``consolidation_ratio * sigma_n`` (Pa) if negative."""
        return float(self.p0_ini) if self.p0_ini >= 0 else float(self.consolidation_ratio) * sigma_n

    def material(self, sigma_n: float) -> CamClaySnow:
        """The layer's Cam-Clay material under the slab's bed-normal stress ``sigma_n`` (Pa)."""
        return CamClaySnow(self.E, self.nu, self.density, M=self.M, beta=self.beta, xi=self.xi,
                           p0_ini=self.consolidation(sigma_n), p0_floor_ratio=self.p0_floor_ratio)

    @property
    def brittle(self) -> bool:
        """True with the brittle failure rule."""
        return self.failure == "brittle"

    def validate(self, where: str = "weak_layer") -> WeakLayer:
        """Check every value (InvalidArgument naming ``where.field``); return self."""
        choice(f"{where}.failure", self.failure, FAILURE_RULES)
        finite_number(f"{where}.failure_log_jp", self.failure_log_jp)
        finite_number(f"{where}.p0_ini", self.p0_ini)
        finite_number(f"{where}.consolidation_ratio", self.consolidation_ratio, lo=0.0)
        self.material(0.0).validate(where)
        return self
