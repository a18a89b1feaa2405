"""Typed scenario description and its strict TOML loader.

A scenario is everything needed to run: domain and grid spacing, time
control, materials, blocks of particles, walls and output choices. Files are
TOML (see ``scenarios/`` and the README); loading is strict: an unknown or
misspelt key fails with its dotted name and the list of valid keys, a wrong
type or out-of-range value fails with the field, the value and the range.
Parameters are layered as in pyro2: defaults, then the file, then
``section.key=value`` overrides (``--set`` on the command line).
"""

from __future__ import annotations

import copy
import difflib
import json
import math
import os
from dataclasses import MISSING, asdict, dataclass, field, fields, replace

from .checks import choice, finite_number, positive_int, vector3
from .errors import InvalidArgument, ScenarioError
from .materials import Elastic, material_from_dict
from .walls import WALL_KINDS, Wall

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["Block", "Domain", "TimeControl", "Output", "Scenario", "load_scenario", "apply_overrides",
           "OUTPUT_FIELDS", "PRECISIONS"]

PRECISIONS = ("float32", "float64")
#: particle fields the output may hold: name -> (per-particle shape, unit, description)
OUTPUT_FIELDS = {
    "x": ((3,), "m", "position"),
    "v": ((3,), "m/s", "velocity"),
    "F": ((3, 3), "1", "elastic deformation gradient F_E"),
    "log_jp": ((), "1", "ln det F_P (0 for elastic particles)"),
    "p": ((), "Pa", "pressure -tr(tau)/3, Kirchhoff, compression positive"),
    "q": ((), "Pa", "Mises stress sqrt(3/2)|dev tau|, Kirchhoff"),
    "yielded": ((), "1", "1 where the Cam-Clay return was active during the frame"),
}


@dataclass(frozen=True)
class Block:
    """A box of particles of one material.

    Parameters
    ----------
    material : str
        Name of a material of the scenario.
    lo, hi : (3,) float
        Corners of the box (m).
    velocity : (3,) float or callable
        Initial velocity (m/s); in Python a function ``f(x: (n, 3)) -> (n, 3)`` also works.
    particles_per_cell : int
        Particles per cell and axis (2 gives 8 per cell in 3D).
    name : str
        Label of the block.
    """

    material: str
    lo: tuple
    hi: tuple
    velocity: object = (0.0, 0.0, 0.0)
    particles_per_cell: int = 2
    name: str = ""


@dataclass(frozen=True)
class Domain:
    """Simulation box and background grid.

    Parameters
    ----------
    lo, hi : (3,) float
        Box corners (m); particles must start inside.
    dx : float
        Grid spacing (m), > 0.
    boundary : {"slip", "sticky", "separate", "none"}
        Condition on the box faces ("none": no box walls, particles that reach
        the grid edge are clamped and counted).
    friction : float
        Coulomb coefficient of the box faces when ``boundary = "separate"``.
    boundary_faces : str
        Axes whose two faces carry the box condition, e.g. ``"xyz"`` or ``"z"``.
    """

    lo: tuple
    hi: tuple
    dx: float
    boundary: str = "slip"
    friction: float = 0.0
    boundary_faces: str = "xyz"


@dataclass(frozen=True)
class TimeControl:
    """Time stepping.

    Parameters
    ----------
    end : float
        End time (s).
    frame_interval : float
        Time between output frames (s).
    cfl : float
        C in ``dt = C dx / (c_p + |v|_max)``; (0, 1], default 0.4.
    dt : float
        Fixed step (s); 0 selects the automatic step.
    dt_max : float
        Upper bound of the automatic step (s); 0 means none.
    gravity : (3,) float
        Gravitational acceleration (m/s^2); a slope is a rotated gravity.
    gravity_ramp : float
        Gravity grows linearly from 0 over this time (s); 0 = full at once.
    damping : float
        Grid velocity damping rate (1/s) applied while ``t < damping_until``:
        ``v *= max(0, 1 - damping dt)``; for settling a scene to rest before the
        experiment starts. 0 = none.
    damping_until : float
        Time (s) at which the damping stops.
    """

    end: float
    frame_interval: float
    cfl: float = 0.4
    dt: float = 0.0
    dt_max: float = 0.0
    gravity: tuple = (0.0, -9.81, 0.0)
    gravity_ramp: float = 0.0
    damping: float = 0.0
    damping_until: float = 0.0


@dataclass(frozen=True)
class Output:
    """Output choices.

    Parameters
    ----------
    fields : list of str
        Particle fields stored per frame (see ``OUTPUT_FIELDS``).
    checkpoint_every : int
        Write a checkpoint every this many frames (0: only the initial one).
    health_every : int
        Run the device health check every this many steps.
    """

    fields: tuple = ("x",)
    checkpoint_every: int = 10
    health_every: int = 20


@dataclass(frozen=True)
class Scenario:
    """A complete, validated simulation set-up (see module docstring)."""

    name: str
    domain: Domain
    time: TimeControl
    materials: dict
    blocks: tuple
    walls: tuple = ()
    output: Output = field(default_factory=Output)
    precision: str = "float32"
    description: str = ""
    scene: dict = field(default_factory=dict)

    # ------------------------------------------------------------------ checks
    def validate(self) -> Scenario:
        """Check every field before any kernel runs; return a normalised copy."""
        d = self.domain
        lo = vector3("domain.lo", d.lo)
        hi = vector3("domain.hi", d.hi)
        for a in range(3):
            if hi[a] <= lo[a]:
                raise InvalidArgument(f"domain.hi[{a}]", hi[a], f"a number > domain.lo[{a}] = {lo[a]:g}")
        dx = finite_number("domain.dx", d.dx, lo=0.0, lo_open=True)
        ncell = [(hi[a] - lo[a]) / dx for a in range(3)]
        if max(ncell) > 4096:
            raise InvalidArgument("domain.dx", d.dx,
                                  f"a spacing giving at most 4096 cells per axis (got {max(ncell):.0f})")
        choice("domain.boundary", d.boundary, (*WALL_KINDS, "none"))
        finite_number("domain.friction", d.friction, lo=0.0)
        if not isinstance(d.boundary_faces, str) or not set(d.boundary_faces) <= set("xyz"):
            raise InvalidArgument("domain.boundary_faces", d.boundary_faces, "letters among 'xyz'")
        dom = Domain(lo, hi, dx, d.boundary, float(d.friction), d.boundary_faces)

        t = self.time
        end = finite_number("time.end", t.end, lo=0.0, lo_open=True)
        fi = finite_number("time.frame_interval", t.frame_interval, lo=0.0, lo_open=True)
        cfl = finite_number("time.cfl", t.cfl, lo=0.0, hi=1.0, lo_open=True)
        dt = finite_number("time.dt", t.dt, lo=0.0)
        dt_max = finite_number("time.dt_max", t.dt_max, lo=0.0)
        g = vector3("time.gravity", t.gravity)
        ramp = finite_number("time.gravity_ramp", t.gravity_ramp, lo=0.0)
        damp = finite_number("time.damping", t.damping, lo=0.0)
        damp_until = finite_number("time.damping_until", t.damping_until, lo=0.0)
        tc = TimeControl(end, fi, cfl, dt, dt_max, g, ramp, damp, damp_until)

        if not self.materials:
            raise InvalidArgument("materials", {}, "at least one material")
        mats = {}
        for name, m in self.materials.items():
            if isinstance(m, dict):
                m = material_from_dict(m, f"materials.{name}")
            elif isinstance(m, Elastic):
                m = m.validate(f"materials.{name}")
            else:
                raise InvalidArgument(f"materials.{name}", m, "an Elastic or CamClaySnow material, or a dict")
            mats[name] = m

        if not self.blocks:
            raise InvalidArgument("blocks", [], "at least one block of particles")
        blocks = []
        for i, b in enumerate(self.blocks):
            w = f"blocks[{i}]"
            if b.material not in mats:
                raise InvalidArgument(f"{w}.material", b.material, "one of " + ", ".join(map(repr, mats)))
            blo = vector3(f"{w}.lo", b.lo)
            bhi = vector3(f"{w}.hi", b.hi)
            for a in range(3):
                if bhi[a] <= blo[a]:
                    raise InvalidArgument(f"{w}.hi[{a}]", bhi[a], f"a number > {w}.lo[{a}] = {blo[a]:g}")
                if blo[a] < lo[a] - 1e-9 * dx or bhi[a] > hi[a] + 1e-9 * dx:
                    raise InvalidArgument(f"{w}.lo/hi[{a}]", (blo[a], bhi[a]),
                                          f"inside the domain [{lo[a]:g}, {hi[a]:g}] (particles inside the grid)")
            ppc = positive_int(f"{w}.particles_per_cell", b.particles_per_cell, lo=1, hi=8)
            vel = b.velocity if callable(b.velocity) else vector3(f"{w}.velocity", b.velocity)
            blocks.append(Block(b.material, blo, bhi, vel, ppc, b.name or f"block{i}"))

        walls = tuple(w.validate(f"walls[{i}]") for i, w in enumerate(self.walls))
        out = self.output
        if not isinstance(out.fields, (list, tuple)):
            raise InvalidArgument("output.fields", out.fields, "a list of field names, e.g. [\"x\", \"v\"]")
        for f_ in out.fields:
            choice("output.fields[]", f_, tuple(OUTPUT_FIELDS))
        positive_int("output.checkpoint_every", out.checkpoint_every, lo=0)
        positive_int("output.health_every", out.health_every, lo=1)
        outp = Output(tuple(dict.fromkeys(("x", *out.fields))), out.checkpoint_every, out.health_every)
        choice("precision", self.precision, PRECISIONS)
        return replace(self, domain=dom, time=tc, materials=mats, blocks=tuple(blocks), walls=walls,
                       output=outp)

    # ----------------------------------------------------------- serialising
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
                       "health_every": self.output.health_every},
        }
        for b in self.blocks:
            bd = asdict(b)
            if callable(b.velocity):
                # a Python velocity field cannot be serialised; the state (checkpoints) carries it
                bd["velocity"] = [0.0, 0.0, 0.0]
            d["blocks"].append(bd)
        if self.scene:
            d["scene"] = copy.deepcopy(self.scene)
        return json.loads(json.dumps(d, default=list))

    @classmethod
    def from_dict(cls, raw: dict, source: str = "scenario") -> Scenario:
        """Build and validate a scenario from a plain dict (as read from TOML)."""
        raw = copy.deepcopy(raw)
        _check_keys(raw, {"name", "description", "precision", "domain", "time", "materials", "blocks", "walls",
                          "output", "scene"}, "", source)
        for req in ("domain", "time", "materials", "blocks"):
            if req not in raw:
                raise ScenarioError(f"{source}: missing section [{req}]")
        dom = _section(Domain, raw["domain"], "domain", source)
        tim = _section(TimeControl, raw["time"], "time", source)
        out = _section(Output, raw.get("output", {}), "output", source)
        if not isinstance(raw["materials"], dict):
            raise ScenarioError(f"{source}: [materials] must be a table of named materials")
        mats = {}
        for k, v in raw["materials"].items():
            if not isinstance(v, dict):
                raise ScenarioError(f"{source}: materials.{k} must be a table")
            mats[k] = material_from_dict(v, f"materials.{k}")
        blocks = [_section(Block, b, f"blocks[{i}]", source)
                  for i, b in enumerate(_table_list(raw["blocks"], "blocks", source))]
        walls = [_section(Wall, w, f"walls[{i}]", source)
                 for i, w in enumerate(_table_list(raw.get("walls", []), "walls", source))]
        sc = cls(name=str(raw.get("name", "scenario")), domain=dom, time=tim, materials=mats, blocks=tuple(blocks),
                 walls=tuple(walls), output=out, precision=raw.get("precision", "float32"),
                 description=str(raw.get("description", "")), scene=raw.get("scene", {}))
        return sc.validate()


def _table_list(v, name, source):
    if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
        raise ScenarioError(f"{source}: {name} must be an array of tables ([[{name}]])")
    return v


def _check_keys(d: dict, allowed: set, prefix: str, source: str):
    for k in d:
        if k not in allowed:
            close = difflib.get_close_matches(k, sorted(allowed), n=1)
            hint = f" (did you mean '{prefix}{close[0]}'?)" if close else ""
            raise ScenarioError(f"{source}: unknown key '{prefix}{k}'{hint}; allowed: {', '.join(sorted(allowed))}")


def _section(cls, d, where: str, source: str):
    if not isinstance(d, dict):
        raise ScenarioError(f"{source}: [{where}] must be a table")
    names = {f.name for f in fields(cls)}
    _check_keys(d, names, where + ".", source)
    required = [f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING]
    for r in required:
        if r not in d:
            raise ScenarioError(f"{source}: {where}.{r} is missing")
    for k, v in d.items():
        if isinstance(v, float) and math.isnan(v):
            raise InvalidArgument(f"{where}.{k}", v, "a number, not NaN")
        if isinstance(v, list):
            d[k] = tuple(v)
    return cls(**d)


def apply_overrides(raw: dict, overrides: list[str] | dict) -> dict:
    """Apply ``section.key=value`` overrides to a raw scenario dict.

    Values are parsed as TOML literals (``1e6``, ``[0, -9.81, 0]``, ``"slip"``);
    a bare word is taken as a string. ``blocks.0.material=snow`` indexes arrays.
    """
    raw = copy.deepcopy(raw)
    items = overrides.items() if isinstance(overrides, dict) else [_split(o) for o in overrides]
    for key, value in items:
        if isinstance(value, str):
            try:
                value = tomllib.loads(f"v = {value}")["v"]
            except tomllib.TOMLDecodeError:
                pass
        parts = key.split(".")
        node = raw
        for p in parts[:-1]:
            if isinstance(node, list):
                try:
                    node = node[int(p)]
                except (ValueError, IndexError):
                    raise ScenarioError(f"override {key!r}: no element {p!r} (the list has {len(node)})") from None
            elif isinstance(node, dict):
                node = node.setdefault(p, {})
            else:
                raise ScenarioError(f"override {key!r}: {p!r} is below a value ({node!r}), not a table")
        last = parts[-1]
        if isinstance(node, list):
            try:
                node[int(last)] = value
            except (ValueError, IndexError):
                raise ScenarioError(f"override {key!r}: no element {last!r} (the list has {len(node)})") from None
        elif isinstance(node, dict):
            node[last] = value
        else:
            raise ScenarioError(f"override {key!r}: {last!r} is below a value ({node!r}), not a table")
    return raw


def _split(o: str):
    if "=" not in o:
        raise ScenarioError(f"override {o!r}: expected key=value")
    k, v = o.split("=", 1)
    return k.strip(), v.strip()


def read_scenario_dict(path_or_name: str) -> tuple[dict, str]:
    """Read a scenario TOML file (a path, or the name of a scene in ``scenarios/``)."""
    path = path_or_name
    if not os.path.exists(path):
        from . import scenarios_dir

        fname = path_or_name if path_or_name.endswith(".toml") else path_or_name + ".toml"
        cand = os.path.join(scenarios_dir(), fname)
        if not os.path.exists(cand):
            raise ScenarioError(f"scenario {path_or_name!r} not found (neither a file nor a scene in "
                                f"{scenarios_dir()}; known scenes: {', '.join(list_scenes())})")
        path = cand
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh), path
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(f"{path}: not valid TOML: {e}") from None


def list_scenes() -> list[str]:
    """Names of the ready scenes shipped in ``scenarios/``."""
    from . import scenarios_dir

    return sorted(f[:-5] for f in os.listdir(scenarios_dir()) if f.endswith(".toml"))


def load_scenario(path_or_name: str, overrides=None) -> Scenario:
    """Load, override and validate a scenario file or ready scene by name."""
    raw, path = read_scenario_dict(path_or_name)
    if overrides:
        raw = apply_overrides(raw, overrides)
    from .scenes import expand_scene

    raw = expand_scene(raw, path)
    return Scenario.from_dict(raw, source=path)
