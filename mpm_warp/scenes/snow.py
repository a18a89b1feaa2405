"""Shared pieces of the snow scenes: slab, settling, the slab's load, the plane-strain box.

Both snow scenes put a weak layer (:mod:`mpm_warp.scenes.weak_layer`) on a substratum under a load,
settle it under ramped gravity and grid damping, then run the experiment. ``x`` runs along the
column, ``y`` is normal to the bed, ``z`` across; a slope of angle ``theta`` is a rotated gravity
``g (sin theta, -cos theta)`` (downslope is ``+x``). Scenes are plane strain in true 2D by default
(``width = 0``: masses, forces and energies per metre of depth); ``width > 0`` builds a free 3D column.
``plane_strain = "slab"`` runs the same plane-strain problem as the quasi-2D slab instead: a 3D box one
cell thick in z between slip faces (the check of the true 2D kernels, and their cost against it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Literal, get_args

from ..checks import choice, finite_number
from ..config import Domain, TimeControl
from ..errors import InvalidArgument
from ..materials import Elastic

__all__ = ["GRAVITY", "Slab", "Settle", "SETTLE_TIME_KEYS", "MIN_WEAK_LAYER_CELLS", "slab_normal_stress",
           "oedometric_pressure", "slope_gravity", "settle_time", "PlaneBox", "PlaneStrain", "plane_domain",
           "check_plane_strain", "check_weak_layer_cells"]

GRAVITY = 9.81
"""Gravitational acceleration (m/s^2)."""

#: the weak layer must span at least this many grid cells: a particle's quadratic B-spline stencil reaches
#: 1.5 cells away, so across 2 cells the slab's base and the substratum's top (or the bed's wall nodes)
#: share grid nodes, and the slab rests partly on them through the grid instead of on the layer
MIN_WEAK_LAYER_CELLS = 3.0
#: ``[time]`` keys a snow scene sets itself (from its slope and :class:`Settle`)
SETTLE_TIME_KEYS = ("gravity", "gravity_ramp", "damping", "damping_until")


@dataclass(frozen=True)
class Slab:
    """The elastic slab.

    Attributes
    ----------
    E : float
        Young's modulus (Pa), > 0.
    nu : float
        Poisson's ratio (-), in [0, 0.5).
    density : float
        Density (kg/m^3), > 0.
    tensile_strength, fracture_energy : float
        Of a slab that can break (Pa, J/m^2), >= 0; 0 = from the density (``scene.slab_fracture``; see
        :class:`~mpm_warp.scenes.snowpack.SnowLayer`). Unused for the substratum.
    """

    E: float = 5.0e6
    nu: float = 0.3
    density: float = 250.0
    tensile_strength: float = 0.0
    fracture_energy: float = 0.0

    def material(self) -> Elastic:
        """The slab's elastic material (checked, naming ``where`` in errors)."""
        return Elastic(self.E, self.nu, self.density)

    def validate(self, where: str = "slab") -> Slab:
        """Check every value; return self."""
        self.material().validate(where)
        finite_number(f"{where}.tensile_strength", self.tensile_strength, lo=0.0)
        finite_number(f"{where}.fracture_energy", self.fracture_energy, lo=0.0)
        return self


@dataclass(frozen=True)
class Settle:
    """Settling before the experiment: gravity ramps up while the grid is damped.

    Attributes
    ----------
    gravity_ramp : float
        Gravity grows linearly from 0 over this time (s), >= 0.
    damping : float
        Grid velocity damping rate while settling (1/s), >= 0.
    duration : float
        End of settling (s), >= ``gravity_ramp``: the experiment (saw, push) starts then.
    """

    gravity_ramp: float = 0.05
    damping: float = 100.0
    duration: float = 0.1

    def validate(self, where: str = "settle") -> Settle:
        """Check every value; return self."""
        ramp = finite_number(f"{where}.gravity_ramp", self.gravity_ramp, lo=0.0)
        finite_number(f"{where}.damping", self.damping, lo=0.0)
        dur = finite_number(f"{where}.duration", self.duration, lo=0.0)
        if dur < ramp:
            raise InvalidArgument(f"{where}.duration", self.duration, f"a time >= {where}.gravity_ramp = {ramp:g} s")
        return self


def slab_normal_stress(density: float, thickness: float, slope_deg: float = 0.0) -> float:
    """Bed-normal stress of the slab's weight, ``rho g D cos(theta)`` (Pa)."""
    return density * GRAVITY * thickness * math.cos(math.radians(slope_deg))


def oedometric_pressure(sigma_n: float, nu: float) -> float:
    """Mean pressure (Pa) under a bed-normal stress ``sigma_n`` with no lateral strain.

    Lateral stresses ``nu/(1-nu) sigma_n``: ``p = sigma_n (1 + nu) / (3 (1 - nu))``.
    """
    return sigma_n * (1.0 + nu) / (3.0 * (1.0 - nu))


def slope_gravity(slope_deg: float, dim: int = 3) -> tuple[float, ...]:
    """Gravity (m/s^2) on a slope of ``slope_deg``: ``g (sin theta, -cos theta[, 0])``, downslope ``+x``."""
    th = math.radians(slope_deg)
    return (GRAVITY * math.sin(th), -GRAVITY * math.cos(th), 0.0)[:dim]


def settle_time(time: TimeControl, settle: Settle, gravity) -> TimeControl:
    """``time`` with the scene's gravity and the settling ramp and damping (:data:`SETTLE_TIME_KEYS`)."""
    return replace(time, gravity=tuple(gravity), gravity_ramp=float(settle.gravity_ramp),
                   damping=float(settle.damping), damping_until=float(settle.duration))


#: how a plane-strain scene (``width = 0``) is run: "2d", the true 2D kernels (x-y, per metre of depth), or
#: "slab", the quasi-2D slab (3D, z in ``[0, dx]`` between slip walls: v_z = 0 on every node, each z layer of
#: particles the 2D scene; 2x the particles and 3x the stencil, per ``dx`` of depth)
PlaneStrain = Literal["2d", "slab"]


@dataclass(frozen=True)
class PlaneBox:
    """The box of a snow scene: true 2D plane strain (``width = 0``), the quasi-2D slab or a free 3D column.

    Attributes
    ----------
    domain : Domain
    dim : int
        2 (plane strain in x-y) or 3.
    depth : float
        Extent of the particles in z (m; 1 m of depth in 2D, where masses and forces are per metre; ``dx`` in
        the slab, the column's width in 3D).
    """

    domain: Domain
    dim: int
    depth: float

    def corner(self, x: float, y: float) -> tuple[float, ...]:
        """A block corner at ``(x, y)`` (m): ``(x, y)`` in 2D, ``(x, y, 0)`` in 3D (the column starts at z = 0)."""
        return (x, y) if self.dim == 2 else (x, y, 0.0)

    def far_corner(self, x: float, y: float) -> tuple[float, ...]:
        """The opposite block corner: ``(x, y)`` in 2D, ``(x, y, width)`` in 3D."""
        return (x, y) if self.dim == 2 else (x, y, self.depth)

    def vector(self, x: float, y: float) -> tuple[float, ...]:
        """A point or direction in the scene's dimension (z = 0 in 3D)."""
        return (x, y) if self.dim == 2 else (x, y, 0.0)


def plane_domain(lo_xy, hi_xy, dx: float, width: float, margin: float, plane_strain: PlaneStrain = "2d") -> PlaneBox:
    """The box: plane strain (``width = 0``) in true 2D or as the quasi-2D slab (``plane_strain = "slab"``: z in
    ``[0, dx]`` between slip walls, the x-y faces free), or a free 3D column of ``width`` (m) with ``margin`` (m)
    of free space on each side in z."""
    if width <= 0.0 and plane_strain == "slab":
        return PlaneBox(Domain((lo_xy[0], lo_xy[1], 0.0), (hi_xy[0], hi_xy[1], dx), dx, boundary="slip",
                               boundary_faces="z"), 3, float(dx))
    if width <= 0.0:
        return PlaneBox(Domain(tuple(lo_xy), tuple(hi_xy), dx, boundary="none", dimension=2), 2, 1.0)
    return PlaneBox(Domain((lo_xy[0], lo_xy[1], -margin), (hi_xy[0], hi_xy[1], width + margin), dx,
                           boundary="none"), 3, float(width))


def check_plane_strain(plane_strain: str, width: float, where: str) -> None:
    """Raise unless ``plane_strain`` is one of :data:`PlaneStrain` and, as the slab, comes with ``width = 0``."""
    choice(f"{where}.plane_strain", plane_strain, get_args(PlaneStrain))
    if plane_strain == "slab" and width > 0.0:
        raise InvalidArgument(f"{where}.plane_strain", plane_strain,
                              f"'2d' when {where}.width = {width:g} m > 0 (a 3D column; the slab is plane strain, "
                              "width = 0)")


def check_weak_layer_cells(d_wl: float, dx: float, where: str) -> None:
    """Raise if the weak layer spans fewer than :data:`MIN_WEAK_LAYER_CELLS` grid cells."""
    if d_wl < MIN_WEAK_LAYER_CELLS * dx * (1.0 - 1e-9):
        raise InvalidArgument(
            f"{where}.weak_layer_thickness", d_wl,
            f"at least {MIN_WEAK_LAYER_CELLS:g} cells of {where}.dx = {dx:g} m (it spans {d_wl / dx:.2g} cells; "
            "thinner, the slab's stencil reaches the substratum wall through the grid): lower dx or thicken the layer")
