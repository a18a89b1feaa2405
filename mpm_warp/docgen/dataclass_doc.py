"""What the code says about a parameter dataclass: its fields' types and defaults, the units and text of its
NumPy-style docstring, and the ranges its checks enforce (read from the source of the check functions).

Used by :mod:`.keys_doc` to write the scenario key reference; nothing here is typed in by hand.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import re
import textwrap
import typing
from dataclasses import dataclass

__all__ = ["FieldDoc", "field_docs", "check_ranges", "UNITS"]

#: the units the docstrings use, as they write them; a parenthesis whose first items are among these gives a unit
UNITS = ("m", "s", "Pa", "-", "deg", "m/s", "1/s", "m/s^2", "kg/m^3", "J/m^2", "J/m^3", "m^2")
#: the check functions whose arguments state a range (mpm_warp.checks)
RANGE_CHECKS = ("finite_number", "positive_int")


@dataclass(frozen=True)
class FieldDoc:
    """One field of a parameter dataclass as its code describes it.

    Attributes
    ----------
    name : str
        The field (the scenario file's key).
    type : str
        The type in a scenario file's words (number, integer, true/false, string, a choice, a list).
    default : str
        The default as TOML writes it; "required" without one; "table" for a nested parameter table.
    unit : str
        The unit the docstring gives (empty when none).
    text : str
        The docstring's description, Sphinx roles reduced to their names.
    nested : type or None
        The dataclass of a nested table (or of the entries of a list of tables).
    """

    name: str
    type: str
    default: str
    unit: str
    text: str
    nested: type | None = None


def _clean(text: str) -> str:
    """Docstring text for a Markdown cell: roles to their last name, one line, no pipes."""
    text = re.sub(r":(?:class|func|meth|mod|data|attr):`~?([^`]*?)`", lambda m: "`" + m.group(1).split(".")[-1] + "`",
                  text)
    return " ".join(text.split()).replace("|", "\\|")


def _units(text: str) -> list[str]:
    """The units a description names, in order: the leading items of each parenthesis that are units."""
    out = []
    for group in re.findall(r"\(([^()]*)\)", text):
        for item in (s.strip() for s in group.split(",")):
            if item not in UNITS:
                break
            out.append(item)
    return out


def docstring_entries(cls) -> dict[str, str]:
    """``{name: description}`` of the ``Attributes`` (or ``Parameters``) section of ``cls``'s own docstring;
    an entry naming several fields (``E, nu, density : float``) gives each the same description."""
    doc = inspect.cleandoc(cls.__dict__.get("__doc__") or "")
    m = re.search(r"^(Attributes|Parameters)\n-+\n(.*?)(?:\n\n[A-Z][a-z]+\n-+\n|\Z)", doc, re.S | re.M)
    if m is None:
        return {}
    out, names, lines = {}, [], []

    def flush():
        for n in names:
            out[n] = "\n".join(lines)
    for line in m.group(2).splitlines():
        if line and not line.startswith(" "):
            flush()
            names = [n.strip() for n in line.split(" : ")[0].split(",")]
            lines = []
        else:
            lines.append(line.strip())
    flush()
    return out


def _type_name(hint) -> tuple[str, type | None]:
    """A type hint in a scenario file's words, and the dataclass of a nested table (or list of tables)."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is typing.Literal:
        return " \\| ".join(f'"{a}"' if isinstance(a, str) else str(a) for a in args), None
    if dataclasses.is_dataclass(hint):
        return "table", hint
    if origin is tuple and args and dataclasses.is_dataclass(args[0]):
        return "list of tables", args[0]
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        named = [a for a in args if a is not type(None)]
        return _type_name(named[0])[0] + " (optional)", None
    if origin is tuple or hint is tuple or hint is typing.Any:
        return "list of numbers", None
    return {float: "number", int: "integer", bool: "true/false", str: "string"}.get(hint, str(hint)), None


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return "none" if value is None else str(value)


def _unit(name: str, entries: dict[str, str]) -> str:
    """The unit of ``name`` in a docstring's entries: its entry's one unit, or its place in a shared entry's."""
    text = entries.get(name)
    if text is None:
        return ""
    names = [n for n, t in entries.items() if t == text]
    units = _units(text)
    if len(units) == len(names) > 1:
        return units[names.index(name)]
    return units[0] if len(units) == 1 else ""


def field_docs(cls) -> list[FieldDoc]:
    """Every init field of the dataclass ``cls``, in order, as :class:`FieldDoc`.

    Raises
    ------
    ValueError
        A field the docstring does not describe (the reference would show it without a word).
    """
    hints = typing.get_type_hints(cls)
    chain = [docstring_entries(k) for k in cls.__mro__ if dataclasses.is_dataclass(k)]
    out = []
    for f in dataclasses.fields(cls):
        if not f.init:
            continue
        entries = next((e for e in chain if f.name in e), {})
        if f.name not in entries:
            raise ValueError(f"{cls.__module__}.{cls.__qualname__}: field {f.name!r} is not in its docstring")
        text = entries[f.name]
        typ, nested = _type_name(hints[f.name])
        if f.default is not dataclasses.MISSING:
            default = _toml(f.default)
        elif f.default_factory is not dataclasses.MISSING:
            default = "table" if nested is not None and typ == "table" else _toml(f.default_factory())
        else:
            default = "required"
        unit = next((u for u in (_unit(f.name, e) for e in chain) if u), "")
        out.append(FieldDoc(f.name, typ, default, unit, _clean(text), nested))
    return out


# ------------------------------------------------------------------------------------------ ranges
def _key(node: ast.AST, loop: dict[str, str]) -> str | None:
    """The dotted key a check names: the text after the f-string's leading ``{where}.`` (or ``section.``)."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        text = node.value
    elif isinstance(node, ast.JoinedStr):
        parts = []
        for i, v in enumerate(node.values):
            if isinstance(v, ast.Constant):
                parts.append(v.value)
            elif i == 0:
                parts.append("")          # the table's own name ({where}, {w})
            elif isinstance(v, ast.FormattedValue) and isinstance(v.value, ast.Name) and v.value.id in loop:
                parts.append(loop[v.value.id])
            else:
                return None
        text = "".join(parts)
    else:
        return None
    text = text.split(" ")[0]                       # "substratum_thickness (of the layers)"
    return text.split(".", 1)[1] if "." in text else text


def _expr(node: ast.AST | None, names: dict[str, str]) -> str | None:
    """A bound's source, local names replaced by the keys they hold and ``2.0 * dx`` written ``2 dx``."""
    if node is None:
        return None
    if isinstance(node, ast.Constant):
        return "none" if node.value is None else f"{node.value:g}" if isinstance(node.value, (int, float)) else None
    text = ast.unparse(node)
    text = re.sub(r"\b[A-Za-z_]\w*\b", lambda m: names.get(m.group(0), m.group(0)), text)
    text = re.sub(r"(\d+)\.0\b", r"\1", text)
    return text.replace(" * ", " ")


def _render(call: ast.Call, names: dict[str, str]) -> str:
    kw = {k.arg: k.value for k in call.keywords}
    is_int = call.func.id == "positive_int"
    lo = _expr(kw.get("lo"), names) if "lo" in kw else ("1" if is_int else None)
    hi = _expr(kw.get("hi"), names)
    lo_open = isinstance(kw.get("lo_open"), ast.Constant) and kw["lo_open"].value is True
    hi_open = isinstance(kw.get("hi_open"), ast.Constant) and kw["hi_open"].value is True
    what = "integer " if is_int else ""
    if lo is not None and hi is not None:
        return f"{what}in {'(' if lo_open else '['}{lo}, {hi}{')' if hi_open else ']'}"
    if lo is not None:
        return f"{what}{'>' if lo_open else '>='} {lo}"
    if hi is not None:
        return f"{what}{'<' if hi_open else '<='} {hi}"
    return "finite" if not is_int else "integer"


def _built(call: ast.AST, fn) -> tuple[type, dict[str, str]] | None:
    """The dataclass a ``Cls(self.a, b=self.c)`` (or ``self.method()`` returning one) builds, and ``{its field:
    our field}`` of the arguments it takes from ``self``; None for anything else."""
    if not isinstance(call, ast.Call):
        return None
    f = call.func
    if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name) and f.value.id == "self" and not call.args:
        owner = fn.__globals__.get(fn.__qualname__.split(".")[0])
        method = getattr(owner, f.attr, None)
        if method is None or not inspect.isfunction(method):
            return None
        tree = ast.parse(textwrap.dedent(inspect.getsource(method)))
        ret = [n.value for n in ast.walk(tree) if isinstance(n, ast.Return)]
        return _built(ret[0], method) if ret else None
    cls = fn.__globals__.get(f.id) if isinstance(f, ast.Name) else None
    if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
        return None
    names = [x.name for x in dataclasses.fields(cls) if x.init]
    pairs = list(zip(names, call.args, strict=False)) + [(k.arg, k.value) for k in call.keywords]
    return cls, {ours: theirs.attr for ours, theirs in pairs if isinstance(theirs, ast.Attribute)
                 and isinstance(theirs.value, ast.Name) and theirs.value.id == "self"}


def _delegated(node: ast.AST, fn, out: dict[str, list[str]]) -> None:
    """The ranges a ``Cls(self.x, ...).validate(where)`` checks, for the fields passed on from ``self``."""
    if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "validate"):
        return
    built = _built(node.func.value, fn)
    if built is None:
        return
    cls, passed = built
    for key, ranges in check_ranges(*[k.__dict__["validate"] for k in reversed(cls.__mro__)
                                      if "validate" in k.__dict__]).items():
        if key in passed:
            out.setdefault(passed[key], []).extend(r for r in ranges if r not in out.get(passed[key], []))


def _walk(body: list[ast.stmt], loop: dict[str, str], names: dict[str, str], out: dict[str, list[str]],
          fn) -> None:
    for stmt in body:
        if isinstance(stmt, ast.For) and isinstance(stmt.target, ast.Name) and isinstance(stmt.iter, ast.Tuple):
            for elt in stmt.iter.elts:
                if isinstance(elt, ast.Constant) and isinstance(elt.value, str):
                    _walk(stmt.body, {**loop, stmt.target.id: elt.value}, names, out, fn)
            continue
        for node in ast.walk(stmt):
            _delegated(node, fn, out)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in RANGE_CHECKS \
                    and node.args:
                key = _key(node.args[0], loop)
                if key is not None:
                    rng = _render(node, names)
                    if rng not in out.setdefault(key, []):
                        out[key].append(rng)
        if isinstance(stmt, ast.Assign) and len(stmt.targets) == 1 and isinstance(stmt.targets[0], ast.Name) \
                and isinstance(stmt.value, ast.Call) and getattr(stmt.value.func, "id", "") in RANGE_CHECKS:
            key = _key(stmt.value.args[0], loop)
            if key is not None:
                names[stmt.targets[0].id] = key


def check_ranges(*functions) -> dict[str, list[str]]:
    """``{dotted key: [range, ...]}`` of every ``finite_number``/``positive_int`` call in the functions' source.

    A key is the check's field name less its table (``f"{where}.saw.speed"`` gives ``saw.speed``); a bound
    that is a local holding another checked value is written as that key (``lo=2.0 * dx`` gives ``2 dx``).
    """
    out: dict[str, list[str]] = {}
    for fn in functions:
        tree = ast.parse(textwrap.dedent(inspect.getsource(fn)))
        _walk(tree.body[0].body, {}, {}, out, fn)
    return out
