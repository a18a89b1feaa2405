"""Reading scenarios: TOML files and ready scenes, ``--set`` overrides, strict keys, scene expansion.

Parameters are layered as in pyro2: the defaults of the typed configuration
(:mod:`mpm_warp.config`, a scene's parameter dataclass), then the file, then ``section.key=value``
overrides (``--set`` on the command line). Reading is strict: an unknown or misspelt key fails
with its dotted name, a did-you-mean and the valid keys; a missing one with its name; a wrong type
or out-of-range value with the field, the value and the range (:class:`InvalidArgument`).

A file with a ``[scene]`` table (``kind = "pst"``, ``"shear_test"``) is expanded by that scene's
builder through the registry :data:`mpm_warp.scenes.SCENES`; the scene then generates the
domain, materials, blocks, walls and its ``[time]`` keys, and its typed parameters go into
:attr:`Scenario.scene`. Layering: this module sits above the scenes (it imports their registry),
the engine below never imports it.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import math
import os
import stat
import typing
from importlib.resources import files

from .config import Block, Domain, Output, Scenario, TimeControl
from .errors import InvalidArgument, ScenarioError
from .materials import MATERIAL_MODELS, Elastic
from .scenes import scene_type
from .walls import Wall

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["load_scenario", "scenario_from_dict", "resolved_scenario", "scene_params_from_dict", "apply_overrides",
           "split_override", "read_scenario_dict", "scenario_path", "list_scenes", "scenarios_dir", "from_table",
           "material_from_table", "TOP_LEVEL_KEYS", "GENERATED_SECTIONS"]

#: keys of a scenario file's top level
TOP_LEVEL_KEYS = ("name", "description", "precision", "domain", "time", "materials", "blocks", "walls", "output",
                  "scene", "calibration")
#: sections a scene generates (a file with a scene may not give them)
GENERATED_SECTIONS = ("domain", "materials", "blocks", "walls")


# ------------------------------------------------------------------------------ strict tables
def check_keys(d: dict, allowed, prefix: str, source: str) -> None:
    """:class:`ScenarioError` for the first key of ``d`` not in ``allowed``, with a did-you-mean."""
    for k in d:
        if k not in allowed:
            close = difflib.get_close_matches(str(k), sorted(allowed), n=1)
            hint = f" (did you mean '{prefix}{close[0]}'?)" if close else ""
            raise ScenarioError(f"{source}: unknown key '{prefix}{k}'{hint}; allowed: {', '.join(sorted(allowed))}")


def from_table(cls, table, where: str, source: str = "scenario"):
    """A dataclass ``cls`` from a TOML table, strictly: unknown keys, missing required keys and NaN fail.

    Nested dataclass fields are read from sub-tables; lists become tuples. Values are checked by the
    dataclass's own ``validate`` later (types, ranges, ``Literal`` choices).
    """
    if not isinstance(table, dict):
        raise ScenarioError(f"{source}: [{where}] must be a table")
    hints = typing.get_type_hints(cls)
    fields = [f for f in dataclasses.fields(cls) if f.init]
    check_keys(table, {f.name for f in fields}, where + ".", source)
    for f in fields:
        if f.name not in table and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ScenarioError(f"{source}: {where}.{f.name} is missing")
    kwargs = {}
    for k, v in table.items():
        hint = hints[k]
        if isinstance(v, float) and math.isnan(v):
            raise InvalidArgument(f"{where}.{k}", v, "a number, not NaN")
        item = _tuple_item(hint)
        if isinstance(hint, type) and dataclasses.is_dataclass(hint):
            v = from_table(hint, v, f"{where}.{k}", source)
        elif item is not None:
            v = tuple(from_table(item, t, f"{where}.{k}[{i}]", source)
                      for i, t in enumerate(_table_list(v, f"{where}.{k}", source)))
        elif isinstance(v, list):
            v = tuple(v)
        kwargs[k] = v
    return cls(**kwargs)


def _tuple_item(hint):
    """The dataclass ``D`` of a ``tuple[D, ...]`` field (an array of tables), else None."""
    args = typing.get_args(hint)
    if typing.get_origin(hint) is tuple and args and isinstance(args[0], type) and dataclasses.is_dataclass(args[0]):
        return args[0]
    return None


def material_from_table(d, where: str = "material", source: str = "scenario") -> Elastic:
    """A material from its table: ``model`` (default "elastic") picks the class, the rest are its fields."""
    if not isinstance(d, dict):
        raise ScenarioError(f"{source}: {where} must be a table")
    d = dict(d)
    model = d.pop("model", "elastic")
    if not isinstance(model, str) or model not in MATERIAL_MODELS:
        raise ScenarioError(f"{source}: {where}.model = {model!r} is unknown: expected one of "
                            f"{sorted(MATERIAL_MODELS)}")
    return from_table(MATERIAL_MODELS[model], d, where, source).validate(where)


def _table_list(v, name: str, source: str) -> list:
    if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
        raise ScenarioError(f"{source}: {name} must be an array of tables ([[{name}]])")
    return v


# --------------------------------------------------------------------------------- scenarios
def scene_params_from_dict(table: dict, source: str = "scenario"):
    """The typed parameters of a ``[scene]`` table (its ``kind`` picks the scene), checked."""
    if not isinstance(table, dict):
        raise ScenarioError(f"{source}: [scene] must be a table")
    st = scene_type(table.get("kind"), source)
    table = {k: v for k, v in table.items() if k != "kind"}
    if st.upgrade is not None:
        table = st.upgrade(copy.deepcopy(table))
    params = from_table(st.params, table, "scene", source)
    return params.validate("scene")


def _common(raw: dict, source: str) -> dict:
    out = {"name": str(raw.get("name", "scenario")), "precision": raw.get("precision", "float32"),
           "output": from_table(Output, raw.get("output", {}), "output", source)}
    if "time" not in raw:
        raise ScenarioError(f"{source}: missing section [time]")
    return out


def _plain(raw: dict, source: str) -> Scenario:
    for req in ("domain", "time", "materials", "blocks"):
        if req not in raw:
            raise ScenarioError(f"{source}: missing section [{req}]")
    common = _common(raw, source)
    if not isinstance(raw["materials"], dict):
        raise ScenarioError(f"{source}: [materials] must be a table of named materials")
    mats = {k: material_from_table(v, f"materials.{k}", source) for k, v in raw["materials"].items()}
    blocks = [from_table(Block, b, f"blocks[{i}]", source)
              for i, b in enumerate(_table_list(raw["blocks"], "blocks", source))]
    walls = [from_table(Wall, w, f"walls[{i}]", source)
             for i, w in enumerate(_table_list(raw.get("walls", []), "walls", source))]
    return Scenario(domain=from_table(Domain, raw["domain"], "domain", source),
                    time=from_table(TimeControl, raw["time"], "time", source), materials=mats, blocks=tuple(blocks),
                    walls=tuple(walls), description=str(raw.get("description", "")), **common)


def scenario_from_dict(raw: dict, source: str = "scenario") -> Scenario:
    """Build and validate a scenario from a scenario file's content (a dict as read from TOML).

    With a ``[scene]`` table of a registered kind the scene's builder makes the domain, materials,
    blocks, walls and its ``[time]`` keys; ``kind = "blocks"`` (or no ``[scene]``) uses the file as written.
    """
    raw = copy.deepcopy(raw)
    check_keys(raw, TOP_LEVEL_KEYS, "", source)
    if "calibration" in raw:
        raise ScenarioError(f"{source}: [calibration] is written by a scene's builder (run files); set the scene's "
                            "parameters in [scene]")
    table = raw.get("scene")
    if table is not None and not isinstance(table, dict):
        raise ScenarioError(f"{source}: [scene] must be a table")
    if not table or table.get("kind", "blocks") == "blocks":
        return _plain(raw, source).validate()
    st = scene_type(table.get("kind"), source)
    for k in GENERATED_SECTIONS:
        if k in raw:
            raise ScenarioError(f"{source}: [{k}] is generated by scene.kind = {st.kind!r}; set its parameters in "
                                "[scene]")
    common = _common(raw, source)
    if isinstance(raw["time"], dict):
        for k in st.time_keys:
            if k in raw["time"]:
                raise ScenarioError(f"{source}: time.{k} is set by the {st.kind} scene; use [scene.settle] / "
                                    "scene.slope_angle")
    time = from_table(TimeControl, raw["time"], "time", source)
    for key, value in table.items():     # as written by the user: a run file of an older release may hold []
        if key.endswith("_layers") and isinstance(value, list) and not value:
            raise InvalidArgument(f"scene.{key}", value, f"at least one layer ([[scene.{key}]] thickness = ..., "
                                  "density = ...); leave the key out for the default")
    if st.expand is not None:
        base = os.path.dirname(os.path.abspath(source)) if os.path.isfile(source) else os.getcwd()
        table = st.expand(table, base)
    params = scene_params_from_dict(table, source)
    sc = st.build(params, time, common["output"], name=common["name"], precision=common["precision"],
                  description=str(raw.get("description", "")))
    return sc.validate()


def resolved_scenario(d: dict, source: str = "scenario") -> Scenario:
    """A :meth:`Scenario.to_dict` back into its Scenario (run files, checkpoints): nothing is rebuilt.

    The generated sections are read as stored and the ``scene`` table becomes the scene's typed
    parameters again.
    """
    d = copy.deepcopy(d)
    table = d.pop("scene", None)
    calibration = d.pop("calibration", None)
    check_keys(d, TOP_LEVEL_KEYS, "", source)
    sc = _plain(d, source)
    if table:
        params = scene_params_from_dict(table, source)
        if calibration is None:  # a run file of an older release: derive what it did not store, once
            calibration = scene_type(params.kind).build(params, sc.time).calibration
        sc = dataclasses.replace(sc, scene=params, calibration=calibration)
    return sc.validate()


# --------------------------------------------------------------------------------- overrides
def split_override(o: str) -> tuple[str, str]:
    """``"key=value"`` -> ``("key", "value")``; :class:`ScenarioError` without ``=``."""
    if not isinstance(o, str) or "=" not in o:
        raise ScenarioError(f"override {o!r}: expected key=value")
    k, v = o.split("=", 1)
    return k.strip(), v.strip()


def apply_overrides(raw: dict, overrides: list[str] | dict) -> dict:
    """Apply ``section.key=value`` overrides to a raw scenario dict (a copy).

    Values are parsed as TOML literals (``1e6``, ``[0, -9.81, 0]``, ``"slip"``); a bare word is
    taken as a string. ``blocks.0.material=snow`` indexes arrays. ``overrides`` is a list (or tuple)
    of ``"key=value"`` strings, a dict ``{key: value}``, or one ``"key=value"`` string.
    """
    raw = copy.deepcopy(raw)
    if isinstance(overrides, str):
        overrides = [overrides]
    if isinstance(overrides, dict):
        bad = [k for k in overrides if not isinstance(k, str)]
        if bad:
            raise InvalidArgument("overrides", overrides, f"a dict with 'section.key' strings as keys, not {bad[0]!r}")
        items = overrides.items()
    elif isinstance(overrides, (list, tuple)):
        items = [split_override(o) for o in overrides]
    else:
        raise InvalidArgument("overrides", overrides, "a list of 'section.key=value' strings, a dict "
                              "{'section.key': value} or one 'section.key=value' string")
    for key, value in items:
        if isinstance(value, str):
            try:
                value = tomllib.loads(f"v = {value}")["v"]
            except tomllib.TOMLDecodeError:
                pass
        parts = key.split(".")
        node = raw
        for p in parts[:-1]:
            node = _child(node, p, key)
        _assign(node, parts[-1], value, key)
    return raw


def _child(node, p: str, key: str):
    if isinstance(node, list):
        try:
            return node[int(p)]
        except (ValueError, IndexError):
            raise ScenarioError(f"override {key!r}: no element {p!r} (the list has {len(node)})") from None
    if isinstance(node, dict):
        return node.setdefault(p, {})
    raise ScenarioError(f"override {key!r}: {p!r} is below a value ({node!r}), not a table")


def _assign(node, last: str, value, key: str) -> None:
    if isinstance(node, list):
        try:
            node[int(last)] = value
        except (ValueError, IndexError):
            raise ScenarioError(f"override {key!r}: no element {last!r} (the list has {len(node)})") from None
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise ScenarioError(f"override {key!r}: {last!r} is below a value ({node!r}), not a table")


# ------------------------------------------------------------------------------------- files
def scenarios_dir() -> str:
    """Folder of the ready scenes (TOML files)."""
    return str(files("mpm_warp.scenarios"))


def list_scenes() -> list[str]:
    """Names of the ready scenes shipped in ``scenarios/``."""
    return sorted(f[:-5] for f in os.listdir(scenarios_dir()) if f.endswith(".toml"))


def scenario_path(path_or_name) -> str:
    """The TOML file of a scenario path or of a ready scene's name; :class:`ScenarioError` when neither exists.

    A path that is not a regular file or a folder (a FIFO, a device, a socket) is refused here, before
    anything opens it (opening a FIFO without a writer would wait for ever).
    """
    if isinstance(path_or_name, os.PathLike):
        path_or_name = os.fspath(path_or_name)
    if not isinstance(path_or_name, str) or not path_or_name:
        raise InvalidArgument("scenario", path_or_name, "a Scenario, a scenario file path (str or os.PathLike) or "
                              "the name of a ready scene (mpm-warp scenes)")
    path = path_or_name
    if os.path.exists(path):
        mode = os.stat(path).st_mode
        if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
            raise ScenarioError(f"{path}: is not a regular file (a FIFO, a device or a socket): a scenario is read "
                                "from a TOML file")
        return path
    fname = path if path.endswith(".toml") else path + ".toml"
    cand = os.path.join(scenarios_dir(), fname)
    if not os.path.exists(cand):
        raise ScenarioError(f"scenario {path_or_name!r} not found (neither a file nor a scene in "
                            f"{scenarios_dir()}; known scenes: {', '.join(list_scenes())})")
    return cand


def read_scenario_dict(path_or_name: str) -> tuple[dict, str]:
    """Read a scenario TOML file (a path, or the name of a ready scene): ``(raw dict, path)``.

    Whatever the file holds (binary bytes, UTF-16 text, arrays nested hundreds deep, a folder),
    the error is one :class:`ScenarioError` line naming the file.
    """
    path = scenario_path(path_or_name)
    if os.path.isdir(path):
        raise ScenarioError(f"{path}: is a directory, not a scenario file")
    try:
        with open(path, "rb") as fh:
            raw = tomllib.load(fh)
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(f"{path}: not valid TOML: {e}") from None
    except UnicodeDecodeError as e:
        raise ScenarioError(f"{path}: not valid TOML: not UTF-8 text (byte {e.start}: "
                            f"{e.object[e.start:e.start + 1]!r}; binary data or another encoding such as UTF-16)") \
            from None
    except RecursionError:
        raise ScenarioError(f"{path}: not valid TOML for a scenario: arrays or tables nested too deeply") from None
    except OSError as e:
        raise ScenarioError(f"{path}: cannot be read ({e.strerror})") from None
    if _nesting(raw) > MAX_NESTING:
        raise ScenarioError(f"{path}: not valid TOML for a scenario: arrays or tables nested too deeply "
                            f"(more than {MAX_NESTING} levels; a scenario needs 4)")
    return raw, path


#: the deepest nesting of arrays and tables a scenario file may have (a scenario needs 4)
MAX_NESTING = 16


def _nesting(obj) -> int:
    """How deeply arrays and tables nest in ``obj`` (0 for a scalar), without recursion."""
    deepest, stack = 0, [(obj, 0)]
    while stack:
        node, depth = stack.pop()
        if isinstance(node, dict | list):
            depth += 1
            deepest = max(deepest, depth)
            stack.extend((v, depth) for v in (node.values() if isinstance(node, dict) else node))
    return deepest


def load_scenario(path_or_name, overrides=None) -> Scenario:
    """Load, override and validate a scenario file or a ready scene by name."""
    raw, path = read_scenario_dict(path_or_name)
    try:
        if overrides:
            raw = apply_overrides(raw, overrides)
        return scenario_from_dict(raw, source=path)
    except RecursionError:
        raise ScenarioError(f"{path}: not valid TOML for a scenario: arrays or tables nested too deeply") from None
