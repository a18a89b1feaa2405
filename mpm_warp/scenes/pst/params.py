"""Parameters of a Propagation Saw Test and the values derived from them (functions of the parameters)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import ClassVar, Literal

import numpy as np

from ...checks import check_choices, finite_number, positive_int
from ...materials import hardening_collapse
from ...walls import WallKind
from ..fronts import fit_window
from ..snow import Settle, Slab, check_weak_layer_cells, oedometric_pressure, slab_normal_stress
from ..weak_layer import WeakLayer
from .references import heierli_speed, heierli_touchdown

__all__ = ["Saw", "Front", "PSTParams"]


@dataclass(frozen=True)
class Saw:
    """The saw: a blade advancing through the weak layer from one end of the column after settling.

    Attributes
    ----------
    speed : float
        Blade speed (m/s), > 0.
    cut_length : float
        Length of the cut (m), in [0, length].
    from_end : {"left", "right"}
        The end it starts from: "left" (x = 0) or "right" (x = L).
    log_jp : float
        Hardening state given to sawn particles (-): large and positive puts p0 at its floor and
        keeps it there (no reachable compaction re-hardens them); re-applied every step.
    """

    speed: float = 4.0
    cut_length: float = 0.4
    from_end: Literal["left", "right"] = "left"
    log_jp: float = 5.0


@dataclass(frozen=True)
class Front:
    """The crack-front criterion.

    Attributes
    ----------
    threshold : float
        A weak-layer particle has collapsed once ``1 - exp(log_jp - log_jp_ref)`` reaches this (-), in (0, 1].
    bin : float
        Bin width along the column (m); 0 = the grid spacing.
    """

    threshold: float = 0.05
    bin: float = 0.0


@dataclass(frozen=True)
class PSTParams:
    """A Propagation Saw Test (``[scene] kind = "pst"``; see :mod:`mpm_warp.scenes.pst`).

    Attributes
    ----------
    dx : float
        Grid spacing (m), > 0.
    particles_per_cell : int
        Particles per cell and axis, 1-8.
    length : float
        Column length L (m), > 0.
    slab_thickness : float
        Slab thickness D (m), > 0.
    weak_layer_thickness : float
        Weak-layer thickness D_wl (m), at least 2 grid cells.
    slope_angle : float
        Slope (deg), in [-60, 60]: gravity ``g (sin, -cos, 0)``.
    width : float
        Column width (m); 0 = plane strain (one cell between slip walls).
    substratum : {"sticky", "slip", "separate"}
        Wall kind of the bed under the weak layer ("separate": Coulomb contact).
    substratum_friction : float
        Coulomb coefficient of a "separate" substratum (-), >= 0.
    margin : float
        Free space around the column (m), >= 2 dx.
    marker_spacing : float
        Spacing of the slab-base markers along the column (m), > 0.
    slab, weak_layer, settle, saw, front
        The parts (:class:`~mpm_warp.scenes.snow.Slab`, :class:`~mpm_warp.scenes.weak_layer.WeakLayer`,
        :class:`~mpm_warp.scenes.snow.Settle`, :class:`Saw`, :class:`Front`).
    """

    kind: ClassVar[str] = "pst"
    #: the steady part of the self-propagation path: from 30 % to 85 % of the way from the cut to the far end
    SPEED_FIT_FRACTIONS: ClassVar[tuple[float, float]] = (0.3, 0.85)
    dx: float = 0.01
    particles_per_cell: int = 2
    length: float = 4.0
    slab_thickness: float = 0.5
    weak_layer_thickness: float = 0.02
    slope_angle: float = 0.0
    width: float = 0.0
    substratum: WallKind = "sticky"
    substratum_friction: float = 0.5
    margin: float = 0.1
    marker_spacing: float = 0.1
    slab: Slab = field(default_factory=Slab)
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
        finite_number(f"{where}.slope_angle", self.slope_angle, lo=-60.0, hi=60.0)
        finite_number(f"{where}.width", self.width, lo=0.0)
        finite_number(f"{where}.margin", self.margin, lo=2.0 * dx)
        finite_number(f"{where}.substratum_friction", self.substratum_friction, lo=0.0)
        finite_number(f"{where}.marker_spacing", self.marker_spacing, lo=0.0, lo_open=True)
        self.slab.validate(f"{where}.slab")
        self.weak_layer.validate(f"{where}.weak_layer")
        self.settle.validate(f"{where}.settle")
        finite_number(f"{where}.saw.cut_length", self.saw.cut_length, lo=0.0, hi=L)
        finite_number(f"{where}.saw.speed", self.saw.speed, lo=0.0, lo_open=True)
        finite_number(f"{where}.saw.log_jp", self.saw.log_jp)
        finite_number(f"{where}.front.bin", self.front.bin, lo=0.0)
        finite_number(f"{where}.front.threshold", self.front.threshold, lo=0.0, lo_open=True, hi=1.0)
        return self

    def to_dict(self) -> dict:
        """Plain dict of the parameters (the ``[scene]`` table; the loader reads it back)."""
        return asdict(self)

    # ------------------------------------------------------------- derived values
    @property
    def sigma_n(self) -> float:
        """Bed-normal stress of the slab (Pa), ``rho g D cos(theta)``."""
        return slab_normal_stress(self.slab.density, self.slab_thickness, self.slope_angle)

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

    @property
    def width_z(self) -> float:
        """Extent of the column in z (m): one cell in plane strain, else ``width``."""
        return float(self.dx if self.width <= 0.0 else self.width)

    def markers(self) -> np.ndarray:
        """Slab-base marker stations along x (m), every ``marker_spacing`` from half a spacing."""
        return np.asarray([float(m) for m in np.arange(0.5 * self.marker_spacing, self.length, self.marker_spacing)])

    def distance_from_cut_end(self, x):
        """Distance (m) of positions ``x`` (m) from the end the saw starts at (its own inverse: distance to x)."""
        return np.asarray(x, dtype=float) if self.saw.from_end == "left" else self.length - np.asarray(x, dtype=float)

    def speed_fit_window(self) -> tuple[float, float]:
        """Steady part of the self-propagation path (m from the cut end), :data:`SPEED_FIT_FRACTIONS` of the way."""
        return fit_window(float(self.saw.cut_length), float(self.length), *self.SPEED_FIT_FRACTIONS)

    def references(self) -> dict[str, float]:
        """Closed-form references of this PST (``mpm_warp.scenes.pst.references``).

        ``sigma_n``, ``p0_ini``, ``p_oedometric`` (Pa); ``collapse_fraction_law`` (-, hardening law from 0
        to ``sigma_n``) and ``collapse_height_law`` (m); Heierli's ``heierli_speed`` (m/s) and
        ``heierli_touchdown`` (m) with that collapse height; the slab's ``rayleigh_speed`` and
        ``shear_wave_speed`` (m/s).
        """
        sigma_n = self.sigma_n
        wl = self.weak_layer.material(sigma_n)
        law = hardening_collapse(sigma_n, wl.bulk, wl.xi)
        slab = self.slab.material()
        h_c = law * self.weak_layer_thickness
        D = self.slab_thickness
        return {"sigma_n": sigma_n, "p0_ini": wl.p0_ini, "p_oedometric": oedometric_pressure(sigma_n, wl.nu),
                "collapse_fraction_law": law, "collapse_height_law": h_c,
                "heierli_speed": heierli_speed(slab.E, D, slab.density, h_c),
                "heierli_touchdown": heierli_touchdown(slab.E, D, slab.density, h_c),
                "rayleigh_speed": slab.rayleigh_speed, "shear_wave_speed": slab.s_wave_speed}

