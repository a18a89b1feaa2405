"""Building a PST scenario from its parameters: domain, materials, blocks, the substratum wall, settling."""

from __future__ import annotations

from ...config import Block, Output, Scenario, TimeControl
from ...walls import Wall
from ..snow import plane_domain, settle_time, slope_gravity
from .params import PSTParams

__all__ = ["build"]


def build(params: PSTParams, time: TimeControl, output: Output | None = None, *, name: str = "pst",
          precision: str = "float32", description: str = "") -> Scenario:
    """The scenario of a PST: a weak layer (``y`` in ``[0, D_wl]``) on the substratum under the slab.

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
    dx, L, D, d_wl = p.dx, p.length, p.slab_thickness, p.weak_layer_thickness
    sigma_n = p.sigma_n
    materials = {"slab": p.slab.material(), "weak_layer": p.weak_layer.material(sigma_n)}
    domain, wz = plane_domain((-p.margin, 0.0), (L + p.margin, d_wl + D + p.margin), dx, p.width, p.margin)
    ppc = p.particles_per_cell
    blocks = (Block("weak_layer", (0.0, 0.0, 0.0), (L, d_wl, wz), particles_per_cell=ppc, name="weak_layer"),
              Block("slab", (0.0, d_wl, 0.0), (L, d_wl + D, wz), particles_per_cell=ppc, name="slab"))
    friction = float(p.substratum_friction) if p.substratum == "separate" else 0.0
    floor = Wall((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), kind=p.substratum, friction=friction, name="substratum")
    desc = description or (f"PST: L = {L:g} m, slab {D:g} m on a {d_wl * 100:g} cm weak layer, slope "
                           f"{p.slope_angle:g} deg, cut {p.saw.cut_length:g} m at {p.saw.speed:g} m/s")
    return Scenario(name=name, domain=domain, time=settle_time(time, p.settle, slope_gravity(p.slope_angle)),
                    materials=materials, blocks=blocks, walls=(floor,), output=output or Output(),
                    precision=precision, description=desc, scene=p)
