"""A missing optional package (mpm_warp.extras): every command that imports one says in one line which package and
which extra, with exit status 2 and no traceback; the extras named in code are pyproject.toml's."""

from __future__ import annotations

import importlib.metadata as md
import os
import re
import subprocess
import sys

import pytest

from mpm_warp.errors import MPMError
from mpm_warp.extras import COMMAND_EXTRA, CORE, EXTRAS, extra_for, missing_line, missing_module, require
from mpm_warp.scenes import weac_reference as wr
from mpm_warp.studies.fresh_clone import FIELD_TABLE, plain_field_verdict

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CAAML = os.path.join(ROOT, "scenarios", "profiles", "example_pst.caaml")
SNOWPILOT = os.path.join(ROOT, "tests", "data", "snowpilot", "snowpits-17459-caaml.xml")
# runs mpm-warp with the top-level modules in argv[1] hidden, as on an install without them
BLOCKED = """
import sys
hidden = set(sys.argv[1].split(","))
class Hide:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in hidden:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
sys.meta_path.insert(0, Hide())
from mpm_warp.cli import main
sys.exit(main(sys.argv[2:]))
"""


def _distributions(requirements: list[str]) -> set[str]:
    """Normalised distribution names of requirement strings, with those their extras bring by the same name
    (``dask[distributed]`` brings the ``distributed`` distribution)."""
    out = set()
    for req in requirements:
        m = re.match(r"([A-Za-z0-9_.-]+)(?:\[([^\]]*)\])?", req)
        out |= {re.sub(r"[-_.]+", "-", n.strip()).lower() for n in [m.group(1), *(m.group(2) or "").split(",")] if n}
    return out


def test_the_extras_in_code_are_pyprojects():
    """Each module :data:`EXTRAS` names comes from a distribution its extra lists, and each distribution an extra
    lists gives at least one of its modules; ``[test]`` brings everything ``[field]`` does."""
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        project = tomllib.load(fh)["project"]
    extras = project["optional-dependencies"]
    provides = md.packages_distributions()
    for extra, modules in EXTRAS.items():
        dists = _distributions(extras[extra])
        given = {mod: {re.sub(r"[-_.]+", "-", d).lower() for d in provides.get(mod, [])} for mod in modules}
        assert all(given[mod] & dists for mod in modules), (extra, given, dists)
        assert dists == set().union(*given.values()) & dists, (extra, dists)
    assert _distributions(extras["field"]) <= _distributions(extras["test"])
    assert "scikit-learn" in _distributions(extras["field"])
    core = _distributions(project["dependencies"])
    assert {re.sub(r"[-_.]+", "-", d).lower() for d in CORE.values()} - core == {"vtk", "pillow"}  # via pyvista, mpl
    assert set(COMMAND_EXTRA.values()) <= set(EXTRAS)


def test_the_line_names_the_package_and_the_extra():
    assert missing_line("field", "distributed") == \
        "mpm-warp field: needs the 'distributed' package; install it with pip install \"mpm-warp[field]\""
    assert missing_line("sweep", "distributed").endswith('pip install "mpm-warp[sweep]"')
    assert missing_line("profile", "weac").endswith('pip install "mpm-warp[weac]"')
    assert missing_line("profile", "sklearn").endswith('pip install "mpm-warp[field]"')     # only [field] has it
    assert missing_line("render", "PIL") == \
        "mpm-warp render: needs the 'PIL' package; install it with pip install pillow (a dependency of mpm-warp)"
    assert missing_line("run", "nothing_like_it") == \
        "mpm-warp run: needs the 'nothing_like_it' package, which is not installed"
    assert (extra_for("scipy"), extra_for("scipy", "field"), extra_for("numpy", "field")) == ("weac", "field", None)


def test_which_errors_are_a_missing_package():
    assert missing_module(ModuleNotFoundError("No module named 'scipy.sparse'", name="scipy.sparse")) == "scipy"
    # a package that is there but lacks a name is not a missing package, nor is a module of mpm_warp
    assert missing_module(ImportError("cannot import name 'x' from 'weac'", name="weac")) is None
    assert missing_module(ModuleNotFoundError("No module named 'mpm_warp.nope'", name="mpm_warp.nope")) is None
    assert missing_module(ValueError("distributed")) is None
    try:
        try:
            import distributed_that_is_not_there  # noqa: F401
        except ImportError as e:
            raise MPMError("the sweep needs dask.distributed") from e
    except MPMError as e:
        assert missing_module(e) == "distributed_that_is_not_there"


def test_weac_missing_and_weac_of_another_api_are_told_apart(monkeypatch):
    monkeypatch.setattr(wr, "weac_version", lambda: None)
    with pytest.raises(wr.WeacUnavailable) as e:
        wr._weac()
    assert missing_module(e.value) == "weac" and str(e.value) == wr.NOT_INSTALLED
    monkeypatch.setattr(wr, "weac_version", lambda: "3.0.1")
    with pytest.raises(wr.WeacUnavailable, match="weac 3.0.1 is installed") as e:
        wr._weac()
    assert missing_module(e.value) is None          # the CLI prints the version line itself


@pytest.mark.slow
def test_require_imports_a_commands_extra(monkeypatch):
    require("run")                                  # no extra, nothing imported
    require("field")
    monkeypatch.setitem(sys.modules, "sklearn", None)
    with pytest.raises(ModuleNotFoundError) as e:
        require("field")
    assert e.value.name == "sklearn"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    from test_render import make_pst

    d = tmp_path_factory.mktemp("extras")
    (d / "psts.csv").write_text(FIELD_TABLE)
    return {"CSV": str(d / "psts.csv"), "RUN": make_pst(d / "pst.h5", n_frames=2), "OUT": str(d / "out")}


CASES = [  # command line, hidden module, the extra (or the distribution) the line names
    *[(["field", "CSV", "--out", "OUT", "--quiet"], m, "mpm-warp[field]") for m in EXTRAS["field"]],
    *[(["sweep", "pst_demo", "--vary", "scene.slope_angle=0,10", "--out", "OUT", "--quiet"], m, "mpm-warp[sweep]")
      for m in EXTRAS["sweep"]],
    (["profile", CAAML], "snowprofile", "mpm-warp[profile]"),
    (["profile", CAAML], "pandas", "mpm-warp[profile]"),
    (["profile", CAAML], "weac", "mpm-warp[weac]"),                 # the column's calibration
    (["profile", CAAML], "scipy", "mpm-warp[weac]"),
    (["profile", SNOWPILOT], "snowpylot", "mpm-warp[profile]"),
    (["scenes"], "snowprofile", "mpm-warp[profile]"),               # pst_profile reads its profile
    (["run", "pst_profile", "--quiet", "--set", "time.end=0.001"], "snowprofile", "mpm-warp[profile]"),
    (["render", "RUN", "--frames", "-1", "--out", "OUT", "--size", "160", "100"], "pyvista", "pip install pyvista"),
    (["render", "RUN", "--frames", "-1", "--out", "OUT", "--size", "160", "100", "--video", "gif"], "PIL",
     "pip install pillow"),
    (["plot", "RUN", "--out", "OUT"], "matplotlib", "pip install matplotlib"),
]


# the quick tier keeps the case (field on an install without Dask); the others are slow (2-10 s each)
PARAMS = [pytest.param(*c, id=f"{c[0][0]}-{c[1]}",
                       marks=() if (c[0][0], c[1]) == ("field", "distributed") else pytest.mark.slow) for c in CASES]


@pytest.mark.parametrize("argv, hidden, install", PARAMS)
def test_a_command_without_its_package_says_so_in_one_line(inputs, argv, hidden, install):
    argv = [inputs.get(a, a) for a in argv]
    p = subprocess.run([sys.executable, "-c", BLOCKED, hidden, *argv], capture_output=True, text=True, timeout=300)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip() and not ln.startswith("Warp ")]  # no-GPU notice
    assert p.returncode == 2, p.stderr
    assert "Traceback" not in p.stderr + p.stdout
    assert lines == [missing_line(argv[0], hidden)], p.stderr
    assert f"'{hidden}' package" in lines[0] and install in lines[0]
    if argv[0] == "field":                           # what the fresh clone's plain install must say
        assert plain_field_verdict(p.returncode, p.stderr) == {"rc": 2, "stderr": lines, "ok": True}


def test_the_fresh_clone_verdict_on_the_field_command():
    line = missing_line("field", "dask")
    assert plain_field_verdict(2, f"Warp CUDA warning: no driver\n{line}\n")["ok"]
    assert not plain_field_verdict(1, f"Traceback (most recent call last):\n{line}\n")["ok"]
    assert not plain_field_verdict(2, "mpm-warp: error: INPUT = 'x' is invalid\n")["ok"]     # names no extra
