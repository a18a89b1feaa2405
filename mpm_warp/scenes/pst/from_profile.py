"""A PST's snowpack from a CAAML snow profile: the ``[scene.profile]`` table into layers (docs/profiles.md).

The loader expands ``[scene.profile]`` once, when it reads a scenario file (:func:`expand_profile`): the
layers above the named weak layer become ``slab_layers`` (density measured or from hand hardness and
grain, E from the density), the weak layer gives ``weak_layer_thickness`` (and its density, when the
profile has one), the layers below it ``substratum_layers`` down to ``substratum_depth``; the profile's
slope and the column length of its PST record are taken unless the file gives them. Profiles record
thicknesses vertically; the model's are bed-normal, ``h cos(slope)``. The expanded layers and the
profile's SHA-256 go into every run file, so a resume never reads the profile again.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
import os
from dataclasses import dataclass
from typing import Literal

from ...checks import check_choices, finite_number, positive_int
from ...errors import InvalidArgument

__all__ = ["ProfileSource", "expand_profile", "profile_table", "follow_grid", "CELLS_ACROSS"]

#: grid cells across the weak layer when the scene file gives no dx (the resolution the snow ladders call resolved)
CELLS_ACROSS = 4


@dataclass(frozen=True)
class ProfileSource:
    """Where a PST's snowpack comes from (``[scene.profile]``).

    Attributes
    ----------
    file : str
        A CAAML 5 or 6 XML snow profile, relative to the scenario file (or absolute); "" = no profile.
    weak_layer_depth : float
        The weak layer by its depth below the surface (m, as the profile records it); 0 = not given.
    weak_layer_index : int
        The weak layer by its index in the profile, from 1 (the layer under the surface layer); 0 = not
        given: the slab ends at its top. Neither given: the depth of the profile's first PST result.
    weak_layer_thickness : float
        The weak layer's thickness (m, as the profile records lengths), >= 0; 0 = by the rules of
        :mod:`mpm_warp.scenes.profile.column` (the profile layer's when it is thin, else 3 cm).
    substratum_depth : float
        How much of the profile below the weak layer to model (m, bed-normal), >= 0; 0 = the scene's
        ``substratum_thickness``.
    thickness : {"vertical", "slope_normal"}
        How the profile's depths and thicknesses were measured: vertically (CAAML's convention, the default)
        or normal to the slope.
    sha256 : str
        The profile file's SHA-256 (hex), written by the loader when it expands the table.
    weak_layer : str
        The chosen weak layer as the profile describes it (written by the loader).
    """

    file: str = ""
    weak_layer_depth: float = 0.0
    weak_layer_index: int = 0
    weak_layer_thickness: float = 0.0
    substratum_depth: float = 0.0
    thickness: Literal["vertical", "slope_normal"] = "vertical"
    sha256: str = ""
    weak_layer: str = ""

    def validate(self, where: str = "scene.profile") -> ProfileSource:
        """Check every value (InvalidArgument naming ``where.field``); return self."""
        if not isinstance(self.file, str):
            raise InvalidArgument(f"{where}.file", self.file, "a path to a CAAML file, or '' for none")
        finite_number(f"{where}.weak_layer_depth", self.weak_layer_depth, lo=0.0)
        positive_int(f"{where}.weak_layer_index", self.weak_layer_index, lo=0)
        finite_number(f"{where}.weak_layer_thickness", self.weak_layer_thickness, lo=0.0, hi=0.5)
        finite_number(f"{where}.substratum_depth", self.substratum_depth, lo=0.0)
        check_choices(self, where)
        return self


def profile_table(table: dict) -> dict:
    """The ``[scene.profile]`` table of a scene table, or {}."""
    prof = table.get("profile") or {}
    if not isinstance(prof, dict):
        raise InvalidArgument("scene.profile", prof, "a table: [scene.profile] file = ..., weak_layer_depth = ...")
    return prof


def expand_profile(table: dict, base_dir: str = ".") -> dict:
    """A ``[scene]`` table with its ``[scene.profile]`` read into layers (module docstring); unchanged without one.

    Raises
    ------
    InvalidArgument
        A profile beside ``slab_layers``, ``substratum_layers``, ``slab``, ``slab_thickness`` or
        ``weak_layer_thickness`` given in the file (the profile gives them); a weak layer not named and no PST
        result to name it; and everything :func:`~mpm_warp.scenes.profile.read_profile` and
        :func:`~mpm_warp.scenes.profile.select_weak_layer` refuse, in one line naming the layer.
    """
    prof = profile_table(table)
    if "file" in prof and isinstance(prof["file"], str) and not prof["file"].strip():
        defaults = {f.name: f.default for f in dataclasses.fields(ProfileSource)}
        if any(prof.get(k, v) != v for k, v in defaults.items() if k != "file"):
            raise InvalidArgument("scene.profile.file", prof["file"], "a path to a CAAML file (an empty path reads no "
                                  "profile; leave [scene.profile] out to run without one)")
    if not prof.get("file"):
        return table
    from ..profile import read_profile, select_weak_layer
    from ..profile.column import describe, profile_column

    keys = [f.name for f in dataclasses.fields(ProfileSource)]
    unknown = sorted(set(prof) - set(keys))
    if unknown:
        raise InvalidArgument(f"scene.profile.{unknown[0]}", prof[unknown[0]], "a key of [scene.profile]: "
                              + ", ".join(keys))
    src = ProfileSource(**prof)
    src.validate()
    for key in ("slab_layers", "substratum_layers", "slab", "slab_thickness", "weak_layer_thickness"):
        if key in table:
            raise InvalidArgument(f"scene.{key}", table[key], "left out when scene.profile.file is given (the "
                                  "profile gives the slab, the weak layer's thickness and the layers below)")
    path = src.file if os.path.isabs(src.file) else os.path.join(base_dir, src.file)
    data = read_profile(path)
    depth = src.weak_layer_depth or None
    if src.weak_layer_index:
        _, weak, _ = select_weak_layer(data, index=src.weak_layer_index)
        depth = weak.depth_top
    if depth is None:
        rec = next((t for t in data.pst_tests if t.depth is not None), None)
        if rec is None:
            raise InvalidArgument("scene.profile.weak_layer_depth", 0.0, (
                "the weak layer's depth (m) or scene.profile.weak_layer_index: the profile records no PST depth"))
        depth = rec.depth
    bottom = data.layers[-1].depth_bottom
    if not 0.0 < depth < bottom:
        raise InvalidArgument("scene.profile.weak_layer_depth", depth, f"a depth in (0, {bottom:.4g}) m below the "
                              "surface: inside the described layers, with a slab above it")
    out = copy.deepcopy(table)
    slope = float(out.get("slope_angle", data.slope_angle if data.slope_angle is not None else 0.0))
    out["slope_angle"] = slope
    scale = math.cos(math.radians(slope)) if src.thickness == "vertical" else 1.0
    keep = float(src.substratum_depth or out.get("substratum_thickness", 0.15))
    col = profile_column(data, depth, src.weak_layer_thickness or None, keep / scale)
    out["slab_layers"] = [_layer(p, scale) for p in col.slab]
    out["weak_layer_thickness"] = col.weak_layer_thickness * scale
    weak = col.weak_layer
    if weak.density is not None and "density" not in (out.get("weak_layer") or {}):
        out.setdefault("weak_layer", {})["density"] = float(weak.density)
    if col.substratum:
        out["substratum_layers"] = [_layer(p, scale) for p in col.substratum]
        out.pop("substratum_thickness", None)
    rec = next((t for t in data.pst_tests if t.column_length), None)
    if "length" not in out and rec is not None:
        out["length"] = float(rec.column_length)
    follow_grid(out)
    with open(path, "rb") as fh:
        digest = hashlib.sha256(fh.read()).hexdigest()
    out["profile"] = {**prof, "sha256": digest, "weak_layer": f"{describe(col)}; in {weak.describe()}: {_name(weak)}"}
    return out


def follow_grid(table: dict) -> None:
    """The grid and margin a column needs, where the table does not give them: ``dx`` resolves the weak layer with
    :data:`CELLS_ACROSS` cells, the margin is at least 2 dx (``table``, a ``[scene]`` table, is changed)."""
    if "dx" not in table:
        table["dx"] = table["weak_layer_thickness"] / CELLS_ACROSS
    if "margin" not in table:
        table["margin"] = max(0.05, 2.0 * table["dx"])


def _name(ly) -> str:
    grains = "/".join(g for g in (ly.grain_1, ly.grain_2) if g)
    return " ".join(s for s in (grains, ly.hardness or "") if s) or f"layer {ly.index}"


def _layer(part, scale: float) -> dict:
    """A column part as a ``slab_layers`` entry: bed-normal thickness, density; E from the density."""
    return {"thickness": part.thickness * scale, "density": part.density, "name": part.name}
