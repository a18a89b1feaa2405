"""Building a shear-test scenario from its parameters: the sample, the loading block, the sticky substratum."""

from __future__ import annotations

from ...config import Block, Output, Scenario, TimeControl
from ...materials import Elastic
from ...walls import Wall
from ..snow import GRAVITY, plane_domain, settle_time
from .params import ShearTestParams

__all__ = ["build"]


def build(params: ShearTestParams, time: TimeControl, output: Output | None = None, *, name: str = "shear_test",
          precision: str = "float32", description: str = "") -> Scenario:
    """The scenario of a shear test (parameters as :func:`mpm_warp.scenes.pst.build`; gravity is vertical): the
    weak layer calibrated from its field quantities under the slab (:meth:`ShearTestParams.calibrated`), once,
    stored in :attr:`~mpm_warp.config.Scenario.calibration`."""
    p = params.validate()
    dx, Ls, d_wl, t_load = p.dx, p.sample_length, p.weak_layer_thickness, p.load_thickness
    sigma_n = p.sigma_n
    m = p.margin_cells
    box = plane_domain((-m, 0.0), (Ls + m, d_wl + t_load + m), dx, p.width, m)
    cal = p.calibrated()
    materials = {"load": Elastic(p.slab.E, p.slab.nu, p.load_density), "weak_layer": cal.material}
    ppc = p.particles_per_cell
    normal = 1 if p.interface_closure else -1  # the laminate closure's axis (docs/model.md §5b)
    blocks = (Block("weak_layer", box.corner(0.0, 0.0), box.far_corner(Ls, d_wl), particles_per_cell=ppc,
                    name="weak_layer", interface_normal=normal),
              Block("load", box.corner(0.0, d_wl), box.far_corner(Ls, d_wl + t_load), particles_per_cell=ppc,
                    name="load", interface_normal=normal))
    floor = Wall(box.vector(0.0, 0.0), box.vector(0.0, 1.0), kind="sticky", name="substratum")
    desc = description or (f"Shear test: {Ls * 100:g} cm x {d_wl * 100:g} cm weak layer under {sigma_n:.0f} Pa, "
                           f"wall at {p.wall_speed:g} m/s")
    return Scenario(name=name, domain=box.domain, time=settle_time(time, p.settle, box.vector(0.0, -GRAVITY)),
                    materials=materials, blocks=blocks, walls=(floor,), output=output or Output(),
                    precision=precision, description=desc, scene=p, calibration={"weak_layer": cal.to_dict()})
