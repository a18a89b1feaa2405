"""The record of a calibrated weak layer: its model parameters, what was given, and what they predict."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from ...camclay_forms import hardening_collapse
from ...materials import BondedCamClay

__all__ = ["CalibratedWeakLayer"]


@dataclass(frozen=True)
class CalibratedWeakLayer:
    """A calibrated weak layer: the material, what was given, what was derived and predicted.

    Attributes (SI units)
    ---------------------
    material : BondedCamClay
    D_wl : float
        Layer thickness (m).
    sigma_n, tau_slope : float
        Slab normal and bed-parallel stress at rest (Pa).
    given : dict
        The measured inputs as the user gave them (name -> value).
    tau_p, w_f, delta_s, h_c : float
        Shear strength (Pa), fracture energy (J/m^2), softening slip (m), collapse height (m):
        given or predicted, as the reference tests of docs/model.md §3b define them (:mod:`.paths`).
    p_bond, kappa_s, xi : float
        The model parameters (Pa, -, -).
    tau_peak, tau_residual, bond_at_collapse : float
        Shear-test peak and residual (Pa) and the bond the collapse removed (-), driven.
    compressive_strength : float
        Oedometric strength of the intact layer (Pa).
    critical_cut : float or None
        Gaume et al. (2017) ``a_c`` (m), when the slab's ``E``, ``nu`` and density are known.
    critical_cut_inputs : dict
    heierli_speed, heierli_touchdown : float or None
        Heierli (2005) anticrack speed (m/s) and touchdown distance (m) with this ``h_c``,
        when the slab's ``E``, thickness and density are known.
    calibration : dict
        ``runs``, ``n_increments``, ``relative_error`` of the ``kappa_s`` iteration.
    """

    material: BondedCamClay
    D_wl: float
    sigma_n: float
    tau_slope: float
    given: dict
    tau_p: float
    w_f: float
    delta_s: float
    h_c: float
    p_bond: float
    kappa_s: float
    xi: float
    tau_peak: float
    tau_residual: float
    bond_at_collapse: float
    compressive_strength: float
    critical_cut: float | None
    critical_cut_inputs: dict = field(default_factory=dict)
    heierli_speed: float | None = None
    heierli_touchdown: float | None = None
    calibration: dict = field(default_factory=dict)

    def collapse_law(self, p0_int):
        """Collapse ``1 - J_P/J_P(0)`` of the debonded layer at the final consolidation pressure ``p0_int`` (Pa)."""
        m = self.material
        return hardening_collapse(p0_int, m.bulk, m.xi, m.p0_int_ini)

    def to_dict(self) -> dict:
        """Plain dict (the material as its own dict); :meth:`from_dict` reads it back exactly."""
        d = asdict(self)
        d["material"] = self.material.to_dict()
        return d

    @classmethod
    def from_dict(cls, d: dict) -> CalibratedWeakLayer:
        """The calibration stored by :meth:`to_dict` (e.g. in a run file's scenario), without running it again."""
        d = dict(d)
        mat = {k: v for k, v in d.pop("material").items() if k != "model"}
        return cls(material=BondedCamClay(**mat), **d)

    @property
    def debond_energy(self) -> float:
        """Plastic work per unit area that debonds the layer, ``D_wl kappa_s`` (J/m^2), in shear, compaction or any
        mix; ``w_f`` is the part of it above the residual friction in the shear test."""
        return self.D_wl * self.kappa_s

    def describe(self) -> str:
        """Human-readable summary: inputs, derived parameters, predictions (printed by the scenes)."""
        m = self.material
        src = {k: "given" for k in self.given}
        if "h_c" not in self.given and "xi" not in self.given:
            src["h_c"] = "WEAC fit of D_wl"
        lines = [
            f"weak layer D_wl = {self.D_wl * 1e3:.3g} mm under sigma_n = {self.sigma_n:.4g} Pa"
            + (f" (bed-parallel {self.tau_slope:.4g} Pa)" if self.tau_slope else ""),
            f"  elastic E = {m.E:.4g} Pa, nu = {m.nu:.3g}, rho = {m.density:.4g} kg/m^3; M = {m.M:.3g}, "
            f"beta = {m.beta:.3g}, p0_int_ini = {m.p0_int_ini:.4g} Pa",
            f"  shear strength   tau_p   = {self.tau_p:9.4g} Pa    ({src.get('tau_p', 'predicted')})",
            f"  fracture energy  w_f     = {self.w_f:9.4g} J/m^2 ({src.get('w_f', 'predicted')})",
            f"  softening slip   delta_s = {self.delta_s * 1e3:9.4g} mm    ({src.get('delta_s', 'predicted')})",
            f"  collapse height  h_c     = {self.h_c * 1e3:9.4g} mm    ({src.get('h_c', 'predicted')}; "
            f"{self.h_c / self.D_wl:.3g} of the layer)",
            f"  -> p_bond = {self.p_bond:.5g} Pa, kappa_s = {self.kappa_s:.5g} J/m^3, xi = {self.xi:.5g} "
            f"(intact p0 = {m.p0_ini:.5g} Pa); debonded after {self.debond_energy:.3g} J/m^2 of plastic work, "
            "in any mode",
            f"  predicted: compressive strength {self.compressive_strength:.4g} Pa "
            f"({self.compressive_strength / self.sigma_n:.3g} x sigma_n); shear-test peak {self.tau_peak:.4g} Pa, "
            f"residual {self.tau_residual:.3g} Pa; collapse removes the last {self.bond_at_collapse:.2f} of the bond",
        ]
        if self.critical_cut is not None:
            lines.append(f"  critical cut (Gaume et al. 2017, flat) a_c = {self.critical_cut:.3g} m")
        if self.heierli_speed is not None:
            lines.append(f"  anticrack (Heierli 2005, this h_c): speed {self.heierli_speed:.3g} m/s, touchdown "
                         f"{self.heierli_touchdown:.3g} m")
        lines.append(f"  calibration: {self.calibration.get('runs')} shear-test runs, relative error "
                     f"{self.calibration.get('relative_error', 0.0):.1e}")
        return "\n".join(lines)

    __str__ = describe
