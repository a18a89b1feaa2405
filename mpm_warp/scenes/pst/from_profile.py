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

__all__ = ["ProfileSource", "expand_profile", "profile_table"]


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
        given. Neither given: the depth of the profile's first PST result.
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
    if not prof.get("file"):
        return table
    from ..profile import read_profile, select_weak_layer

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
    depth, index = src.weak_layer_depth or None, src.weak_layer_index or None
    if depth is None and index is None:
        rec = next((t for t in data.pst_tests if t.depth is not None), None)
        if rec is None:
            raise InvalidArgument("scene.profile.weak_layer_depth", 0.0, (
                "the weak layer's depth (m) or scene.profile.weak_layer_index: the profile records no PST depth"))
        depth = rec.depth
    slab, weak, below = select_weak_layer(data, depth=depth, index=index)
    out = copy.deepcopy(table)
    slope = float(out.get("slope_angle", data.slope_angle if data.slope_angle is not None else 0.0))
    out["slope_angle"] = slope
    scale = math.cos(math.radians(slope)) if src.thickness == "vertical" else 1.0
    out["slab_layers"] = [_layer(ly, scale) for ly in slab]
    out["weak_layer_thickness"] = weak.thickness * scale
    if weak.density is not None and "density" not in (out.get("weak_layer") or {}):
        out.setdefault("weak_layer", {})["density"] = float(weak.density)
    keep = float(src.substratum_depth or out.get("substratum_thickness", 0.15))
    sub, total = [], 0.0
    for ly in below:
        if total >= keep - 1e-12:
            break
        h = min(ly.thickness * scale, keep - total)
        sub.append({**_layer(ly, scale), "thickness": h})
        total += h
    if sub:
        out["substratum_layers"] = sub
        out.pop("substratum_thickness", None)
    rec = next((t for t in data.pst_tests if t.column_length), None)
    if "length" not in out and rec is not None:
        out["length"] = float(rec.column_length)
    with open(path, "rb") as fh:
        digest = hashlib.sha256(fh.read()).hexdigest()
    out["profile"] = {**prof, "sha256": digest, "weak_layer": f"{weak.describe()}: {_name(weak)}"}
    return out


def _name(ly) -> str:
    grains = "/".join(g for g in (ly.grain_1, ly.grain_2) if g)
    return " ".join(s for s in (grains, ly.hardness or "") if s) or f"layer {ly.index}"


def _layer(ly, scale: float) -> dict:
    """A profile layer as a ``slab_layers`` entry: bed-normal thickness, density; E from the density."""
    return {"thickness": ly.thickness * scale, "density": float(ly.density),
            "name": f"{_name(ly)}, {ly.density:.0f} kg/m3 ({'measured' if ly.measured else 'from hardness'})"}
