"""The scenario key reference in ``docs/scenarios.md``, generated from the parameter dataclasses.

Every table of a scenario file (``[domain]``, ``[time]``, ``[output]``, ``[materials.NAME]`` per model,
``[[blocks]]``, ``[[walls]]``, and each scene kind's ``[scene]`` with its nested tables) is one Markdown
table: key, type, default, unit, range and description. Types and defaults come from the dataclass fields,
units and descriptions from their NumPy-style docstrings, ranges from the checks the code runs
(:func:`.dataclass_doc.check_ranges` over the validating functions' source). Nothing is typed in here but
the order of the tables and the functions that check each.
"""

from __future__ import annotations

from .. import config
from ..config import Block, Domain, Output, TimeControl
from ..loader import TOP_LEVEL_KEYS
from ..materials import MATERIAL_MODELS
from ..scenes import SCENES
from ..scenes.snow import MIN_WEAK_LAYER_CELLS, check_plane_strain
from ..walls import Wall
from .dataclass_doc import check_ranges, field_docs

__all__ = ["keys_lines", "BEGIN", "END"]

BEGIN = "<!-- keys:begin -->"
END = "<!-- keys:end -->"
HEADER = ["| key | type | default | unit | range | what it is |", "|---|---|---|---|---|---|"]


def _validators(cls) -> list:
    """The ``validate`` methods ``cls`` and its bases define (a subclass's checks add to its base's)."""
    return [k.__dict__["validate"] for k in reversed(cls.__mro__) if "validate" in k.__dict__]


def _table(cls, ranges: dict[str, list[str]], prefix: str = "", extra: dict[str, str] | None = None) -> list[str]:
    """The Markdown rows of ``cls``'s fields; ``ranges`` by dotted key below the scene table (``prefix``)."""
    rows = list(HEADER)
    for f in field_docs(cls):
        rng = list(ranges.get(prefix + f.name, []))
        if extra and f.name in extra:
            rng.append(extra[f.name])
        typ = f"table `[{f.nested.__name__}]`" if f.type == "table" else (
            f"list of `[{f.nested.__name__}]`" if f.nested is not None else f.type)
        rows.append(f"| `{f.name}` | {typ} | {f.default if f.default == 'required' else f'`{f.default}`'} | "
                    f"{f.unit} | {', '.join(rng)} | {f.text} |")
    return rows


def _nested(cls, ranges: dict[str, list[str]], table: str, prefix: str, level: str, seen: set) -> list[str]:
    """The tables of ``cls``'s nested fields (``[table.key]``, ``[[table.key]]``), each once per scene."""
    out = []
    for f in field_docs(cls):
        if f.nested is None:
            continue
        brackets = ("[[", "]]") if f.type == "list of tables" else ("[", "]")
        name = f"{table}.{f.name}"
        out += ["", f"{level} `{brackets[0]}{name}{brackets[1]}`: `{f.nested.__name__}`", ""]
        if f.nested in seen:
            out.append(f"The keys of `{f.nested.__name__}` above.")
            continue
        seen.add(f.nested)
        r = {**ranges, **{prefix + f.name + "." + k: v for k, v in check_ranges(*_validators(f.nested)).items()}}
        out += _table(f.nested, r, prefix + f.name + ".")
        out += _nested(f.nested, r, name, prefix + f.name + ".", level, seen)
    return out


def _plain_tables() -> list[str]:
    out = ["### The tables of a plain scene", "",
           "Top-level keys of a scenario file: " + ", ".join(f"`{k}`" for k in TOP_LEVEL_KEYS)
           + " (`mpm_warp.loader.TOP_LEVEL_KEYS`). `precision` is one of "
           + ", ".join(f'`"{p}"`' for p in config.PRECISIONS) + "; `[calibration]` is written by a scene's builder "
           "into run files, never read from a scenario file.", ""]
    for title, cls, fns in (("[domain]", Domain, (config._domain,)), ("[time]", TimeControl, (config._time,)),
                            ("[output]", Output, (config.Scenario.validate,)), ("[[blocks]]", Block, (config._block,)),
                            ("[[walls]]", Wall, (Wall.validate,))):
        out += [f"#### `{title}`: `{cls.__name__}`", ""] + _table(cls, check_ranges(*fns)) + [""]
    out += ["`output.fields` names any of: " + ", ".join(f"`{k}` ({unit}, {what})" for k, (_, unit, what)
                                                          in config.OUTPUT_FIELDS.items()) + ".", ""]
    out += [f"#### `[materials.NAME]`: one of {len(MATERIAL_MODELS)} models", "",
            "`model` picks the model (`mpm_warp.materials.MATERIAL_MODELS`; default `\"elastic\"`); the other keys "
            "are its fields.", ""]
    for model, cls in MATERIAL_MODELS.items():
        doc = (cls.__doc__ or "").strip().split("\n")[0]
        out += [f"##### `model = \"{model}\"`: `{cls.__name__}`", "", doc, ""]
        out += _table(cls, check_ranges(*_validators(cls))) + [""]
    return out


def _scene_tables() -> list[str]:
    out = []
    wl_cells = {"weak_layer_thickness": f">= {MIN_WEAK_LAYER_CELLS:g} dx"}
    for kind, st in SCENES.items():
        if st.params is None:
            continue
        ranges = check_ranges(*_validators(st.params), check_plane_strain)
        out += [f"### `[scene] kind = \"{kind}\"`: `{st.params.__name__}`", "", st.description + ".",
                f"The scene sets `[time]` {', '.join(f'`{k}`' for k in st.time_keys)} itself (a file may not give "
                "them)." if st.time_keys else "", ""]
        out += _table(st.params, ranges, extra=wl_cells if "weak_layer_thickness" in ranges else None)
        out += _nested(st.params, ranges, "scene", "", "####", set())
        out.append("")
    return out


def keys_lines() -> list[str]:
    """The lines of the key reference (between :data:`BEGIN` and :data:`END` in ``docs/scenarios.md``)."""
    lines = ["Generated from the parameter dataclasses by `python -m mpm_warp.docgen` (types and "
             "defaults from the fields, units and text from their docstrings, ranges from the checks the loader "
             "runs; a range given as another key, such as `2 dx`, is relative to that key's value). A unit `-` "
             "is dimensionless.", ""]
    lines += _plain_tables() + _scene_tables()
    while lines and lines[-1] == "":
        lines.pop()
    return lines
