"""Walls: planes that constrain grid velocities (docs/model.md §5).

A :class:`Wall` is a plane through ``point`` with ``normal`` pointing into the
material. Kinds: ``"sticky"`` (no relative motion), ``"slip"`` (no normal
relative motion, free tangential) and ``"separate"`` (contact that may open,
with Coulomb friction ``friction``). A wall may move with ``velocity``,
reached after a linear ramp of ``ramp_time`` seconds; the motion is evaluated
on the device from the simulation clock.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Literal, get_args

from .checks import choice, finite_number, vector

__all__ = ["Wall", "WallKind", "WALL_KINDS", "box_walls"]

WallKind = Literal["sticky", "slip", "separate"]
#: the wall kinds, in the order of their kernel codes (0 sticky, 1 slip, 2 separate): the one list of them
WALL_KINDS: tuple[str, ...] = get_args(WallKind)


@dataclass(frozen=True)
class Wall:
    """A plane wall.

    Parameters
    ----------
    point : (dim,) float
        A point of the plane at t = 0 (m).
    normal : (dim,) float
        Normal pointing into the material (normalised on validation).
    kind : {"sticky", "slip", "separate"}
        Boundary condition.
    friction : float
        Coulomb coefficient (-), used by ``"separate"``; >= 0.
    velocity : (dim,) float or None
        Prescribed wall velocity (m/s); None = at rest.
    ramp_time : float
        Time (s) over which the velocity ramps up linearly from zero; 0 = at once.
    name : str
        Name used in the output (wall forces).
    """

    point: tuple
    normal: tuple
    kind: WallKind = "slip"
    friction: float = 0.0
    velocity: tuple | None = None
    ramp_time: float = 0.0
    name: str = "wall"

    def validate(self, where: str = "wall", dim: int = 3) -> Wall:
        """Return a checked copy with a unit normal; raise InvalidArgument on bad fields.

        ``dim`` is the scene's dimension: every vector has ``dim`` components.
        """
        p = vector(f"{where}.point", self.point, dim)
        n = vector(f"{where}.normal", self.normal, dim, nonzero=True)
        norm = math.sqrt(sum(c * c for c in n))
        n = tuple(c / norm for c in n)
        choice(f"{where}.kind", self.kind, WALL_KINDS)
        finite_number(f"{where}.friction", self.friction, lo=0.0)
        v = vector(f"{where}.velocity", (0.0,) * dim if self.velocity is None else self.velocity, dim)
        finite_number(f"{where}.ramp_time", self.ramp_time, lo=0.0)
        return Wall(p, n, self.kind, float(self.friction), v, float(self.ramp_time), str(self.name))

    @property
    def kind_id(self) -> int:
        """Integer code used by the kernels (0 sticky, 1 slip, 2 separate)."""
        return WALL_KINDS.index(self.kind)

    def to_dict(self) -> dict:
        """Plain dict (for scenario files and output attributes)."""
        d = asdict(self)
        for k in ("point", "normal", "velocity"):
            d[k] = list(d[k])
        return d


def box_walls(lo, hi, kind: WallKind = "slip", friction: float = 0.0, faces: str = "xyz") -> list[Wall]:
    """The faces of the box ``[lo, hi]`` (2 or 3 components) as walls with inward normals.

    ``faces`` selects the axes whose two faces are walls (e.g. ``"xz"``); axes
    beyond the box's dimension are ignored.
    """
    names = "xyz"
    dim = len(lo)
    walls = []
    for a in range(dim):
        if names[a] not in faces:
            continue
        n = [0.0] * dim
        n[a] = 1.0
        walls.append(Wall(tuple(lo), tuple(n), kind, friction, name=f"{names[a]}_lo"))
        n = [0.0] * dim
        n[a] = -1.0
        walls.append(Wall(tuple(hi), tuple(n), kind, friction, name=f"{names[a]}_hi"))
    return walls
