"""Parameters of a Propagation Saw Test and the values derived from them (functions of the parameters).

:meth:`PSTParams.validate` checks each value's range here, beside the fields (the key reference is generated
from it); the limits that tie parameters together are in :mod:`.params_checks`. A table of an older release
is read in today's keys by :mod:`.upgrade`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import ClassVar, Literal

import numpy as np

from ...checks import check_choices, finite_number, positive_int
from ...errors import InvalidArgument
from ...walls import WallKind
from ..references import heierli_speed, heierli_touchdown
from ..snow import PlaneStrain, Settle, Slab, check_plane_strain, check_weak_layer_cells, oedometric_pressure
from ..snowpack import SnowLayer, equivalent_slab, stack_normal_stress, stack_thickness
from ..weak_layer import CalibratedWeakLayer, WeakLayer
from .from_profile import ProfileSource
from .params_checks import check_closure_layers, check_crack_band, check_layers, check_rigid_base
from .saw import CutFrom, Front, Saw, SawStop
from .upgrade import upgrade_table

__all__ = ["Saw", "Front", "PSTParams", "ColumnEnds", "CutFrom", "SawStop", "upgrade_table"]

#: the column's end faces: normal to the slope (European practice) or vertical (the North American standard)
ColumnEnds = Literal["slope_normal", "vertical"]
#: the slab's crack band in grid cells: the width a crack breaks at 2 particles per cell (docs/model.md §9)
CRACK_BAND_CELLS = 1.5


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
        Slope (deg), in [-60, 60]: gravity ``g (sin, -cos)`` (downslope is +x for a positive angle).
    column_ends : {"slope_normal", "vertical"}
        The column's end faces: normal to the slope (European practice, the default) or vertical (the North
        American standard; Birkeland et al. 2025). Vertical ends lean upslope with height by ``tan(slope)``;
        the column spans ``[0, length]`` at the weak layer's mid-height either way.
    width : float
        Column width (m); 0 = plane strain (quantities per metre of depth in true 2D).
    plane_strain : {"2d", "slab"}
        How plane strain (``width = 0``) is run: "2d", the true 2D kernels (the default), or "slab", the
        quasi-2D slab (3D, one cell thick in z between slip walls, 2 particle layers at 2 per cell and axis;
        each layer is the 2D run, at about 5x its cost). "slab" needs ``width = 0``.
    bed : {"sticky", "slip", "separate"}
        Wall kind under the substratum ("separate": Coulomb contact with ``bed_friction``).
    rigid_base : bool
        The weak layer rests on the bed itself, a rigid base, as in weac's model and the column FE
        (docs/model.md §6): no substratum, so ``substratum``, ``substratum_thickness`` and ``substratum_layers``
        must keep their defaults, and the bed must be "sticky". False (the default): the elastic old snow of the
        substratum under the weak layer.
    bed_friction : float
        Coulomb coefficient of a "separate" bed (-), >= 0.
    margin : float
        Free space around the column (m), >= 2 dx.
    marker_spacing : float
        Spacing of the slab-base markers along the column (m), > 0.
    slab, substratum, weak_layer, settle, saw, front
        The parts (:class:`~mpm_warp.scenes.snow.Slab` twice: a homogeneous slab of ``slab_thickness`` and
        the old snow of ``substratum_thickness`` under the weak layer; :class:`~mpm_warp.scenes.weak_layer.
        WeakLayer`, :class:`~mpm_warp.scenes.snow.Settle`, :class:`Saw`, :class:`Front`).
    slab_fracture : bool
        The slab can break: each slab layer cracks in tension (:class:`~mpm_warp.materials.CrackingSnow`) at its
        tensile strength and fracture energy (given, or from its density), over a crack band of 1.5 grid cells,
        ``1.5 dx`` (the width a crack breaks, docs/model.md §9). False (the default): an elastic slab, at no extra
        cost.
    interface_closure : bool
        The laminate closure at the stack's interfaces (docs/model.md §5b): a particle whose grid cells mix two
        layers' snow is strained as its layer in a laminate, so that the normal and shear stress are continuous
        across the interfaces instead of the rows beside a stiffness jump carrying half or double the load. False
        (the default): the plain MLS-MPM strain, at no extra cost.
    profile : ProfileSource
        The CAAML snow profile the layers come from (:mod:`.from_profile`; the loader reads it once and fills the
        layers); empty for a snowpack given in the file.
    slab_layers, substratum_layers : tuple of SnowLayer
        A layered slab or substratum, top to bottom (:class:`~mpm_warp.scenes.snowpack.SnowLayer`; an
        omitted E comes from the density). Given, they replace ``slab``/``slab_thickness`` (or
        ``substratum``/``substratum_thickness``), which must then keep their defaults.
    """

    kind: ClassVar[str] = "pst"
    dx: float = 0.0075
    particles_per_cell: int = 2
    length: float = 8.0
    slab_thickness: float = 0.5
    weak_layer_thickness: float = 0.03
    substratum_thickness: float = 0.15
    slope_angle: float = 0.0
    column_ends: ColumnEnds = "slope_normal"
    width: float = 0.0
    plane_strain: PlaneStrain = "2d"
    bed: WallKind = "sticky"
    bed_friction: float = 0.5
    rigid_base: bool = False
    margin: float = 0.05
    marker_spacing: float = 0.1
    slab: Slab = field(default_factory=Slab)
    substratum: Slab = field(default_factory=Slab)
    weak_layer: WeakLayer = field(default_factory=WeakLayer)
    settle: Settle = field(default_factory=Settle)
    saw: Saw = field(default_factory=Saw)
    front: Front = field(default_factory=Front)
    slab_layers: tuple[SnowLayer, ...] = ()
    substratum_layers: tuple[SnowLayer, ...] = ()
    slab_fracture: bool = False
    interface_closure: bool = False
    profile: ProfileSource = field(default_factory=ProfileSource)

    def validate(self, where: str = "scene") -> PSTParams:
        """Check every value (InvalidArgument naming ``where.field``, the value and the range); return self."""
        check_choices(self, where)
        dx = finite_number(f"{where}.dx", self.dx, lo=0.0, lo_open=True)
        positive_int(f"{where}.particles_per_cell", self.particles_per_cell, lo=1, hi=8)
        L = finite_number(f"{where}.length", self.length, lo=0.0, lo_open=True)
        finite_number(f"{where}.slab_thickness", self.slab_thickness, lo=0.0, lo_open=True)
        d_wl = finite_number(f"{where}.weak_layer_thickness", self.weak_layer_thickness, lo=0.0, lo_open=True)
        check_weak_layer_cells(d_wl, dx, where)
        finite_number(f"{where}.substratum_thickness", self.substratum_thickness, lo=0.0, lo_open=True)
        for part in ("slab", "substratum"):
            check_layers(self, part, where)
        check_rigid_base(self, where)
        if not self.rigid_base:
            finite_number(f"{where}.substratum_thickness (of the layers)", self.substratum_depth, lo=2.0 * dx)
        self.profile.validate(f"{where}.profile")
        if not isinstance(self.slab_fracture, bool):
            raise InvalidArgument(f"{where}.slab_fracture", self.slab_fracture, "true or false")
        if self.slab_fracture:
            check_crack_band(self, where)
        if not isinstance(self.interface_closure, bool):
            raise InvalidArgument(f"{where}.interface_closure", self.interface_closure, "true or false")
        if self.interface_closure:
            check_closure_layers(self, where)
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
        finite_number(f"{where}.saw.pre_cut", self.saw.pre_cut, lo=0.0, hi=self.saw.cut_length)
        finite_number(f"{where}.front.bin", self.front.bin, lo=0.0)
        finite_number(f"{where}.front.deflection", self.front.deflection, lo=0.0, lo_open=True, hi=1.0)
        finite_number(f"{where}.front.runaway_lead", self.front.runaway_lead, lo=0.0, lo_open=True)
        zone = max(self.slab_depth, 2.0 * self.bin_width)   # analysis.end_zone: the free end unloads the layer
        if self.saw.cut_length > 0 and not L > zone:         # (uncut, the scene is a column: interface_column)
            raise InvalidArgument(f"{where}.length", self.length, f"a number in ({zone:g}, inf) with a saw cut: longer "
                                  "than the far end zone, one slab depth, where a front counts as at the far end")
        return self

    @property
    def crack_band(self) -> float:
        """Width of the band a slab crack localises in (m): 1.5 grid cells, ``1.5 dx``. Measured: a crack breaks
        three particle columns at 2 particles per cell, whatever the band and the cell size, and notched bars
        then spend G_f over the ligament within 7-12 % (docs/model.md §9)."""
        return CRACK_BAND_CELLS * self.dx

    def slab_materials(self) -> list:
        """The slab layers' materials, top to bottom: elastic, or cracking with ``slab_fracture``."""
        return [layer.cracking(self.crack_band) if self.slab_fracture else layer.slab().material()
                for layer in self.slab_stack()]

    def to_dict(self) -> dict:
        """Plain dict of the parameters (the ``[scene]`` table; the loader reads it back; ``interface_closure``
        and ``rigid_base`` only when on and ``saw.stop`` only when "runaway", so the files of scenes without them
        are unchanged; the layer lists only when given: :func:`upgrade_table` refuses empty ones)."""
        d = asdict(self)
        for key in ("slab_layers", "substratum_layers"):
            if not d[key]:
                del d[key]
        if not self.interface_closure:
            del d["interface_closure"]
        if not self.rigid_base:
            del d["rigid_base"]
        if self.saw.stop == "cut_length":
            del d["saw"]["stop"]
        if self.saw.pre_cut == 0.0:
            del d["saw"]["pre_cut"]
        return d

    # ------------------------------------------------------------- the snowpack
    def slab_stack(self) -> tuple[SnowLayer, ...]:
        """The slab's layers, top to bottom (one layer of ``slab`` and ``slab_thickness`` unless layered)."""
        s = self.slab
        return self.slab_layers or (SnowLayer(self.slab_thickness, s.density, s.E, s.nu, s.tensile_strength,
                                              s.fracture_energy),)

    def substratum_stack(self) -> tuple[SnowLayer, ...]:
        """The substratum's layers, top to bottom (none on a rigid base)."""
        if self.rigid_base:
            return ()
        s = self.substratum
        return self.substratum_layers or (SnowLayer(self.substratum_thickness, s.density, s.E, s.nu),)

    @property
    def layered(self) -> bool:
        """Whether the slab has more than one layer."""
        return len(self.slab_stack()) > 1

    @property
    def slab_depth(self) -> float:
        """Slab thickness D (m): the weak layer's depth below the surface, bed-normal."""
        return self.slab_thickness if not self.slab_layers else stack_thickness(self.slab_layers)

    @property
    def substratum_depth(self) -> float:
        """Thickness of the substratum (m; 0 on a rigid base)."""
        if self.rigid_base:
            return 0.0
        return self.substratum_thickness if not self.substratum_layers else stack_thickness(self.substratum_layers)

    def equivalent_slab(self) -> Slab:
        """The homogeneous slab of the same thickness, weight and bending stiffness (the slab itself unless
        layered; :func:`~mpm_warp.scenes.snowpack.equivalent_slab`): the closed-form references use it."""
        return self.slab if not self.slab_layers else equivalent_slab(self.slab_layers)

    @property
    def cut_at_origin(self) -> bool:
        """Whether the saw starts at the end ``x = 0`` (the upslope end for a slope angle >= 0)."""
        return (self.saw.cut_from == "upslope") == (self.slope_angle >= 0.0)

    def end_shift(self, y: float) -> float:
        """Shift along x (m) of the column's end faces at bed-normal height ``y`` (m) against the weak layer's
        mid-height: 0 with slope-normal ends, ``-(y - y_wl) tan(slope)`` with vertical ones (they lean upslope)."""
        if self.column_ends == "slope_normal":
            return 0.0
        y_wl = self.substratum_depth + 0.5 * self.weak_layer_thickness
        return -(float(y) - y_wl) * math.tan(math.radians(self.slope_angle))

    # ------------------------------------------------------------- derived values
    @property
    def sigma_n(self) -> float:
        """Bed-normal stress of the slab on the weak layer (Pa), ``sum rho_i g h_i cos(theta)``."""
        return stack_normal_stress(self.slab_stack(), self.slope_angle)

    def calibrated(self) -> CalibratedWeakLayer:
        """The weak layer calibrated under this slab's load (:meth:`~mpm_warp.scenes.weak_layer.WeakLayer.
        calibrate`; a layered slab enters through its mean density and thickness, the same normal stress, and
        its bending-equivalent E and nu for the predictions)."""
        eq = self.equivalent_slab()
        return self.weak_layer.calibrate(self.weak_layer_thickness, eq.density, self.slab_depth,
                                         abs(self.slope_angle), eq.E, eq.nu)

    @property
    def base_y(self) -> float:
        """Bed-normal position of the slab's base (m): substratum and weak layer below it."""
        return self.substratum_depth + self.weak_layer_thickness

    @property
    def saw_start(self) -> float:
        """Time the saw starts (s): the end of settling."""
        return float(self.settle.duration)

    @property
    def saw_end(self) -> float:
        """Time the saw reaches ``saw.cut_length`` (s): where it stops unless it stopped on runaway before
        (:func:`.saw.sawn` gives the parameters of the cut made)."""
        return self.saw_start + max(self.saw.cut_length - self.saw.pre_cut, 0.0) / self.saw.speed

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
        return np.asarray(x, dtype=float) if self.cut_at_origin else self.length - np.asarray(x, dtype=float)

    def references(self, wl: CalibratedWeakLayer) -> dict[str, float]:
        """Closed-form references of this PST (:mod:`mpm_warp.scenes.references`) with the calibrated layer ``wl``
        (:meth:`calibrated`, or a scenario's stored calibration); a layered slab enters as its bending-equivalent
        homogeneous slab (:meth:`equivalent_slab`).

        ``sigma_n``, ``p_oedometric`` (Pa); the layer's ``tau_p`` (Pa), ``w_f`` (J/m^2), ``delta_s``
        (m), ``collapse_height_calibrated`` (m, the debonded layer under this slab at rest); Heierli's
        ``heierli_speed`` (m/s) and ``heierli_touchdown`` (m) with that collapse height; Gaume et al.
        (2017) ``critical_cut_gaume`` (m, flat ground); the slab's ``rayleigh_speed`` and
        ``shear_wave_speed`` (m/s).
        """
        slab = self.equivalent_slab().material()
        D = self.slab_depth
        return {"sigma_n": self.sigma_n, "p_oedometric": oedometric_pressure(self.sigma_n, wl.material.nu),
                "tau_p": wl.tau_p, "w_f": wl.w_f, "delta_s": wl.delta_s, "collapse_height_calibrated": wl.h_c,
                "heierli_speed": heierli_speed(slab.E, D, slab.density, wl.h_c),
                "heierli_touchdown": heierli_touchdown(slab.E, D, slab.density, wl.h_c),
                "critical_cut_gaume": float(wl.critical_cut) if wl.critical_cut is not None else math.nan,
                "rayleigh_speed": slab.rayleigh_speed, "shear_wave_speed": slab.s_wave_speed}
