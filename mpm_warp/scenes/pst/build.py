"""Building a PST scenario from its parameters: substratum, weak layer and slab on the bed wall, settling."""

from __future__ import annotations

from ...config import Block, Output, Scenario, TimeControl
from ...walls import Wall
from ..snow import plane_domain, settle_time, slope_gravity
from .params import PSTParams

__all__ = ["build"]


def build(params: PSTParams, time: TimeControl, output: Output | None = None, *, name: str = "pst",
          precision: str = "float32", description: str = "") -> Scenario:
    """The scenario of a PST: old snow (``y`` in ``[0, D_sub]``) on the bed wall, the weak layer, the slab.

    The weak layer is the bonded Cam-Clay calibrated from its field quantities under this slab
    (:meth:`PSTParams.calibrated`); the elastic substratum keeps it off the bed's grid nodes.

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
    dx, L, D, d_wl, d_sub = p.dx, p.length, p.slab_thickness, p.weak_layer_thickness, p.substratum_thickness
    materials = {"slab": p.slab.material(), "weak_layer": p.calibrated().material,
                 "substratum": p.substratum.material()}
    box = plane_domain((-p.margin, 0.0), (L + p.margin, p.base_y + D + p.margin), dx, p.width, p.margin,
                       p.plane_strain)
    ppc = p.particles_per_cell
    blocks = (Block("substratum", box.corner(0.0, 0.0), box.far_corner(L, d_sub), particles_per_cell=ppc,
                    name="substratum"),
              Block("weak_layer", box.corner(0.0, d_sub), box.far_corner(L, d_sub + d_wl), particles_per_cell=ppc,
                    name="weak_layer"),
              Block("slab", box.corner(0.0, p.base_y), box.far_corner(L, p.base_y + D), particles_per_cell=ppc,
                    name="slab"))
    friction = float(p.bed_friction) if p.bed == "separate" else 0.0
    bed = Wall(box.vector(0.0, 0.0), box.vector(0.0, 1.0), kind=p.bed, friction=friction, name="bed")
    desc = description or (f"PST: L = {L:g} m, slab {D:g} m on a {d_wl * 100:g} cm weak layer, slope "
                           f"{p.slope_angle:g} deg, cut {p.saw.cut_length:g} m at {p.saw.speed:g} m/s"
                           + (", plane strain" if box.dim == 2 else ", plane strain (quasi-2D slab)"
                              if p.width <= 0.0 else f", {p.width:g} m wide"))
    return Scenario(name=name, domain=box.domain,
                    time=settle_time(time, p.settle, slope_gravity(p.slope_angle, box.dim)),
                    materials=materials, blocks=blocks, walls=(bed,), output=output or Output(),
                    precision=precision, description=desc, scene=p)
