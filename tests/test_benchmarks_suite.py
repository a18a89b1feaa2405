"""benchmarks/ is a suite: scripts that import the package (never sys.path), tests that never import a script,
one protocol (``--quick`` writes its JSON with the environment record elsewhere than the committed results), an
index that lists every file, no file over 400 lines; the cheap scripts' quick modes run here."""

import ast
import glob
import json
import os
import re
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(ROOT, "benchmarks")
FILES = sorted(os.path.relpath(p, BENCH) for p in glob.glob(os.path.join(BENCH, "*", "*.py")))
GROUPS = ("perf", "convergence", "snow", "field", "robustness")


def _source(rel: str) -> str:
    with open(os.path.join(BENCH, rel)) as fh:
        return fh.read()


def _is_script(rel: str) -> bool:
    return 'if __name__ == "__main__":' in _source(rel)


#: every file is a benchmark: what scripts share, and the Taichi peer they run as a child, live in the package
#: (benchmarks/README.md, "Shared code")
SCRIPTS = [f for f in FILES if _is_script(f)]


def test_the_suite_is_grouped_by_question():
    assert {f.split("/")[0] for f in FILES} == set(GROUPS)
    assert not glob.glob(os.path.join(BENCH, "*.py"))             # no script outside a group
    for g in GROUPS:
        assert os.path.isdir(os.path.join(BENCH, g, "results"))
    # the benchmarks are exactly the scripts benchmarks/README.md gives a question and a command (47 today), and no
    # other file is left: a script that loses its __main__, or a new one left out of the index, fails
    with open(os.path.join(BENCH, "README.md")) as fh:
        rows = [line for line in fh if re.match(r"^\| `[a-z_]+/[a-z_0-9]+\.py` \|", line)]
    indexed = {re.match(r"^\| `([^`]+)`", line).group(1): line.count(" | ") >= 4 for line in rows}
    assert sorted(SCRIPTS) == sorted(f for f, benchmark in indexed.items() if benchmark)
    assert sorted(set(FILES) - set(SCRIPTS)) == sorted(f for f, benchmark in indexed.items() if not benchmark)
    assert len(SCRIPTS) == 47


@pytest.mark.parametrize("rel", FILES)
def test_no_benchmark_uses_sys_path_and_imports_only_the_package_or_a_sibling(rel):
    src = _source(rel)
    assert "sys.path" not in src, rel
    group = rel.split("/")[0]
    siblings = {os.path.splitext(os.path.basename(f))[0] for f in FILES if f.startswith(group + "/")}
    others = {os.path.splitext(os.path.basename(f))[0] for f in FILES} - siblings
    for node in ast.walk(ast.parse(src, rel)):
        names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                 else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
        for name in names:
            top = name.split(".")[0]
            assert top not in others | {"benchmarks", "common", "tests"}, f"{rel} imports {name}"


def test_no_test_imports_a_benchmark():
    scripts = {os.path.splitext(os.path.basename(f))[0] for f in FILES}
    for path in glob.glob(os.path.join(ROOT, "tests", "*.py")):
        src = open(path).read()
        for node in ast.walk(ast.parse(src, path)):
            if isinstance(node, ast.Attribute):       # sys.path, importlib.util.spec_from_file_location
                assert node.attr != "spec_from_file_location", path
                assert not (node.attr == "path" and isinstance(node.value, ast.Name) and node.value.id == "sys"), path
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            for name in names:
                assert name.split(".")[0] not in scripts | {"benchmarks"}, f"{path} imports {name}"


#: a script that is one call of the package's whole command line (its protocol, its environment record), tested
#: there: the field what-ifs (mpm_warp.studies.field_what_if, tests/test_field_what_if.py)
DELEGATED = "what_if_main(__doc__, __file__,"


@pytest.mark.parametrize("rel", SCRIPTS)
def test_every_script_has_the_protocol(rel):
    src = _source(rel)
    if DELEGATED in src:
        return
    assert "argparse" in src or "parser(__doc__" in src, rel
    assert '"--quick"' in src or "parser(__doc__" in src, rel
    assert "environment(" in src, rel                           # the JSON carries the environment record


def test_the_index_lists_every_file_with_its_command():
    with open(os.path.join(BENCH, "README.md")) as fh:
        index = fh.read()
    for rel in FILES:
        assert f"`{rel}`" in index, rel
    for rel in SCRIPTS:
        assert f"python benchmarks/{rel}" in index, rel
    assert "bash benchmarks/device_suite.sh" in index


def test_no_file_of_the_suite_is_over_400_lines():
    paths = [os.path.join(BENCH, f) for f in FILES] + glob.glob(os.path.join(ROOT, "mpm_warp", "studies", "*.py")) \
        + glob.glob(os.path.join(ROOT, "mpm_warp", "studies", "*", "*.py"))
    for p in paths:
        with open(p) as fh:
            assert sum(1 for _ in fh) <= 400, p


#: the quick modes run here (44 s of CPU time in all, kernels compiled; benchmarks/README.md): script, extra
#: arguments and the files it writes. Not run here (benchmarks/README.md says why): perf/pst_plane_strain.py,
#: perf/device_suite.py (tests/test_device_suite.py runs it), snow/pst.py, snow/critical_cut.py, snow/wf_sweep.py,
#: snow/speed_trends.py (PST runs of a minute or more each).
QUICK = {
    "perf/throughput.py": ([], ["throughput_cpu_quick.json", "throughput_cpu_quick.png"]),
    "perf/leave_out.py": ([], ["leave_out_cpu_quick.json"]),
    "perf/bonded_return_cost.py": ([], ["bonded_return_cost_cpu_quick.json"]),
    "perf/return_cost.py": ([], ["return_cost_cpu_quick.json"]),
    "perf/plastic_step.py": (["--no-taichi"], ["plastic_step_cpu_quick.json"]),
    "convergence/error_vs_runtime.py": ([], ["error_vs_runtime_quick.json", "error_vs_runtime_quick.md",
                                             "error_vs_runtime_quick.png"]),
    "convergence/mesh_study.py": ([], ["mesh_study_quick.json", "mesh_study_quick.png"]),
    "convergence/error_vs_runtime_snow.py": ([], ["error_vs_runtime_snow_quick.json",
                                                  "error_vs_runtime_snow_quick.png"]),
    "snow/shear_test.py": ([], ["snow_shear_test_quick.json", "snow_shear_test_quick.png"]),
    "snow/interface_stress.py": ([], ["interface_stress_cpu_quick.json", "interface_stress_cpu_quick.png"]),
    "field/forecast.py": ([], ["field_forecast.json", "field_forecast.png"]),
}


@pytest.mark.slow
@pytest.mark.parametrize("rel", sorted(QUICK))
def test_quick_mode_writes_its_json_with_the_environment_elsewhere(rel, tmp_path):
    extra, files = QUICK[rel]
    committed = os.path.join(BENCH, rel.split("/")[0], "results")
    before = {f: os.path.getmtime(os.path.join(committed, f)) for f in os.listdir(committed)}
    env = dict(os.environ, MPM_WARP_THREADS="1")
    proc = subprocess.run([sys.executable, os.path.join(BENCH, rel), "--quick", "--out", str(tmp_path), *extra],
                          capture_output=True, text=True, timeout=300, env=env, cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert sorted(os.listdir(tmp_path)) == sorted(files)
    with open(tmp_path / files[0]) as fh:
        data = json.load(fh)
    envr = data["environment"]
    assert envr["device"] == "cpu" and re.match(r"\d{4}-\d\d-\d\d", envr["date"]) and envr["warp"]
    assert len(envr["load_average_1_5_15_min"]) == 3
    assert {f: os.path.getmtime(os.path.join(committed, f)) for f in os.listdir(committed)} == before
