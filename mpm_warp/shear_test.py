"""Unconfined shear test of the weak layer under the slab's normal load (SI Note 2).

A weak-layer sample (length ``L_s``, thickness ``D_wl``) bonded to a sticky
substratum at ``y = 0`` carries a loading block that applies the slab's
bed-normal stress ``sigma_n = rho_slab g D cos(theta)``: a thin elastic block of
thickness ``t`` and density ``sigma_n / (g t)`` (the same load as the full slab,
with a shorter time step and far fewer particles than a 0.5 m slab). The block
is the test's moving top: a device action (:func:`push_kernel`) holds its
particles' ``x`` velocity at 0 while settling and at ``wall_speed`` (0.01 m/s in
SI Note 2) from the end of settling on (displacement control, as the SI's wall
pushing the slab); its vertical motion is free, so the layer can collapse. The
impulse the action gives is summed: the push force. (An engine wall pushing
the block's face would act on the grid nodes behind its plane only, so its grip
would jump from node to node as it travels.)

Frame scalars (:class:`ShearMonitor`): ``shear_displacement`` and
``normal_displacement`` (m, mean displacement of the loading block since
t = 0), ``shear_strain`` (``u_x / D_wl``) and ``axial_strain`` (``-u_y / D_wl``,
compaction positive; both since t = 0, settling adds ~0.1 %),
``shear_stress`` (Pa, the push's mean force over the last frame divided by the
sample's area ``L_s`` x model thickness: the wall reaction of SI Note 2; it
equals the substratum's shear reaction, by momentum balance),
``layer_shear_stress`` (Pa, mean ``sigma_xy`` of the weak-layer particles,
Cauchy: lower, since the free ends carry none and part of the push reaches the
layer's top through the shared grid nodes), ``mises_q``/``p_mean`` (Pa, mean Mises stress and pressure of the weak
layer, Kirchhoff), ``collapse`` (-, mean ``1 - J_P/J_P,ref`` of the layer) and
``failed_fraction`` (-).
:func:`shear_curves` takes displacements from the start of the push instead.
"""

import copy
import math

import numpy as np
import warp as wp

from . import fronts
from .errors import ScenarioError
from .kernels.snow import push_kernel
from .materials import CamClaySnow
from .pst import (
    GRAVITY,
    SETTLE_DEFAULTS,
    WEAK_LAYER_DEFAULTS,
    WeakLayer,
    _num,
    check_generated,
    check_weak_layer_cells,
    merge_table,
    plane_domain,
    settle_time_keys,
    slab_normal_stress,
    weak_layer_material,
)

__all__ = ["build_shear_test", "ShearMonitor", "attach", "run_shear_test", "shear_curves",
           "analyze_shear_series", "SHEAR_DEFAULTS"]

#: defaults of every ``[scene]`` key of a shear test (units in ``scenarios/shear_test.toml``)
SHEAR_DEFAULTS = {
    "kind": "shear_test",
    "dx": 0.005,                  # m
    "particles_per_cell": 2,
    "sample_length": 0.2,         # m, L_s
    "weak_layer_thickness": 0.02,  # m, D_wl
    "load_thickness": 0.05,       # m, loading block thickness t
    "width": 0.0,                 # m, 0 = plane strain
    "wall_speed": 0.01,           # m/s
    "margin": 0.03,               # m
    "slope_angle": 0.0,           # deg, of the PST whose slab load is reproduced
    "slab": {"E": 5.0e6, "nu": 0.3, "density": 250.0, "thickness": 0.5},
    "weak_layer": WEAK_LAYER_DEFAULTS,
    "settle": SETTLE_DEFAULTS,
}


def build_shear_test(raw: dict) -> dict:
    """Expand ``[scene] kind = "shear_test"`` into domain, materials, blocks, walls and time settings."""
    raw = copy.deepcopy(raw)
    check_generated(raw, "shear_test")
    s = merge_table({k: v for k, v in raw["scene"].items() if k != "derived"}, SHEAR_DEFAULTS, "scene")
    dx = _num("scene.dx", s["dx"], lo=0.0, lo_open=True)
    Ls = _num("scene.sample_length", s["sample_length"], lo=0.0, lo_open=True)
    Dwl = _num("scene.weak_layer_thickness", s["weak_layer_thickness"], lo=0.0, lo_open=True)
    check_weak_layer_cells(Dwl, dx, "scene")
    t_load = _num("scene.load_thickness", s["load_thickness"], lo=2.0 * dx)
    v = _num("scene.wall_speed", s["wall_speed"], lo=0.0, lo_open=True)
    width = _num("scene.width", s["width"], lo=0.0)
    margin = _num("scene.margin", s["margin"], lo=2.0 * dx)
    theta = _num("scene.slope_angle", s["slope_angle"], lo=-60.0, hi=60.0)
    slab = s["slab"]
    sigma_n = slab_normal_stress(_num("scene.slab.density", slab["density"], lo=0.0, lo_open=True),
                                 _num("scene.slab.thickness", slab["thickness"], lo=0.0, lo_open=True), theta)
    t_settle = float(s["settle"]["duration"])
    m_cells = math.ceil(margin / dx) * dx
    wz_domain, wz = plane_domain((-m_cells, 0.0), (Ls + m_cells, Dwl + t_load + m_cells), dx, width, m_cells)
    ppc = s["particles_per_cell"]
    load_density = sigma_n / (GRAVITY * t_load)
    mats = {"load": {"model": "elastic", "E": slab["E"], "nu": slab["nu"], "density": load_density},
            "weak_layer": weak_layer_material(s["weak_layer"], sigma_n, "scene.weak_layer")}
    blocks = [
        {"name": "weak_layer", "material": "weak_layer", "lo": [0.0, 0.0, 0.0], "hi": [Ls, Dwl, wz],
         "particles_per_cell": ppc},
        {"name": "load", "material": "load", "lo": [0.0, Dwl, 0.0], "hi": [Ls, Dwl + t_load, wz],
         "particles_per_cell": ppc},
    ]
    walls = [{"name": "substratum", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0], "kind": "sticky"}]
    wlp = s["weak_layer"]
    wl_cc = CamClaySnow(float(wlp["E"]), float(wlp["nu"]), float(wlp["density"]), xi=float(wlp["xi"]))
    s["derived"] = {"sigma_n": sigma_n, "load_density": load_density, "push_start": t_settle,
                    "sample_area": Ls * wz, "width_z": wz, "p0_ini": mats["weak_layer"]["p0_ini"],
                    "collapse_fraction_law": wl_cc.collapse_at(sigma_n)}
    raw["scene"] = s
    raw["domain"] = wz_domain
    raw["materials"] = mats
    raw["blocks"] = blocks
    raw["walls"] = walls
    raw["time"] = settle_time_keys(raw, s["settle"], (0.0, -GRAVITY, 0.0), "scene")
    raw.setdefault("description", f"Shear test: {Ls * 100:g} cm x {Dwl * 100:g} cm weak layer under "
                                  f"{sigma_n:.0f} Pa, wall at {v:g} m/s")
    return raw


def _cauchy_shear(F: np.ndarray, mu: float, lam: float) -> np.ndarray:
    """Cauchy shear stress ``sigma_xy`` (Pa) of Hencky elasticity for deformation gradients (n, 3, 3)."""
    U, s, _ = np.linalg.svd(F)
    eps = np.log(np.maximum(s, 1e-6))
    tau_p = 2.0 * mu * eps + lam * eps.sum(axis=1, keepdims=True)
    tau = np.einsum("nij,nj,nkj->nik", U, tau_p, U)
    return tau[:, 0, 1] / np.prod(np.maximum(s, 1e-6), axis=1)


class ShearMonitor:
    """Frame diagnostics of a shear test (see the module docstring); created by :func:`attach`."""

    UNITS = {"shear_displacement": "m", "normal_displacement": "m", "shear_strain": "1", "axial_strain": "1",
             "layer_shear_stress": "Pa",
             "shear_stress": "Pa", "mises_q": "Pa", "p_mean": "Pa", "collapse": "1", "failed_fraction": "1"}

    def units(self) -> dict[str, str]:
        """Units of the frame series this monitor records."""
        return dict(self.UNITS)

    def __init__(self, sim):
        scene = sim.scenario.scene
        if scene.get("kind") != "shear_test" or "derived" not in scene:
            raise ScenarioError("ShearMonitor needs a scenario built by scene.kind = 'shear_test'")
        self.sim = sim
        self.scene = scene
        wlp = scene["weak_layer"]
        self.weak = WeakLayer(sim, "weak_layer", float(scene["derived"]["push_start"]), wlp["failure"] == "brittle",
                              float(wlp["failure_log_jp"]))
        self.wl = self.weak.group
        self.load = next(g for g in sim.model.groups if g.name == "load")
        pl = self.load
        T = sim.model.T
        self.impulse = wp.zeros(1, dtype=wp.float64, device=sim.device)
        self.push = wp.launch(push_kernel(T), pl.count,
                              inputs=[sim.state.v[pl.start:pl.end], sim.state.C[pl.start:pl.end], sim.state.clock,
                                      float(scene["derived"]["push_start"]), T(scene["wall_speed"]), T(pl.mass),
                                      self.impulse],
                              device=sim.device, record_cmd=True)
        sim.stepper.actions.append(self.push)
        self._last = (0.0, 0.0)  # (time, impulse) at the previous frame
        self.times: list[float] = []
        self.series: dict[str, list[float]] = {}

    def frame_scalars(self, sim) -> dict[str, float]:
        """Frame diagnostics, also appended to :attr:`series` once per time."""
        t = sim.time
        if self.times and self.times[-1] == t:
            return {k: v[-1] for k, v in self.series.items()}
        x = sim.state.x.numpy().astype(np.float64)
        lo = self.load
        u = (x[lo.start:lo.end] - sim.x0[lo.start:lo.end]).mean(axis=0)
        wl = self.wl
        m = wl.material
        p, q = sim.stress_invariants()
        F = sim.state.F.numpy()[wl.start:wl.end].astype(np.float64)
        c, flag = self.weak.collapse()
        d_wl = float(self.scene["weak_layer_thickness"])
        imp = float(self.impulse.numpy()[0])
        t_last, imp_last = self._last
        self._last = (t, imp)
        area = float(self.scene["derived"]["sample_area"])
        push = (imp - imp_last) / (t - t_last) / area if t > t_last else 0.0
        out = {"shear_displacement": float(u[0]), "normal_displacement": float(u[1]), "shear_stress": push,
               "shear_strain": float(u[0]) / d_wl, "axial_strain": -float(u[1]) / d_wl,
               "layer_shear_stress": float(np.mean(_cauchy_shear(F, m.mu, m.lam))),
               "mises_q": float(np.mean(q[wl.start:wl.end])), "p_mean": float(np.mean(p[wl.start:wl.end])),
               "collapse": float(np.mean(c)), "failed_fraction": float(np.mean(flag != 0))}
        self.times.append(t)
        for k, v in out.items():
            self.series.setdefault(k, []).append(v)
        return out

    def summary(self) -> dict:
        """Shear-test results from the series recorded so far (:func:`analyze_shear_series`)."""
        return analyze_shear_series(self.scene, np.asarray(self.times),
                                    {k: np.asarray(v) for k, v in self.series.items()})


def attach(sim) -> ShearMonitor:
    """Add the weak-layer action and the shear-test frame diagnostics to ``sim``; return the monitor (idempotent)."""
    from .scenes import attach_monitor

    return attach_monitor(sim, ShearMonitor)


def shear_curves(scene: dict, times, series: dict) -> dict[str, np.ndarray]:
    """Curves of the pushing phase: ``u`` (m), ``gamma``, ``tau`` (Pa), ``q`` (Pa), ``axial`` (-), ``t`` (s).

    Displacements are taken relative to the state when the push starts;
    ``axial`` is the thickness loss over ``D_wl`` (positive = compaction).
    """
    t = np.asarray(times, dtype=float)
    i0 = min(int(np.searchsorted(t, float(scene["derived"]["push_start"]) - 1e-12)), len(t) - 1)
    d_wl = float(scene["weak_layer_thickness"])
    u = np.asarray(series["shear_displacement"], dtype=float)[i0:]
    v = np.asarray(series["normal_displacement"], dtype=float)[i0:]
    u = u - u[0]
    return {"t": t[i0:], "u": u, "gamma": u / d_wl, "tau": np.asarray(series["shear_stress"], dtype=float)[i0:],
            "q": np.asarray(series["mises_q"], dtype=float)[i0:], "axial": -(v - v[0]) / d_wl}


def analyze_shear_series(scene: dict, times, series: dict) -> dict:
    """Peak and residual strength, softening displacement and collapse (:func:`fronts.shear_summary`)."""
    c = shear_curves(scene, times, series)
    if len(c["u"]) < 3:
        return {}
    sm = fronts.shear_summary(c["u"], c["tau"], c["axial"])
    return {"peak_shear_stress": sm.peak_stress, "residual_shear_stress": sm.residual_stress,
            "peak_displacement": sm.peak_displacement, "softening_displacement": sm.softening_displacement,
            "drop_displacement": sm.drop_displacement,
            "collapse_fraction": sm.collapse_fraction, "peak_q": float(np.max(c["q"])),
            "sigma_n": float(scene["derived"]["sigma_n"]),
            "collapse_fraction_law": float(scene["derived"]["collapse_fraction_law"])}


def run_shear_test(scenario, output=None, device=None, overrides=None, n_threads=None, **run_kwargs):
    """Load, attach the diagnostics, run; ``RunResult.extra`` holds :func:`analyze_shear_series`.

    Returns
    -------
    (RunResult, ShearMonitor)
    """
    from .scenes import run_scene

    return run_scene(scenario, output, device, overrides, n_threads, **run_kwargs)


# registered last: mpm_warp.scenes imports this module lazily (no circular import at load time)
from .scenes import register_scene, register_scene_monitor  # noqa: E402

register_scene("shear_test")(build_shear_test)
register_scene_monitor("shear_test", attach)
