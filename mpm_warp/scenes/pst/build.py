"""Building a PST scenario from its parameters: substratum, weak layer and slab layers on the bed wall."""

from __future__ import annotations

import math

from ...config import Block, Output, Scenario, TimeControl
from ...walls import Wall
from ..snow import plane_domain, settle_time, slope_gravity
from .params import PSTParams

__all__ = ["build", "layer_names"]


def layer_names(part: str, n: int) -> list[str]:
    """Names of the particle groups (and materials) of a stack of ``n`` layers: ``part`` for one layer,
    ``part_1`` (top) to ``part_n`` (bottom) for several."""
    return [part] if n == 1 else [f"{part}_{k + 1}" for k in range(n)]


def build(params: PSTParams, time: TimeControl, output: Output | None = None, *, name: str = "pst",
          precision: str = "float32", description: str = "") -> Scenario:
    """The scenario of a PST: old snow (``y`` in ``[0, D_sub]``) on the bed wall, the weak layer, the slab.

    The weak layer is the bonded Cam-Clay calibrated from its field quantities under this slab's load
    (:meth:`PSTParams.calibrated`), once: its parameters and predictions travel with the scenario
    (:attr:`~mpm_warp.config.Scenario.calibration`). Each slab and substratum layer is a block of its own
    material; with vertical column ends every block is cut by the two end planes.

    Parameters
    ----------
    params : PSTParams
        The scene (checked here).
    time : TimeControl
        End, frame interval and step control; gravity (from ``slope_angle``) and the settling ramp and
        damping (``params.settle``) are set here.
    output : Output, optional
    name, precision, description : str
        As :class:`~mpm_warp.config.Scenario`; an empty description is generated from the parameters.
    """
    p = params.validate()
    dx, L, d_wl = p.dx, p.length, p.weak_layer_thickness
    cal = p.calibrated()
    slab, sub = p.slab_stack(), p.substratum_stack()
    top = p.base_y + p.slab_depth
    # x-shift of the end faces at the bed and at the top (0 with slope-normal ends)
    s_lo, s_hi = min(0.0, p.end_shift(0.0), p.end_shift(top)), max(0.0, p.end_shift(0.0), p.end_shift(top))
    box = plane_domain((s_lo - p.margin, 0.0), (L + s_hi + p.margin, top + p.margin), dx, p.width, p.margin,
                       p.plane_strain)
    halfspaces = _end_planes(p, box.dim)
    ppc = p.particles_per_cell
    normal = 1 if p.interface_closure else -1  # the stack's axis: bed-normal
    materials, blocks = {}, []

    def add(group: str, material, y0: float, y1: float):
        materials[group] = material
        blocks.append(Block(group, box.corner(s_lo, y0), box.far_corner(L + s_hi, y1), particles_per_cell=ppc,
                            name=group, halfspaces=halfspaces, interface_normal=normal))

    y = 0.0
    for group, layer in reversed(list(zip(layer_names("substratum", len(sub)), sub, strict=True))):
        add(group, layer.slab().material(), y, y + layer.thickness)
        y += layer.thickness
    add("weak_layer", cal.material, y, y + d_wl)
    y += d_wl
    for group, layer, material in reversed(list(zip(layer_names("slab", len(slab)), slab, p.slab_materials(),
                                                    strict=True))):
        add(group, material, y, y + layer.thickness)
        y += layer.thickness
    # blocks in the order of old: substratum, weak layer, slab (bottom to top)
    friction = float(p.bed_friction) if p.bed == "separate" else 0.0
    bed = Wall(box.vector(0.0, 0.0), box.vector(0.0, 1.0), kind=p.bed, friction=friction, name="bed")
    return Scenario(name=name, domain=box.domain,
                    time=settle_time(time, p.settle, slope_gravity(p.slope_angle, box.dim)),
                    materials=materials, blocks=tuple(blocks), walls=(bed,), output=output or Output(),
                    precision=precision, description=description or _describe(p, box.dim),
                    scene=p, calibration={"weak_layer": cal.to_dict()})


def _end_planes(p: PSTParams, dim: int) -> tuple:
    """The two end faces of a column with vertical ends as half-spaces ``n . x <= c``; none when slope-normal."""
    if p.column_ends == "slope_normal" or p.slope_angle == 0.0:
        return ()
    t = math.tan(math.radians(p.slope_angle))
    y_wl = p.substratum_depth + 0.5 * p.weak_layer_thickness
    z = (0.0,) * (dim - 2)
    # x - end_shift(y) within [0, L]: x + t (y - y_wl) >= 0 and <= L
    return ((-1.0, -t, *z, -t * y_wl), (1.0, t, *z, p.length + t * y_wl))


def _describe(p: PSTParams, dim: int) -> str:
    slab = p.slab_stack()
    layers = f"{len(slab)}-layer slab {p.slab_depth:g} m" if len(slab) > 1 else f"slab {p.slab_depth:g} m"
    return (f"PST: L = {p.length:g} m, {layers} on a {p.weak_layer_thickness * 100:g} cm weak layer, slope "
            f"{p.slope_angle:g} deg, {p.column_ends.replace('_', '-')} ends, cut {p.saw.cut_length:g} m from the "
            f"{p.saw.cut_from} end at {p.saw.speed:g} m/s"
            + (", plane strain" if dim == 2 else ", plane strain (quasi-2D slab)" if p.width <= 0.0
               else f", {p.width:g} m wide"))
