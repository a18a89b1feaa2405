"""Parameters of a Propagation Saw Test and the values derived from them (functions of the parameters)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import ClassVar, Literal

import numpy as np

from ...checks import check_choices, finite_number, positive_int
from ...walls import WallKind
from ..references import heierli_speed, heierli_touchdown
from ..snow import (
    PlaneStrain,
    Settle,
    Slab,
    check_plane_strain,
    check_weak_layer_cells,
    oedometric_pressure,
    slab_normal_stress,
)
from ..weak_layer import CalibratedWeakLayer, WeakLayer

__all__ = ["Saw", "Front", "PSTParams"]


@dataclass(frozen=True)
class Saw:
    """The saw: a blade advancing through the weak layer from one end of the column after settling.

    Behind the blade the weak layer loses its bond (a kerf): cohesionless, it collapses under the
    slab as a debonded layer does (:mod:`mpm_warp.scenes.weak_layer`).

    Attributes
    ----------
    speed : float
        Blade speed (m/s), in (0, 1]: a saw is slow against the crack (field saws: 0.1-0.5 m/s).
    cut_length : float
        Length of the cut (m), in [0, length]: where the blade stops.
    from_end : {"left", "right"}
        The end it starts from: "left" (x = 0, the upslope end on a slope) or "right" (x = L).
    """

    speed: float = 1.0
    cut_length: float = 0.6
    from_end: Literal["left", "right"] = "left"


@dataclass(frozen=True)
class Front:
    """The front criteria (see :mod:`mpm_warp.scenes.pst`).

    Attributes
    ----------
    bin : float
        Bin width along the column (m); 0 = the grid spacing.
    deflection : float
        The slab-deflection front: the slab base has come down by this fraction of the collapse
        height ``h_c`` (-), in (0, 1].
    runaway_lead : float
        The crack runs away from the saw once the damage front leads the blade by this (m), > 0:
        the saw position then estimates the critical cut from one run.
    """

    bin: float = 0.0
    deflection: float = 0.1
    runaway_lead: float = 0.3


@dataclass(frozen=True)
class PSTParams:
    """A Propagation Saw Test (``[scene] kind = "pst"``; see :mod:`mpm_warp.scenes.pst`).

    Attributes
    ----------
    dx : float
        Grid spacing (m), > 0: at least 4 cells across the weak layer resolve it (the default).
    particles_per_cell : int
        Particles per cell and axis, 1-8.
    length : float
        Column length L (m), > 0.
    slab_thickness : float
        Slab thickness D (m), > 0.
    weak_layer_thickness : float
        D_wl (m), at least 3 grid cells (:data:`~mpm_warp.scenes.snow.MIN_WEAK_LAYER_CELLS`: the B-spline
        stencils of the slab and the substratum must not share a node); 4 resolve it (the default).
    substratum_thickness : float
        Elastic old snow under the weak layer (m), >= 2 dx: the layer shares no grid node with the bed.
    slope_angle : float
        Slope (deg), in [-60, 60]: gravity ``g (sin, -cos)``.
    width : float
        Column width (m); 0 = plane strain (quantities per metre of depth in true 2D).
    plane_strain : {"2d", "slab"}
        How plane strain (``width = 0``) is run: "2d", the true 2D kernels (the default), or "slab", the
        quasi-2D slab (3D, one cell thick in z between slip walls, 2 particle layers at 2 per cell and axis;
        each layer is the 2D run, at about 5x its cost). "slab" needs ``width = 0``.
    bed : {"sticky", "slip", "separate"}
        Wall kind under the substratum ("separate": Coulomb contact with ``bed_friction``).
    bed_friction : float
        Coulomb coefficient of a "separate" bed (-), >= 0.
    margin : float
        Free space around the column (m), >= 2 dx.
    marker_spacing : float
        Spacing of the slab-base markers along the column (m), > 0.
    slab, substratum, weak_layer, settle, saw, front
        The parts (:class:`~mpm_warp.scenes.snow.Slab` twice: the slab and the old snow under the
        weak layer; :class:`~mpm_warp.scenes.weak_layer.WeakLayer`, :class:`~mpm_warp.scenes.snow.Settle`,
        :class:`Saw`, :class:`Front`).
    """

    kind: ClassVar[str] = "pst"
    dx: float = 0.0075
    particles_per_cell: int = 2
    length: float = 8.0
    slab_thickness: float = 0.5
    weak_layer_thickness: float = 0.03
    substratum_thickness: float = 0.15
    slope_angle: float = 0.0
    width: float = 0.0
    plane_strain: PlaneStrain = "2d"
    bed: WallKind = "sticky"
    bed_friction: float = 0.5
    margin: float = 0.05
    marker_spacing: float = 0.1
    slab: Slab = field(default_factory=Slab)
    substratum: Slab = field(default_factory=Slab)
    weak_layer: WeakLayer = field(default_factory=WeakLayer)
    settle: Settle = field(default_factory=Settle)
    saw: Saw = field(default_factory=Saw)
    front: Front = field(default_factory=Front)

    def validate(self, where: str = "scene") -> PSTParams:
        """Check every value (InvalidArgument naming ``where.field``, the value and the range); return self."""
        check_choices(self, where)
        dx = finite_number(f"{where}.dx", self.dx, lo=0.0, lo_open=True)
        positive_int(f"{where}.particles_per_cell", self.particles_per_cell, lo=1, hi=8)
        L = finite_number(f"{where}.length", self.length, lo=0.0, lo_open=True)
        finite_number(f"{where}.slab_thickness", self.slab_thickness, lo=0.0, lo_open=True)
        d_wl = finite_number(f"{where}.weak_layer_thickness", self.weak_layer_thickness, lo=0.0, lo_open=True)
        check_weak_layer_cells(d_wl, dx, where)
        finite_number(f"{where}.substratum_thickness", self.substratum_thickness, lo=2.0 * dx)
        finite_number(f"{where}.slope_angle", self.slope_angle, lo=-60.0, hi=60.0)
        finite_number(f"{where}.width", self.width, lo=0.0)
        check_plane_strain(self.plane_strain, self.width, where)
        finite_number(f"{where}.margin", self.margin, lo=2.0 * dx)
        finite_number(f"{where}.bed_friction", self.bed_friction, lo=0.0)
        finite_number(f"{where}.marker_spacing", self.marker_spacing, lo=0.0, lo_open=True)
        self.slab.validate(f"{where}.slab")
        self.substratum.validate(f"{where}.substratum")
        self.weak_layer.validate(f"{where}.weak_layer")
        self.settle.validate(f"{where}.settle")
        finite_number(f"{where}.saw.cut_length", self.saw.cut_length, lo=0.0, hi=L)
        finite_number(f"{where}.saw.speed", self.saw.speed, lo=0.0, lo_open=True, hi=1.0)
        finite_number(f"{where}.front.bin", self.front.bin, lo=0.0)
        finite_number(f"{where}.front.deflection", self.front.deflection, lo=0.0, lo_open=True, hi=1.0)
        finite_number(f"{where}.front.runaway_lead", self.front.runaway_lead, lo=0.0, lo_open=True)
        return self

    def to_dict(self) -> dict:
        """Plain dict of the parameters (the ``[scene]`` table; the loader reads it back)."""
        return asdict(self)

    # ------------------------------------------------------------- derived values
    @property
    def sigma_n(self) -> float:
        """Bed-normal stress of the slab on the weak layer (Pa), ``rho g D cos(theta)``."""
        return slab_normal_stress(self.slab.density, self.slab_thickness, self.slope_angle)

    def calibrated(self) -> CalibratedWeakLayer:
        """The weak layer calibrated under this slab (:meth:`~mpm_warp.scenes.weak_layer.WeakLayer.calibrate`)."""
        return self.weak_layer.calibrate(self.weak_layer_thickness, self.slab.density, self.slab_thickness,
                                         abs(self.slope_angle), self.slab.E, self.slab.nu)

    @property
    def base_y(self) -> float:
        """Bed-normal position of the slab's base (m): substratum and weak layer below it."""
        return self.substratum_thickness + self.weak_layer_thickness

    @property
    def saw_start(self) -> float:
        """Time the saw starts (s): the end of settling."""
        return float(self.settle.duration)

    @property
    def saw_end(self) -> float:
        """Time the saw stops (s)."""
        return self.saw_start + self.saw.cut_length / self.saw.speed

    @property
    def bin_width(self) -> float:
        """Width of the front bins (m)."""
        return float(self.front.bin or self.dx)

    @property
    def n_bins(self) -> int:
        """Number of front bins along the column."""
        return int(math.ceil(self.length / self.bin_width - 1e-9))

    def markers(self) -> np.ndarray:
        """Slab-base marker stations along x (m), every ``marker_spacing`` from half a spacing."""
        return np.asarray([float(m) for m in np.arange(0.5 * self.marker_spacing, self.length, self.marker_spacing)])

    def distance_from_cut_end(self, x):
        """Distance (m) of positions ``x`` (m) from the end the saw starts at (its own inverse: distance to x)."""
        return np.asarray(x, dtype=float) if self.saw.from_end == "left" else self.length - np.asarray(x, dtype=float)

    def references(self) -> dict[str, float]:
        """Closed-form references of this PST (:mod:`mpm_warp.scenes.references`) with the calibrated layer.

        ``sigma_n``, ``p_oedometric`` (Pa); the layer's ``tau_p`` (Pa), ``w_f`` (J/m^2), ``delta_s``
        (m), ``collapse_height_calibrated`` (m, the debonded layer under this slab at rest); Heierli's
        ``heierli_speed`` (m/s) and ``heierli_touchdown`` (m) with that collapse height; Gaume et al.
        (2017) ``critical_cut_gaume`` (m, flat ground); the slab's ``rayleigh_speed`` and
        ``shear_wave_speed`` (m/s).
        """
        wl = self.calibrated()
        slab = self.slab.material()
        D = self.slab_thickness
        return {"sigma_n": self.sigma_n, "p_oedometric": oedometric_pressure(self.sigma_n, wl.material.nu),
                "tau_p": wl.tau_p, "w_f": wl.w_f, "delta_s": wl.delta_s, "collapse_height_calibrated": wl.h_c,
                "heierli_speed": heierli_speed(slab.E, D, slab.density, wl.h_c),
                "heierli_touchdown": heierli_touchdown(slab.E, D, slab.density, wl.h_c),
                "critical_cut_gaume": float(wl.critical_cut) if wl.critical_cut is not None else math.nan,
                "rayleigh_speed": slab.rayleigh_speed, "shear_wave_speed": slab.s_wave_speed}
