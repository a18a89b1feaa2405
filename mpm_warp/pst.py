"""Propagation Saw Test (PST): scene builder, saw, crack-front tracking (MODEL.md 6).

A column of length ``L`` on a stiff substratum: a thin Cam-Clay weak layer
(thickness ``D_wl``) bonded to the substratum (a wall at ``y = 0``) under an
elastic slab (thickness ``D``). ``x`` runs along the column, ``y`` is normal
to the bed, ``z`` across; a slope of angle ``theta`` is a rotated gravity
``g (sin theta, -cos theta, 0)`` (downslope is ``+x``). By default the column is
one cell thin in ``z`` between slip walls (plane strain); ``scene.width > 0``
gives a full 3D column with free sides.

Run sequence (all on the device, no host loop):

1. settling: gravity ramps up over ``settle.gravity_ramp`` while the grid is
   damped until ``settle.duration`` (``time.damping``/``damping_until``); the
   hardening state of the weak layer at the end of settling is snapshotted;
2. the saw: from ``settle.duration`` on, a blade advances at ``saw.speed``
   from one end of the column through the weak layer up to ``saw.cut_length``;
   weak-layer particles behind the blade get ``log_jp = saw.log_jp`` (a large
   positive value: ``p0`` sits at its floor and compaction cannot re-harden
   them within any reachable strain), re-applied every step while behind it;
3. free run: the crack runs by itself or arrests.

Weak-layer failure (``weak_layer.failure = "brittle"``, :func:`weak_layer_kernel`):
from the end of settling on, a weak-layer particle whose stress reaches the
yield surface loses its cohesion at once (``log_jp -> 0``, ``p0`` at its floor)
and then compacts under the slab until the hardening law carries the load:
the anticrack's collapse. Why it is needed: the engine's associative return
softens only through plastic dilation, which the slab's weight stops at the
critical state, and compaction on the cap only hardens; neither lets the
layer give way under a load it carried, so no crack can run by itself
(checked: with ``failure = "none"`` the front stops at the saw). Gaume et al.
(2018) obtain the softening with a modified, non-associative flow rule; this
rule is its brittle limit, implemented here without touching the engine.

Crack front (documented criterion): a weak-layer particle has *collapsed* once
its plastic volume has shrunk by more than ``front.threshold`` relative to the
reference state (the settled layer, or the state at failure),
``1 - exp(log_jp - log_jp_ref) >= threshold``, or once it has been sawn. The
column is split into bins of ``front.bin`` along the cut direction; a bin's
arrival time is the first time any of its particles collapsed (``atomic_min``
on the device, every step). The front at time ``t`` is the far edge of the
contiguous run of bins, from the saw's end, whose arrival time is ``<= t``
(distance from the saw's starting end, m). The failure front (failed or sawn
particles) is tracked the same way.

Resolution: the weak layer must span at least two grid cells
(:data:`MIN_WEAK_LAYER_CELLS`); with one, the slab's B-spline stencil reaches
the substratum's wall nodes and the slab rests partly on the wall.

The scene builder is registered as scene kind ``"pst"``; :func:`attach` adds
the saw/front action and the frame diagnostics to a :class:`Simulation`, and
:func:`run_pst` does both and fills ``RunResult.extra``.
"""


import copy
import math

import numpy as np
import warp as wp

from . import fronts
from .checks import finite_number
from .errors import ScenarioError
from .kernels.snow import pst_action_kernel, weak_layer_kernel
from .materials import CamClaySnow, Elastic

__all__ = ["build_pst", "attach", "run_pst", "PSTMonitor", "slab_normal_stress",
           "weak_layer_material", "GRAVITY"]

GRAVITY = fronts.GRAVITY
"""Gravitational acceleration (m/s^2)."""

#: defaults of the ``[scene.weak_layer]`` table (see ``scenarios/pst_flat.toml`` for the reasoning)
WEAK_LAYER_DEFAULTS = {"E": 1.0e6, "nu": 0.3, "density": 150.0, "M": 1.2, "beta": 0.3, "xi": 0.0066,
                       "consolidation_ratio": 3.0, "p0_ini": -1.0, "p0_floor_ratio": 1e-5,
                       "failure": "brittle", "failure_log_jp": 0.0}
#: defaults of the ``[scene.settle]`` table: gravity ramp (s), grid damping rate (1/s), settling time (s)
SETTLE_DEFAULTS = {"gravity_ramp": 0.05, "damping": 100.0, "duration": 0.1}
#: the weak layer must span at least this many grid cells: thinner, the slab's B-spline stencil
#: reaches the substratum's wall nodes and the slab rests partly on the wall through the grid
MIN_WEAK_LAYER_CELLS = 2.0

#: defaults of every ``[scene]`` key of a PST (units in the comments of ``scenarios/pst_*.toml``)
PST_DEFAULTS = {
    "kind": "pst",
    "dx": 0.01,                   # m
    "particles_per_cell": 2,      # per axis
    "length": 4.0,                # m, column length L
    "slab_thickness": 0.5,        # m, D
    "weak_layer_thickness": 0.02,  # m, D_wl
    "slope_angle": 0.0,           # deg
    "width": 0.0,                 # m, 0 = plane strain (one cell between slip walls)
    "substratum": "sticky",       # "sticky" (bonded) or "frictional" (Coulomb contact)
    "substratum_friction": 0.5,   # -, only for "frictional"
    "margin": 0.1,                # m, free space around the column
    "marker_spacing": 0.1,        # m, slab-base markers along the column
    "slab": {"E": 5.0e6, "nu": 0.3, "density": 250.0},
    "weak_layer": WEAK_LAYER_DEFAULTS,
    "settle": SETTLE_DEFAULTS,
    "saw": {"speed": 4.0, "cut_length": 0.4, "from_end": "left", "log_jp": 5.0},
    "front": {"threshold": 0.05, "bin": 0.0},
}
_GENERATED = ("domain", "materials", "blocks", "walls")
_GENERATED_TIME = ("gravity", "gravity_ramp", "damping", "damping_until")


# ----------------------------------------------------------------------------- shared helpers
def merge_table(given: dict, defaults: dict, where: str) -> dict:
    """``defaults`` updated by ``given``; unknown keys raise :class:`ScenarioError` naming ``where.key``."""
    if not isinstance(given, dict):
        raise ScenarioError(f"{where} must be a table")
    out = copy.deepcopy(defaults)
    for k, v in given.items():
        if k not in defaults:
            raise ScenarioError(f"unknown key '{where}.{k}'; allowed: {', '.join(sorted(defaults))}")
        if isinstance(defaults[k], dict):
            out[k] = merge_table(v, defaults[k], f"{where}.{k}")
        else:
            out[k] = v
    return out


def _num(where: str, v, lo=None, lo_open=False, hi=None) -> float:
    """A finite number (InvalidArgument naming ``where`` otherwise)."""
    return finite_number(where, v, lo=lo, lo_open=lo_open, hi=hi)


def slab_normal_stress(density: float, thickness: float, slope_deg: float = 0.0) -> float:
    """Bed-normal stress of the slab's weight, ``rho g D cos(theta)`` (Pa)."""
    return density * GRAVITY * thickness * math.cos(math.radians(slope_deg))


def oedometric_pressure(sigma_n: float, nu: float) -> float:
    """Mean pressure (Pa) under a bed-normal stress ``sigma_n`` with no lateral strain.

    Lateral stresses ``nu/(1-nu) sigma_n``: ``p = sigma_n (1 + nu) / (3 (1 - nu))``.
    """
    return sigma_n * (1.0 + nu) / (3.0 * (1.0 - nu))


def weak_layer_material(wl: dict, sigma_n: float, where: str) -> dict:
    """Cam-Clay material dict of the weak layer; ``p0_ini`` from the slab load when not given.

    ``p0_ini = consolidation_ratio * sigma_n`` (the layer consolidated by the slab it
    carries) unless ``p0_ini >= 0`` is given explicitly (Pa).
    """
    if wl["failure"] not in ("brittle", "none"):
        raise ScenarioError(f"{where}.failure = {wl['failure']!r}: expected 'brittle' or 'none'")
    _num(f"{where}.failure_log_jp", wl["failure_log_jp"])
    p0 = _num(f"{where}.p0_ini", wl["p0_ini"])
    if p0 < 0:
        p0 = _num(f"{where}.consolidation_ratio", wl["consolidation_ratio"], lo=0.0) * sigma_n
    return {"model": "camclay", "E": wl["E"], "nu": wl["nu"], "density": wl["density"], "M": wl["M"],
            "beta": wl["beta"], "xi": wl["xi"], "p0_ini": float(p0), "p0_floor_ratio": wl["p0_floor_ratio"]}


def settle_time_keys(raw: dict, settle: dict, gravity: tuple, where: str) -> dict:
    """``[time]`` with gravity and the settling ramp/damping filled in (the scene owns them)."""
    t = dict(raw.get("time", {}))
    for k in _GENERATED_TIME:
        if k in t:
            raise ScenarioError(f"time.{k} is set by the {where} scene; use [scene.settle] / scene.slope_angle")
    ramp = _num(f"{where}.settle.gravity_ramp", settle["gravity_ramp"], lo=0.0)
    dur = _num(f"{where}.settle.duration", settle["duration"], lo=0.0)
    if dur < ramp:
        raise ScenarioError(f"{where}.settle.duration = {dur:g} s must be >= settle.gravity_ramp = {ramp:g} s")
    t.update(gravity=list(gravity), gravity_ramp=ramp, damping=_num(f"{where}.settle.damping",
                                                                      settle["damping"], lo=0.0),
             damping_until=dur)
    return t


def check_generated(raw: dict, kind: str) -> None:
    """A scene table generates the domain, materials, blocks and walls: they may not be given too."""
    for k in _GENERATED:
        if k in raw:
            raise ScenarioError(f"[{k}] is generated by scene.kind = {kind!r}; set its parameters in [scene]")


def check_weak_layer_cells(d_wl: float, dx: float, where: str) -> None:
    """Raise if the weak layer spans fewer than :data:`MIN_WEAK_LAYER_CELLS` grid cells."""
    if d_wl < MIN_WEAK_LAYER_CELLS * dx * (1.0 - 1e-9):
        raise ScenarioError(
            f"{where}.weak_layer_thickness = {d_wl:g} m spans {d_wl / dx:.2g} cells of {where}.dx = {dx:g} m: "
            f"at least {MIN_WEAK_LAYER_CELLS:g} are needed (else the slab's stencil reaches the substratum "
            f"wall through the grid); lower dx or thicken the layer")


def plane_domain(lo_xy, hi_xy, dx: float, width: float, margin: float) -> tuple[dict, float]:
    """Domain table and z extent: one cell between slip walls (width 0) or a free 3D column."""
    if width <= 0.0:
        return ({"lo": [lo_xy[0], lo_xy[1], 0.0], "hi": [hi_xy[0], hi_xy[1], dx], "dx": dx,
                 "boundary": "slip", "boundary_faces": "z"}, dx)
    return ({"lo": [lo_xy[0], lo_xy[1], -margin], "hi": [hi_xy[0], hi_xy[1], width + margin], "dx": dx,
             "boundary": "none"}, width)


# ----------------------------------------------------------------------------- builder
def build_pst(raw: dict) -> dict:
    """Expand ``[scene] kind = "pst"`` into domain, materials, blocks, walls and time settings.

    Derived values used at run time (layout, saw timing, markers, references)
    are stored in ``scene.derived`` so a run file is self-describing.
    """
    raw = copy.deepcopy(raw)
    check_generated(raw, "pst")
    given = {k: v for k, v in raw["scene"].items() if k != "derived"}
    s = merge_table(given, PST_DEFAULTS, "scene")
    dx = _num("scene.dx", s["dx"], lo=0.0, lo_open=True)
    L = _num("scene.length", s["length"], lo=0.0, lo_open=True)
    D = _num("scene.slab_thickness", s["slab_thickness"], lo=0.0, lo_open=True)
    Dwl = _num("scene.weak_layer_thickness", s["weak_layer_thickness"], lo=0.0, lo_open=True)
    check_weak_layer_cells(Dwl, dx, "scene")
    theta = _num("scene.slope_angle", s["slope_angle"], lo=-60.0, hi=60.0)
    width = _num("scene.width", s["width"], lo=0.0)
    margin = _num("scene.margin", s["margin"], lo=2.0 * dx)
    if s["substratum"] not in ("sticky", "frictional"):
        raise ScenarioError(f"scene.substratum = {s['substratum']!r}: expected 'sticky' or 'frictional'")
    saw = s["saw"]
    cut = _num("scene.saw.cut_length", saw["cut_length"], lo=0.0, hi=L)
    speed = _num("scene.saw.speed", saw["speed"], lo=0.0, lo_open=True)
    if saw["from_end"] not in ("left", "right"):
        raise ScenarioError(f"scene.saw.from_end = {saw['from_end']!r}: expected 'left' (x = 0) or 'right' (x = L)")
    bin_w = _num("scene.front.bin", s["front"]["bin"], lo=0.0) or dx
    thr = _num("scene.front.threshold", s["front"]["threshold"], lo=0.0, lo_open=True, hi=1.0)

    slab, wl = s["slab"], s["weak_layer"]
    sigma_n = slab_normal_stress(_num("scene.slab.density", slab["density"], lo=0.0, lo_open=True), D, theta)
    mats = {"slab": {"model": "elastic", "E": slab["E"], "nu": slab["nu"], "density": slab["density"]},
            "weak_layer": weak_layer_material(wl, sigma_n, "scene.weak_layer")}
    th = math.radians(theta)
    gravity = (GRAVITY * math.sin(th), -GRAVITY * math.cos(th), 0.0)
    domain, wz = plane_domain((-margin, 0.0), (L + margin, Dwl + D + margin), dx, width, margin)
    ppc = s["particles_per_cell"]
    blocks = [
        {"name": "weak_layer", "material": "weak_layer", "lo": [0.0, 0.0, 0.0], "hi": [L, Dwl, wz],
         "particles_per_cell": ppc},
        {"name": "slab", "material": "slab", "lo": [0.0, Dwl, 0.0], "hi": [L, Dwl + D, wz],
         "particles_per_cell": ppc},
    ]
    floor = {"name": "substratum", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0]}
    if s["substratum"] == "sticky":
        floor["kind"] = "sticky"
    else:
        floor.update(kind="separate", friction=_num("scene.substratum_friction", s["substratum_friction"], lo=0.0))
    spacing = _num("scene.marker_spacing", s["marker_spacing"], lo=0.0, lo_open=True)
    markers = [float(m) for m in np.arange(0.5 * spacing, L, spacing)]

    E, nu, rho = float(slab["E"]), float(slab["nu"]), float(slab["density"])
    slab_mat = Elastic(E, nu, rho)
    wl_mat = mats["weak_layer"]
    wl_cc = CamClaySnow(float(wl["E"]), float(wl["nu"]), float(wl["density"]), xi=float(wl["xi"]))
    collapse_law = wl_cc.collapse_at(sigma_n)
    s["derived"] = {
        "sigma_n": sigma_n, "p0_ini": wl_mat["p0_ini"], "p_oedometric": oedometric_pressure(sigma_n, float(wl["nu"])),
        "collapse_fraction_law": collapse_law, "collapse_height_law": collapse_law * Dwl,
        "saw_start": float(s["settle"]["duration"]), "saw_end": float(s["settle"]["duration"]) + cut / speed,
        "bin": bin_w, "threshold": thr, "markers": markers, "slab_base_y": Dwl, "width_z": wz,
        "heierli_speed": fronts.heierli_speed(E, D, rho, collapse_law * Dwl),
        "heierli_touchdown": fronts.heierli_touchdown(E, D, rho, collapse_law * Dwl),
        "rayleigh_speed": slab_mat.rayleigh_speed,
        "shear_wave_speed": slab_mat.s_wave_speed,
    }
    raw["scene"] = s
    raw["domain"] = domain
    raw["materials"] = mats
    raw["blocks"] = blocks
    raw["walls"] = [floor]
    raw["time"] = settle_time_keys(raw, s["settle"], gravity, "scene")
    raw.setdefault("description", f"PST: L = {L:g} m, slab {D:g} m on a {Dwl * 100:g} cm weak layer, "
                                  f"slope {theta:g} deg, cut {cut:g} m at {speed:g} m/s")
    return raw


# ----------------------------------------------------------------------------- device actions
class WeakLayer:
    """Device state of a Cam-Clay weak layer group: collapse reference, failure flags, brittle action.

    Parameters
    ----------
    sim : Simulation
    group_name : str
        Name of the weak-layer particle group.
    t_ref : float
        End of settling (s): the collapse reference is the state then.
    brittle : bool
        Add the brittle cohesion loss of :func:`weak_layer_kernel`.
    log_jp_failed : float
        Hardening state given at failure (-); 0 removes all consolidation.

    Attributes
    ----------
    ref : wp.array (n,)
        ``log_jp`` collapse is measured from.
    failed : wp.array of uint8 (n,)
        0 intact, 1 failed, 2 sawn.
    """

    #: relative tolerance on the yield function for "on the yield surface" (after the engine's return y ~ 0)
    YIELD_TOL = 1e-3

    def __init__(self, sim, group_name: str, t_ref: float, brittle: bool, log_jp_failed: float = 0.0):
        model = sim.model
        T = model.T
        g = next(g for g in model.groups if g.name == group_name)
        m = g.material
        self.group = g
        self.log_jp = sim.state.log_jp[g.plastic_start:g.plastic_start + g.count]
        self.ref = wp.array(np.full(g.count, m.initial_log_jp), dtype=T, device=sim.device)
        self.failed = wp.zeros(g.count, dtype=wp.uint8, device=sim.device)
        self.action = wp.launch(
            weak_layer_kernel(T), g.count,
            inputs=[sim.state.F[g.start:g.end], self.log_jp, self.ref, self.failed, sim.state.clock, float(t_ref),
                    int(bool(brittle)), T(m.mu), T(m.lam), T(m.M), T(m.beta), T(m.xi), T(m.p0_floor),
                    T(log_jp_failed), T(self.YIELD_TOL)],
            device=sim.device, record_cmd=True)
        sim.stepper.actions.append(self.action)

    def collapse(self) -> tuple[np.ndarray, np.ndarray]:
        """Host copies: collapse ``1 - exp(log_jp - ref)`` (-) and the failure flags."""
        lj = self.log_jp.numpy().astype(np.float64)
        return fronts.collapse_fraction(lj, self.ref.numpy().astype(np.float64)), self.failed.numpy()


class PSTMonitor:
    """The saw, the front trackers and the frame diagnostics of one PST simulation.

    Created by :func:`attach`. Frame scalars (stored in the run file):
    ``front`` (m from the cut end, collapse criterion of the module docstring),
    ``failure_front`` (m, same with failed-or-sawn particles), ``saw`` (m),
    ``collapse_height`` (m, mean collapse times ``D_wl`` over failed, unsawn
    particles that collapsed by more than the threshold),
    ``marker{k}_ux``/``marker{k}_uy`` (m, displacement since t = 0 of the
    slab-base particle nearest to ``scene.derived.markers[k]``).
    """

    def __init__(self, sim):
        sc = sim.scenario
        scene = sc.scene
        if scene.get("kind") != "pst" or "derived" not in scene:
            raise ScenarioError("PSTMonitor needs a scenario built by scene.kind = 'pst'")
        self.sim = sim
        self.scene = scene
        d = scene["derived"]
        model = sim.model
        T = model.T
        wl = next(g for g in model.groups if g.name == "weak_layer")
        slab = next(g for g in model.groups if g.name == "slab")
        self.wl, self.slab = wl, slab
        L = float(scene["length"])
        saw = scene["saw"]
        self.direction = 1.0 if saw["from_end"] == "left" else -1.0
        self.x_start = 0.0 if self.direction > 0 else L
        self.bin = float(d["bin"])
        self.n_bins = int(math.ceil(L / self.bin - 1e-9))
        self.length = L
        self.t_start = float(d["saw_start"])
        self.cut_length = float(saw["cut_length"])
        self.speed = float(saw["speed"])
        self.d_wl = float(scene["weak_layer_thickness"])
        self.log_jp_cut = float(saw["log_jp"])
        self.threshold = float(d["threshold"])
        dev = sim.device
        wlp = scene["weak_layer"]
        self.weak = WeakLayer(sim, "weak_layer", self.t_start, wlp["failure"] == "brittle",
                              float(wlp["failure_log_jp"]))
        self.arrival = wp.full(self.n_bins, np.inf, dtype=wp.float64, device=dev)
        self.arrival_failure = wp.full(self.n_bins, np.inf, dtype=wp.float64, device=dev)
        self.action = wp.launch(
            pst_action_kernel(T), wl.count,
            inputs=[sim.state.x[wl.start:wl.end], self.weak.log_jp, self.weak.ref, self.weak.failed,
                    sim.state.clock, self.t_start, self.x_start, self.direction, self.speed, self.cut_length,
                    T(self.log_jp_cut), T(math.log(1.0 - self.threshold)), self.bin, self.arrival,
                    self.arrival_failure],
            device=dev, record_cmd=True)
        sim.stepper.actions.append(self.action)
        # slab-base markers: the particle of the lowest slab row nearest to each station (middle of z)
        x0 = sim.x0[slab.start:slab.end]
        base = x0[:, 1] <= x0[:, 1].min() + 1e-6
        zmid = 0.5 * float(d["width_z"])
        idx = np.nonzero(base)[0]
        zc = idx[np.abs(x0[idx, 2] - zmid) <= np.abs(x0[idx, 2] - zmid).min() + 1e-6]
        self.markers = np.asarray(d["markers"], dtype=float)
        self.marker_index = slab.start + zc[np.argmin(np.abs(x0[zc, 0][None, :] - self.markers[:, None]), axis=1)]
        #: frame series recorded so far: ``times`` (s) and ``series`` name -> list
        self.times: list[float] = []
        self.series: dict[str, list[float]] = {}

    # ------------------------------------------------------------------ queries
    def units(self) -> dict[str, str]:
        """Units of the frame scalars."""
        u = {"front": "m", "failure_front": "m", "saw": "m", "collapse_height": "m"}
        for k in range(len(self.markers)):
            u[f"marker{k}_ux"] = "m"
            u[f"marker{k}_uy"] = "m"
        return u

    def arrival_times(self) -> tuple[np.ndarray, np.ndarray]:
        """Bin centres (m from the cut end) and first-failure times (s, inf where not failed)."""
        s = np.minimum((np.arange(self.n_bins) + 0.5) * self.bin, self.length)
        return s, self.arrival.numpy().copy()

    def saw_position(self, t: float) -> float:
        """Blade distance from the cut end (m) at time ``t`` (s)."""
        return float(np.clip(self.speed * (t - self.t_start), 0.0, self.cut_length))

    def frame_scalars(self, sim) -> dict[str, float]:
        """Frame diagnostics (see the class docstring), also appended to :attr:`series` once per time."""
        t = sim.time
        if self.times and self.times[-1] == t:
            return {k: v[-1] for k, v in self.series.items()}
        out = {"front": min(fronts.front_from_arrival(self.arrival.numpy(), t, self.bin), self.length),
               "failure_front": min(fronts.front_from_arrival(self.arrival_failure.numpy(), t, self.bin),
                                    self.length),
               "saw": self.saw_position(t)}
        c, flag = self.weak.collapse()
        sel = (c >= self.threshold) & (flag != 2)
        out["collapse_height"] = float(np.mean(c[sel]) * self.d_wl) if sel.any() else 0.0
        u = sim.state.x.numpy()[self.marker_index].astype(np.float64) - sim.x0[self.marker_index]
        for k in range(len(self.markers)):
            out[f"marker{k}_ux"] = float(u[k, 0])
            out[f"marker{k}_uy"] = float(u[k, 1])
        self.times.append(t)
        for k, v in out.items():
            self.series.setdefault(k, []).append(v)
        return out

    def summary(self) -> dict:
        """Scene results from the series recorded so far (see :func:`mpm_warp.fronts.pst_summary`)."""
        return fronts.pst_summary(self.scene, np.asarray(self.times),
                                  {k: np.asarray(v) for k, v in self.series.items()}, arrival=self.arrival_times())


def attach(sim) -> PSTMonitor:
    """Add the saw/front action and the PST frame diagnostics to ``sim``; return the monitor (idempotent)."""
    from .scenes import attach_monitor

    return attach_monitor(sim, PSTMonitor)


#: former name of :func:`mpm_warp.fronts.pst_summary`
analyze_pst_series = fronts.pst_summary


def run_pst(scenario, output: str | None = None, device: str | None = None, overrides=None, n_threads=None,
            **run_kwargs):
    """Load (name, path or Scenario), attach the saw and diagnostics, run; ``extra`` holds the results.

    Returns
    -------
    (RunResult, PSTMonitor)
    """
    from .scenes import run_scene

    return run_scene(scenario, output, device, overrides, n_threads, **run_kwargs)


# registered last: mpm_warp.scenes imports this module lazily (no circular import at load time)
from .scenes import register_scene, register_scene_monitor  # noqa: E402

register_scene("pst")(build_pst)
register_scene_monitor("pst", attach)
