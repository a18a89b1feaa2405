"""Parameters of the unconfined shear test and the values derived from them."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import ClassVar

from ...checks import check_choices, finite_number, positive_int
from ...errors import InvalidArgument
from ..snow import GRAVITY, Settle, Slab, check_weak_layer_cells, slab_normal_stress
from ..weak_layer import CalibratedWeakLayer, WeakLayer

__all__ = ["SlabLoad", "ShearTestParams"]


@dataclass(frozen=True)
class SlabLoad(Slab):
    """The slab whose bed-normal load the test applies (``E`` and ``nu`` also of the loading block).

    Attributes
    ----------
    E, nu, density : float
        As :class:`~mpm_warp.scenes.snow.Slab` (Pa, -, kg/m^3).
    thickness : float
        Slab thickness (m), > 0.
    """

    thickness: float = 0.5

    def validate(self, where: str = "slab") -> SlabLoad:
        """Check every value; return self."""
        super().validate(where)
        finite_number(f"{where}.thickness", self.thickness, lo=0.0, lo_open=True)
        return self


@dataclass(frozen=True)
class ShearTestParams:
    """An unconfined shear test of the weak layer (``[scene] kind = "shear_test"``; SI Note 2).

    Attributes
    ----------
    dx : float
        Grid spacing (m), > 0.
    particles_per_cell : int
        Particles per cell and axis, 1-8.
    sample_length : float
        Sample length L_s (m), > 0.
    weak_layer_thickness : float
        D_wl (m), at least 3 grid cells (:data:`~mpm_warp.scenes.snow.MIN_WEAK_LAYER_CELLS`, as the PST's).
    load_thickness : float
        Thickness t of the loading block (m), >= 2 dx; its density ``sigma_n / (g t)`` gives the slab's load.
    width : float
        Sample width (m); 0 = plane strain.
    wall_speed : float
        Push speed of the loading block (m/s), > 0.
    margin : float
        Free space around the sample (m), >= 2 dx; rounded up to whole cells.
    slope_angle : float
        Slope (deg) of the PST whose slab load is reproduced, in [-60, 60].
    slab, weak_layer, settle
        :class:`SlabLoad`, :class:`~mpm_warp.scenes.weak_layer.WeakLayer`, :class:`~mpm_warp.scenes.snow.Settle`.
    interface_closure : bool
        The laminate closure at the layer's interface with the loading block (docs/model.md §5b; as the PST's
        option). False (the default): the plain MLS-MPM strain.
    """

    kind: ClassVar[str] = "shear_test"
    dx: float = 0.005
    particles_per_cell: int = 2
    sample_length: float = 0.2
    weak_layer_thickness: float = 0.02
    load_thickness: float = 0.05
    width: float = 0.0
    wall_speed: float = 0.01
    margin: float = 0.03
    slope_angle: float = 0.0
    slab: SlabLoad = field(default_factory=SlabLoad)
    weak_layer: WeakLayer = field(default_factory=WeakLayer)
    settle: Settle = field(default_factory=Settle)
    interface_closure: bool = False

    def validate(self, where: str = "scene") -> ShearTestParams:
        """Check every value (InvalidArgument naming ``where.field``, the value and the range); return self."""
        check_choices(self, where)
        dx = finite_number(f"{where}.dx", self.dx, lo=0.0, lo_open=True)
        positive_int(f"{where}.particles_per_cell", self.particles_per_cell, lo=1, hi=8)
        finite_number(f"{where}.sample_length", self.sample_length, lo=0.0, lo_open=True)
        d_wl = finite_number(f"{where}.weak_layer_thickness", self.weak_layer_thickness, lo=0.0, lo_open=True)
        check_weak_layer_cells(d_wl, dx, where)
        finite_number(f"{where}.load_thickness", self.load_thickness, lo=2.0 * dx)
        finite_number(f"{where}.wall_speed", self.wall_speed, lo=0.0, lo_open=True)
        finite_number(f"{where}.width", self.width, lo=0.0)
        finite_number(f"{where}.margin", self.margin, lo=2.0 * dx)
        finite_number(f"{where}.slope_angle", self.slope_angle, lo=-60.0, hi=60.0)
        self.slab.validate(f"{where}.slab")
        self.weak_layer.validate(f"{where}.weak_layer")
        self.settle.validate(f"{where}.settle")
        if not isinstance(self.interface_closure, bool):
            raise InvalidArgument(f"{where}.interface_closure", self.interface_closure, "true or false")
        return self

    def to_dict(self) -> dict:
        """Plain dict of the parameters (the ``[scene]`` table; the loader reads it back; ``interface_closure``
        only when on, so the files of scenes without it are unchanged)."""
        d = asdict(self)
        if not self.interface_closure:
            del d["interface_closure"]
        return d

    # ------------------------------------------------------------- derived values
    @property
    def sigma_n(self) -> float:
        """Bed-normal stress of the slab (Pa), ``rho g D cos(theta)``."""
        return slab_normal_stress(self.slab.density, self.slab.thickness, self.slope_angle)

    @property
    def load_density(self) -> float:
        """Density of the loading block (kg/m^3), ``sigma_n / (g t)``."""
        return self.sigma_n / (GRAVITY * self.load_thickness)

    @property
    def push_start(self) -> float:
        """Time the push starts (s): the end of settling."""
        return float(self.settle.duration)

    @property
    def margin_cells(self) -> float:
        """The margin rounded up to whole cells (m)."""
        return math.ceil(self.margin / self.dx) * self.dx

    @property
    def depth(self) -> float:
        """Extent of the sample in z (m): 1 m of depth in plane strain (quantities per metre), else ``width``."""
        return float(1.0 if self.width <= 0.0 else self.width)

    @property
    def sample_area(self) -> float:
        """Sheared area of the sample (m^2), ``L_s`` x its depth."""
        return self.sample_length * self.depth

    def calibrated(self) -> CalibratedWeakLayer:
        """The weak layer calibrated under the slab (:meth:`~mpm_warp.scenes.weak_layer.WeakLayer.calibrate`)."""
        return self.weak_layer.calibrate(self.weak_layer_thickness, self.slab.density, self.slab.thickness,
                                         abs(self.slope_angle), self.slab.E, self.slab.nu)

    def references(self, wl: CalibratedWeakLayer) -> dict[str, float]:
        """The calibrated layer's predictions (``wl``, :meth:`calibrated` or a scenario's stored calibration):
        ``sigma_n``, ``tau_p``, ``tau_peak`` (material-point peak), ``p0_ini`` (Pa); ``delta_s`` (m), ``w_f``
        (J/m^2); ``collapse_fraction_law`` (-, the debonded layer under the slab)."""
        return {"sigma_n": self.sigma_n, "tau_p": wl.tau_p, "tau_peak": wl.tau_peak, "p0_ini": wl.material.p0_ini,
                "delta_s": wl.delta_s, "w_f": wl.w_f, "collapse_fraction_law": wl.h_c / self.weak_layer_thickness}
