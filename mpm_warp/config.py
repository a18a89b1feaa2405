"""Typed description of a run: domain, time control, output, blocks and the scenario (no file reading).

A :class:`Scenario` is everything the engine needs: domain and grid spacing, time control,
materials, blocks of particles, walls and output choices, plus, for a snow scene, its typed
parameters (:attr:`Scenario.scene`, e.g. :class:`mpm_warp.scenes.pst.PSTParams`), which the engine
only stores. :meth:`Scenario.validate` checks every value before any kernel runs (the error names
the field, the value and the allowed range). Reading TOML files, overrides and strict keys are in
:mod:`mpm_warp.loader`. Units are SI throughout (m, s, kg, Pa).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Literal, Protocol, get_args, runtime_checkable

import numpy as np

from .checks import choice, finite_number, positive_int, vector
from .errors import InvalidArgument
from .materials import Elastic
from .time_step import MAX_MACH, MAX_STEPS, STABLE_DT, check_end_time, first_step, step_budget
from .walls import WALL_KINDS, WallKind

__all__ = ["Block", "Domain", "TimeControl", "Output", "Scenario", "SceneParams", "OUTPUT_FIELDS", "PRECISIONS",
           "BOUNDARIES", "Precision", "Boundary", "ON_INVERSION", "MAX_STEPS", "MAX_MACH", "STABLE_DT", "first_step",
           "check_end_time"]

Precision = Literal["float32", "float64"]
PRECISIONS: tuple[str, ...] = get_args(Precision)
Boundary = Literal[WallKind, "none"]
#: conditions of the box faces: a wall kind, or "none" (no box walls)
BOUNDARIES: tuple[str, ...] = (*WALL_KINDS, "none")
OnInversion = Literal["report", "stop"]
#: what a run does when P2G floors singular values or meets an inverted element (``Output.on_inversion``)
ON_INVERSION: tuple[str, ...] = get_args(OnInversion)
#: particle fields the output may hold: name -> (per-particle shape, unit, description); "dim" is the scene's dimension
OUTPUT_FIELDS = {
    "x": (("dim",), "m", "position"),
    "v": (("dim",), "m/s", "velocity"),
    "F": ((3, 3), "1", "elastic deformation gradient F_E (plane strain: in-plane block and F_zz)"),
    "stress": ((3, 3), "Pa", "Cauchy stress tensor, tension positive (plane strain: in-plane block and sigma_zz)"),
    "log_jp": ((), "1", "ln det F_P (0 for elastic particles)"),
    "kappa": ((), "J/m^3 or Pa", "softening state: plastic work of a bonded weak layer (J/m^3; its bond is "
              "1 - kappa/kappa_s), largest effective tensile stress of a cracking slab (Pa); 0 elsewhere"),
    "damage": ((), "1", "damage 0-1: 1 - bond of a bonded weak layer, tensile damage of a cracking slab; 0 elsewhere"),
    "p": ((), "Pa", "pressure -tr(tau)/3, Kirchhoff, compression positive"),
    "q": ((), "Pa", "Mises stress sqrt(3/2)|dev tau|, Kirchhoff"),
    "yielded": ((), "1", "1 where the Cam-Clay return was active during the frame"),
}


@runtime_checkable
class SceneParams(Protocol):
    """Typed parameters of a snow scene (see :mod:`mpm_warp.scenes`): a frozen dataclass with a ``kind``."""

    kind: str

    def to_dict(self) -> dict:
        """Plain, JSON-serialisable dict (with ``kind``) that the loader turns back into the parameters."""


@dataclass(frozen=True)
class Block:
    """A box of particles of one material.

    Attributes
    ----------
    material : str
        Name of a material of the scenario.
    lo, hi : (dim,) float
        Corners of the box (m).
    velocity : (dim,) float, callable or None
        Initial velocity (m/s); in Python a function ``f(x: (n, dim)) -> (n, dim)`` also works; None = at rest.
    particles_per_cell : int
        Particles per cell and axis, 1-8 (2 gives 8 per cell in 3D, 4 in 2D).
    name : str
        Label of the block (its particle group).
    halfspaces : tuple of (dim + 1,) float
        Planes that also bound the block: ``(n_x, n_y[, n_z], c)`` keeps the lattice points with
        ``n . x <= c`` (m); e.g. the slanted ends of a PST column with vertical faces. Empty: the box.
    interface_normal : int
        The axis normal to the layers of a laterally uniform stack the block is part of (every block naming the
        same axis): where a grid cell mixes the stack's materials its particles take the laminate closure
        (docs/model.md §5b). -1 (the default): none.
    """

    material: str
    lo: tuple
    hi: tuple
    velocity: Any = None
    particles_per_cell: int = 2
    name: str = ""
    halfspaces: tuple = ()
    interface_normal: int = -1

    def inside(self, x):
        """Mask (n,) of the points ``x`` (n, dim) (m) inside every one of :attr:`halfspaces`."""
        keep = np.ones(len(x), dtype=bool)
        for h in self.halfspaces:
            keep &= np.asarray(x) @ np.asarray(h[:-1], dtype=float) <= float(h[-1])
        return keep


@dataclass(frozen=True)
class Domain:
    """Simulation box and background grid.

    Attributes
    ----------
    lo, hi : (dim,) float
        Box corners (m); particles must start inside.
    dx : float
        Grid spacing (m), > 0.
    boundary : {"sticky", "slip", "separate", "none"}
        Condition of the box faces: a wall kind (:data:`mpm_warp.walls.WALL_KINDS`) or "none" (no box
        walls; particles that reach the grid edge are clamped and counted).
    friction : float
        Coulomb coefficient (-) of the box faces when ``boundary = "separate"``.
    boundary_faces : str
        Axes whose two faces carry the box condition, e.g. ``"xyz"`` or ``"z"``.
    dimension : {2, 3}
        3: a 3D scene. 2: plane strain in the x-y plane (true 2D kernels: a 3x3
        stencil, 4 particles per cell at 2 per axis; the out-of-plane elastic
        stretch is kept, so the constitutive law is the 3D one under
        ``F_zz = 1``). In 2D every vector has two components (x, y), and masses,
        volumes, energies and wall forces are per metre of depth.
    """

    lo: tuple
    hi: tuple
    dx: float
    boundary: Boundary = "slip"
    friction: float = 0.0
    boundary_faces: str = "xyz"
    dimension: int = 3


@dataclass(frozen=True)
class TimeControl:
    """Time stepping.

    Attributes
    ----------
    end : float
        End time (s).
    frame_interval : float
        Time between output frames (s).
    cfl : float
        C in ``dt = C dx / (c_p + |v|_max)`` (-); (0, 1], default 0.4.
    dt : float
        Fixed step (s); 0 selects the automatic step.
    dt_max : float
        Upper bound of the automatic step (s); 0 means none.
    allow_unstable_dt : bool
        Accept a fixed ``dt`` above the stability limit :data:`STABLE_DT` ``dx / c_p`` (stability studies:
        the health check then stops the run); False (default) refuses it before anything runs.
    gravity : (dim,) float or None
        Gravitational acceleration (m/s^2); a slope is a rotated gravity. None: 9.81 m/s^2 along -y.
    gravity_ramp : float
        Gravity grows linearly from 0 over this time (s); 0 = full at once.
    damping : float
        Grid velocity damping rate (1/s) applied while ``t < damping_until``:
        ``v *= max(0, 1 - damping dt)``; settles a scene to rest before the experiment. 0 = none.
    damping_until : float
        Time (s) at which the damping stops.
    """

    end: float
    frame_interval: float
    cfl: float = 0.4
    dt: float = 0.0
    dt_max: float = 0.0
    allow_unstable_dt: bool = False
    gravity: tuple | None = None
    gravity_ramp: float = 0.0
    damping: float = 0.0
    damping_until: float = 0.0


@dataclass(frozen=True)
class Output:
    """Output choices.

    Attributes
    ----------
    fields : tuple of str
        Particle fields stored per frame (:data:`OUTPUT_FIELDS`); ``x`` is always stored.
    checkpoint_every : int
        Write a checkpoint every this many frames (0: only the initial one).
    health_every : int
        Run the device health check every this many steps (>= 1).
    on_inversion : {"report", "stop"}
        "report" (default): count singular-value floor events and inversions (``det F_tr <= 0``)
        and report them in the result; "stop": end the run (exit status 3) at the first health
        check that finds one, naming the step and the counts.
    """

    fields: tuple = ("x",)
    checkpoint_every: int = 10
    health_every: int = 20
    on_inversion: OnInversion = "report"


@dataclass(frozen=True)
class Scenario:
    """A complete simulation set-up.

    Attributes
    ----------
    name, description : str
    domain : Domain
    time : TimeControl
    materials : dict of str -> Elastic or CamClaySnow
    blocks : tuple of Block
    walls : tuple of Wall
    output : Output
    precision : {"float32", "float64"}
    scene : SceneParams or None
        Typed parameters of the snow scene this scenario was built from (None for plain blocks);
        the engine stores them (run files, checkpoints) and never reads them.
    calibration : dict or None
        What the scene's builder derived from its parameters, as plain JSON values (the PST's and the
        shear test's weak-layer calibration: model parameters and predictions); stored with the scenario
        so that monitors, resumes and post-processing read it instead of deriving it again.
    """

    name: str
    domain: Domain
    time: TimeControl
    materials: dict
    blocks: tuple
    walls: tuple = ()
    output: Output = field(default_factory=Output)
    precision: Precision = "float32"
    description: str = ""
    scene: SceneParams | None = None
    calibration: dict | None = None

    def validate(self) -> Scenario:
        """Check every field before any kernel runs; return a normalised copy."""
        dom = _domain(self.domain)
        dim = dom.dimension
        tc = _time(self.time, dim)
        if not self.materials:
            raise InvalidArgument("materials", {}, "at least one material")
        mats = {}
        for name, m in self.materials.items():
            if not isinstance(m, Elastic):
                raise InvalidArgument(f"materials.{name}", m, "an Elastic or CamClaySnow material")
            mats[name] = m.validate(f"materials.{name}")
        blocks = tuple(_block(b, i, mats, dom) for i, b in enumerate(self.blocks))
        if not blocks:
            raise InvalidArgument("blocks", [], "at least one block of particles")
        walls = tuple(w.validate(f"walls[{i}]", dim) for i, w in enumerate(self.walls))
        out = self.output
        if not isinstance(out.fields, (list, tuple)):
            raise InvalidArgument("output.fields", out.fields, "a list of field names, e.g. [\"x\", \"v\"]")
        for f_ in out.fields:
            choice("output.fields[]", f_, tuple(OUTPUT_FIELDS))
        positive_int("output.checkpoint_every", out.checkpoint_every, lo=0)
        positive_int("output.health_every", out.health_every, lo=1)
        choice("output.on_inversion", out.on_inversion, ON_INVERSION)
        outp = Output(tuple(dict.fromkeys(("x", *out.fields))), out.checkpoint_every, out.health_every,
                      out.on_inversion)
        choice("precision", self.precision, PRECISIONS)
        if self.calibration is not None and not isinstance(self.calibration, dict):
            raise InvalidArgument("calibration", self.calibration, "a dict of what the scene builder derived, or None")
        if self.scene is not None and not isinstance(self.scene, SceneParams):
            raise InvalidArgument("scene", self.scene, "typed scene parameters (e.g. mpm_warp.scenes.pst.PSTParams) "
                                  "or None; a scenario file's [scene] table is read by mpm_warp.loader")
        step_budget(tc, dom.dx, mats, blocks)
        return replace(self, domain=dom, time=tc, materials=mats, blocks=blocks, walls=walls, output=outp)

    def to_dict(self) -> dict:
        """Plain, JSON-serialisable dict of the resolved scenario (stored in every output)."""
        d = {
            "name": self.name,
            "description": self.description,
            "precision": self.precision,
            "domain": asdict(self.domain),
            "time": asdict(self.time),
            "materials": {k: m.to_dict() for k, m in self.materials.items()},
            "blocks": [],
            "walls": [w.to_dict() for w in self.walls],
            "output": {"fields": list(self.output.fields), "checkpoint_every": self.output.checkpoint_every,
                       "health_every": self.output.health_every, "on_inversion": self.output.on_inversion},
        }
        for b in self.blocks:
            bd = asdict(b)
            if callable(b.velocity):
                # a Python velocity field cannot be serialised; the state (checkpoints) carries it
                bd["velocity"] = [0.0] * self.domain.dimension
            if b.interface_normal < 0:
                del bd["interface_normal"]  # not written when off: the files of scenes without it are unchanged
            d["blocks"].append(bd)
        if self.scene is not None:
            d["scene"] = {"kind": self.scene.kind, **self.scene.to_dict()}
        if self.calibration is not None:
            d["calibration"] = self.calibration
        return json.loads(json.dumps(d, default=list))


def _domain(d: Domain) -> Domain:
    dim = positive_int("domain.dimension", d.dimension, lo=2, hi=3)
    lo = vector("domain.lo", d.lo, dim)
    hi = vector("domain.hi", d.hi, dim)
    for a in range(dim):
        if hi[a] <= lo[a]:
            raise InvalidArgument(f"domain.hi[{a}]", hi[a], f"a number > domain.lo[{a}] = {lo[a]:g}")
    dx = finite_number("domain.dx", d.dx, lo=0.0, lo_open=True)
    ncell = [(hi[a] - lo[a]) / dx for a in range(dim)]
    max_cells = 4096 if dim == 3 else 32768
    if max(ncell) > max_cells:
        raise InvalidArgument("domain.dx", d.dx,
                              f"a spacing giving at most {max_cells} cells per axis (got {max(ncell):.0f})")
    choice("domain.boundary", d.boundary, BOUNDARIES)
    finite_number("domain.friction", d.friction, lo=0.0)
    if not isinstance(d.boundary_faces, str) or not set(d.boundary_faces) <= set("xyz"):
        raise InvalidArgument("domain.boundary_faces", d.boundary_faces, "letters among 'xyz'")
    return Domain(lo, hi, dx, d.boundary, float(d.friction), d.boundary_faces, dim)


def _time(t: TimeControl, dim: int) -> TimeControl:
    end = finite_number("time.end", t.end, lo=0.0, lo_open=True)
    fi = finite_number("time.frame_interval", t.frame_interval, lo=0.0, lo_open=True)
    if fi > end:
        raise InvalidArgument("time.frame_interval", t.frame_interval, f"at most time.end = {end:g} s (a longer "
                              "interval writes no frame but the initial and the last)")
    return TimeControl(
        end=end,
        frame_interval=fi,
        cfl=finite_number("time.cfl", t.cfl, lo=0.0, hi=1.0, lo_open=True),
        dt=finite_number("time.dt", t.dt, lo=0.0),
        dt_max=finite_number("time.dt_max", t.dt_max, lo=0.0),
        allow_unstable_dt=_flag("time.allow_unstable_dt", t.allow_unstable_dt),
        gravity=vector("time.gravity", (0.0, -9.81, 0.0)[:dim] if t.gravity is None else t.gravity, dim),
        gravity_ramp=finite_number("time.gravity_ramp", t.gravity_ramp, lo=0.0),
        damping=finite_number("time.damping", t.damping, lo=0.0),
        damping_until=finite_number("time.damping_until", t.damping_until, lo=0.0))


def _block(b: Block, i: int, mats: dict, dom: Domain) -> Block:
    w = f"blocks[{i}]"
    if b.material not in mats:
        raise InvalidArgument(f"{w}.material", b.material, "one of " + ", ".join(map(repr, mats)))
    dim = dom.dimension
    blo = vector(f"{w}.lo", b.lo, dim)
    bhi = vector(f"{w}.hi", b.hi, dim)
    lo, hi, dx = dom.lo, dom.hi, dom.dx
    for a in range(dim):
        if bhi[a] <= blo[a]:
            raise InvalidArgument(f"{w}.hi[{a}]", bhi[a], f"a number > {w}.lo[{a}] = {blo[a]:g}")
        if blo[a] < lo[a] - 1e-9 * dx or bhi[a] > hi[a] + 1e-9 * dx:
            raise InvalidArgument(f"{w}.lo/hi[{a}]", (blo[a], bhi[a]),
                                  f"inside the domain [{lo[a]:g}, {hi[a]:g}] (particles inside the grid)")
    size = [bhi[a] - blo[a] for a in range(dim)]
    if dx > max(size) * (1 + 1e-9):        # a layer thinner than a cell (one particle across) is fine; a block
        raise InvalidArgument("domain.dx", dx, (  # inside one cell is a few particles the grid cannot resolve
            f"a spacing at most the largest extent of every block: {w} is " + " x ".join(f"{e:g}" for e in size)
            + " m, inside one cell"))
    ppc = positive_int(f"{w}.particles_per_cell", b.particles_per_cell, lo=1, hi=8)
    vel = b.velocity if callable(b.velocity) else vector(
        f"{w}.velocity", (0.0,) * dim if b.velocity is None else b.velocity, dim)
    if isinstance(b.halfspaces, (str, bytes)) or not isinstance(b.halfspaces, (list, tuple)):
        raise InvalidArgument(f"{w}.halfspaces", b.halfspaces, f"a list of planes [n_1, ..., n_{dim}, c]")
    hs = tuple(vector(f"{w}.halfspaces[{k}]", h, dim + 1) for k, h in enumerate(b.halfspaces))
    for k, h in enumerate(hs):
        if all(c == 0.0 for c in h[:-1]):
            raise InvalidArgument(f"{w}.halfspaces[{k}]", h, "a plane with a non-zero normal")
    normal = positive_int(f"{w}.interface_normal", b.interface_normal, lo=-1, hi=dim - 1)
    return Block(b.material, blo, bhi, vel, ppc, b.name or f"block{i}", hs, normal)


def _flag(field: str, value) -> bool:
    if not isinstance(value, bool):
        raise InvalidArgument(field, value, "true or false")
    return value
