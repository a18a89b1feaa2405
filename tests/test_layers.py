"""The package imports only downward (docs/architecture.md): no cycle, no upward import, every package installed.

Layers, bottom to top: kernels -> engine -> validation (reference problems) -> scenes -> loader and runner
-> post-processing -> field data (real pits as scenes) -> studies (what the benchmarks share) -> CLI and sweeps
-> the package facade ``mpm_warp/__init__.py``. Every ``import`` in every module counts, also those inside
functions (a late import is still a dependency).
"""

from __future__ import annotations

import ast
import os
import sys

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PACKAGES = {"mpm_warp": "mpm_warp", "mpm_warp.kernels": "kernels"}
LAYERS = ["kernels", "engine", "validation", "scenes", "scene API", "post", "field", "studies", "CLI and sweeps",
          "facade"]


#: the layer of each top-level package or module named after its layer or not (the rest is the engine)
TOP_LAYER = {"kernels": "kernels", "validation": "validation", "scenes": "scenes", "loader": "scene API",
             "runner": "scene API", "post": "post", "field": "field", "studies": "studies",
             **dict.fromkeys(("cli", "cli_field", "docgen", "sweep", "sweep_summary"), "CLI and sweeps")}


def layer(module: str) -> int:
    """Index in :data:`LAYERS` of a module of the package."""
    if module == "mpm_warp":
        return LAYERS.index("facade")
    return LAYERS.index(TOP_LAYER.get(module.split(".")[1], "engine"))


def modules() -> dict[str, str]:
    """Module name -> file of every module of the package (``kernels/`` installs as ``mpm_warp.kernels``)."""
    out = {}
    for pkg, folder in PACKAGES.items():
        for dirpath, _, names in os.walk(os.path.join(ROOT, folder)):
            for f in names:
                if f.endswith(".py"):
                    rel = os.path.relpath(os.path.join(dirpath, f), os.path.join(ROOT, folder))[:-3]
                    rel = rel.replace(os.sep, ".")
                    name = pkg if rel == "__init__" else pkg + "." + rel.removesuffix(".__init__")
                    out[name] = os.path.join(dirpath, f)
    return out


def imports(mods: dict[str, str]) -> tuple[dict[str, set], dict[str, set]]:
    """``(internal, external)``: per module the package modules it imports and the top-level external names."""
    internal, external = {}, {}
    for name, path in mods.items():
        is_pkg = path.endswith("__init__.py")
        internal[name], external[name] = set(), set()
        for node in ast.walk(ast.parse(open(path).read(), path)):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = name.split(".")[: len(name.split(".")) - node.level + (1 if is_pkg else 0)]
                    prefix = ".".join(base + ([node.module] if node.module else []))
                else:
                    prefix = node.module
                # "from pkg import sub" imports the submodule; "from pkg import name" the package itself
                targets = [f"{prefix}.{a.name}" if f"{prefix}.{a.name}" in mods else prefix for a in node.names]
            else:
                continue
            for t in targets:
                while t not in mods and "." in t and t.split(".")[0] == "mpm_warp":
                    t = t.rsplit(".", 1)[0]      # "import mpm_warp.io.hdf5.x" -> the module that exists
                if t in mods:
                    if t != name:
                        internal[name].add(t)
                else:
                    external[name].add(t.split(".")[0])
    return internal, external


def upward(internal: dict[str, set]) -> list[str]:
    """Every import of a module from a higher layer."""
    return [f"{m} ({LAYERS[layer(m)]}) imports {t} ({LAYERS[layer(t)]})"
            for m, ts in sorted(internal.items()) for t in sorted(ts) if layer(t) > layer(m)]


def cycles(internal: dict[str, set]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in internal.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in internal:
        if v not in index:
            visit(v)
    return out


def test_the_checker_sees_upward_imports_and_cycles():
    graph = {"mpm_warp.model": {"mpm_warp.scenes.pst"}, "mpm_warp.scenes.pst": {"mpm_warp.config"},
             "mpm_warp.config": {"mpm_warp.model"}, "mpm_warp.post.plots": {"mpm_warp.cli"}}
    assert upward(graph) == [
        "mpm_warp.model (engine) imports mpm_warp.scenes.pst (scenes)",
        "mpm_warp.post.plots (post) imports mpm_warp.cli (CLI and sweeps)"]
    assert cycles(graph) == [["mpm_warp.config", "mpm_warp.model", "mpm_warp.scenes.pst"]]


def test_no_cycle_and_no_upward_import():
    mods = modules()
    assert {"mpm_warp.simulation", "mpm_warp.scenes.pst.monitor", "mpm_warp.kernels.p2g", "mpm_warp.post.fields",
            "mpm_warp.loader", "mpm_warp.cli", "mpm_warp.studies.convergence"} <= mods.keys()
    internal, _ = imports(mods)
    assert upward(internal) == []
    assert cycles(internal) == []


def test_kernels_import_only_warp_the_standard_library_and_kernels():
    mods = modules()
    internal, external = imports(mods)
    for m in mods:
        if layer(m) == LAYERS.index("kernels"):
            assert all(layer(t) == LAYERS.index("kernels") for t in internal[m]), m
            assert external[m] <= {"warp"} | set(sys.stdlib_module_names), (m, external[m])


def test_studies_sit_above_the_scenes_and_below_the_cli():
    internal, _ = imports(modules())
    assert layer("mpm_warp.studies.convergence") == LAYERS.index("studies")
    assert LAYERS.index("scene API") < LAYERS.index("studies") < LAYERS.index("CLI and sweeps")
    assert internal["mpm_warp.studies.blocks"] >= {"mpm_warp.simulation", "mpm_warp.studies.plastic_block"}
    assert not any(t.startswith("mpm_warp.studies") for m, ts in internal.items() for t in ts
                   if not m.startswith("mpm_warp.studies"))      # nothing in the library depends on a study


def test_engine_knows_no_scene():
    internal, _ = imports(modules())
    engine = [m for m in internal if layer(m) == LAYERS.index("engine")]
    assert "mpm_warp.simulation" in engine and "mpm_warp.config" in engine
    for m in engine:
        assert not any(t.startswith(("mpm_warp.scenes", "mpm_warp.post", "mpm_warp.loader", "mpm_warp.runner"))
                       for t in internal[m]), m


def test_every_package_is_installed():
    """pyproject lists packages by name: a new subpackage must be listed (a plain install must work)."""
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        listed = set(tomllib.load(fh)["tool"]["setuptools"]["packages"])
    found = {m for m, p in modules().items() if p.endswith("__init__.py")} | {"mpm_warp.scenarios"}
    assert found == listed
