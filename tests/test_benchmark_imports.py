"""No script under ``benchmarks/`` imports another: what two scripts share lives in the package, where it is tested.

Each ``benchmarks/**/*.py`` is parsed with ``ast``; an import whose top-level name is the stem of a file under
``benchmarks/`` (``from closure import draw``), an import of ``benchmarks`` itself, or a way around the import
statement (``sys.path``, ``importlib``, ``runpy``, ``__import__``, ``spec_from_file_location``) fails it, with no
exception (the block benchmarks' shared code and Taichi peer are ``mpm_warp.studies.perf``).
"""

from __future__ import annotations

import ast
import glob
import os

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: names that load code from a path or a string instead of an import statement
_AROUND = {"path", "importlib", "runpy", "__import__", "spec_from_file_location", "import_module", "run_path"}


def script_imports(root: str) -> dict[str, list[str]]:
    """Per file under ``root/benchmarks`` (its path under ``benchmarks/``), what in it imports another script or
    goes around the import statement: one line each, empty where it does neither."""
    bench = os.path.join(root, "benchmarks")
    files = sorted(glob.glob(os.path.join(bench, "**", "*.py"), recursive=True))
    stems = {os.path.splitext(os.path.basename(f))[0] for f in files}
    out = {}
    for path in files:
        rel = os.path.relpath(path, bench).replace(os.sep, "/")
        with open(path) as fh:
            tree = ast.parse(fh.read(), rel)
        bad = []
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = ["." if node.level else node.module or ""]
            else:
                names = []
            bad += [f"line {node.lineno}: imports {n}" for n in names
                    if n == "." or n.split(".")[0] in stems | {"benchmarks"}]
            if isinstance(node, ast.Attribute) and node.attr in _AROUND and not (
                    node.attr == "path" and not (isinstance(node.value, ast.Name) and node.value.id == "sys")):
                bad.append(f"line {node.lineno}: {ast.unparse(node)}")
            if isinstance(node, ast.Name) and node.id in _AROUND - {"path"}:
                bad.append(f"line {node.lineno}: {node.id}")
            if isinstance(node, (ast.Import, ast.ImportFrom)) and any(
                    n.split(".")[0] in ("importlib", "runpy") for n in names):
                bad.append(f"line {node.lineno}: imports {names[0]}")
        out[rel] = bad
    return out


def test_no_benchmark_script_imports_another():
    found = script_imports(ROOT)
    assert len(found) >= 44, "the benchmark scripts were not found"
    bad = {rel: lines for rel, lines in found.items() if lines}
    assert not bad, f"scripts that import scripts (move what they share into the package): {bad}"


@pytest.mark.parametrize("source, what", [
    ("from closure import draw\n", "imports closure"),
    ("import slab_fe as fe\n", "imports slab_fe"),
    ("from . import closure\n", "imports ."),
    ("import sys\nsys.path.insert(0, 'x')\n", "sys.path"),
    ("import importlib\nm = importlib.import_module('closure')\n", "importlib"),
    ("m = __import__('closure')\n", "__import__"),
    ("import benchmarks.field.closure\n", "imports benchmarks"),
])
def test_the_check_finds_a_script_that_imports_a_script(tmp_path, source, what):
    field = tmp_path / "benchmarks" / "field"
    field.mkdir(parents=True)
    (field / "closure.py").write_text("X = 1\n")
    (field / "strength.py").write_text(source)
    (field / "slab_fe.py").write_text("import os\nfrom mpm_warp.field.studies.drawn import draw_rows\np = os.path\n")
    found = script_imports(str(tmp_path))
    assert any(what in line for line in found["field/strength.py"]), found
    assert found["field/closure.py"] == [] and found["field/slab_fe.py"] == []
