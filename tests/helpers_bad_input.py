"""The scene the bad-input tests break one key at a time, and their checks (tests/test_bad_*.py).

Malformed scenario files, out-of-range values and bad ``--set`` overrides must fail with
:class:`mpm_warp.ScenarioError` or :class:`mpm_warp.InvalidArgument` (both ``MPMError`` and ``ValueError``)
whose message names the field and the value, before any kernel runs; the CLI prints them as one line and
exits with status 2 (3 for a blow-up), never a traceback.
"""

from __future__ import annotations

import pytest

import mpm_warp as mw

BASE = """\
name = "bad_input_base"
description = "A small valid scene that the tests break one key at a time"
precision = "float32"

[domain]
lo = [0.0, 0.0, 0.0]
hi = [0.4, 0.2, 0.04]
dx = 0.02
boundary = "slip"
boundary_faces = "xz"

[time]
end = 0.01
frame_interval = 0.005
cfl = 0.4
gravity = [0.0, -9.81, 0.0]

[materials.snow]
model = "elastic"
E = 1.0e6
nu = 0.3
density = 250.0

[[blocks]]
name = "block"
material = "snow"
lo = [0.1, 0.02, 0.0]
hi = [0.2, 0.08, 0.04]

[[walls]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
kind = "separate"
friction = 0.3

[output]
fields = ["x", "v", "p", "q"]
checkpoint_every = 5
"""


def sub(old: str, new: str) -> str:
    """BASE with the one occurrence of ``old`` replaced by ``new``."""
    assert BASE.count(old) == 1, old
    return BASE.replace(old, new)


def write_scene(tmp_path, text: str) -> str:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return str(path)


def load_scenario_text(tmp_path, text: str, overrides=None) -> mw.Scenario:
    return mw.load_scenario(write_scene(tmp_path, text), overrides)


def expect(tmp_path, text: str, cls, *needles: str, overrides=None) -> mw.MPMError:
    """Loading must raise ``cls`` (an MPMError and ValueError) whose message holds every needle."""
    with pytest.raises(cls) as info:
        load_scenario_text(tmp_path, text, overrides)
    err = info.value
    assert isinstance(err, mw.MPMError) and isinstance(err, ValueError)
    msg = str(err)
    assert "\n" not in msg
    for n in needles:
        assert n in msg, f"{n!r} not in {msg!r}"
    return err


TIME_TABLE = "[time]\nend = 0.01\nframe_interval = 0.005\ncfl = 0.4\ngravity = [0.0, -9.81, 0.0]\n"
MATERIALS_TABLE = '[materials.snow]\nmodel = "elastic"\nE = 1.0e6\nnu = 0.3\ndensity = 250.0\n'


def one_line(text: str) -> str:
    lines = [ln for ln in text.splitlines() if ln.strip()]
    assert len(lines) == 1, text
    return lines[0]


def run_cli(argv, capsys, status: int = 2) -> str:
    """Run ``mpm-warp argv``: it must exit with ``status`` and print one line on stderr (returned), nothing else."""
    from mpm_warp.cli import main

    assert main(argv) == status
    out, err = capsys.readouterr()
    assert "Traceback" not in err and out == ""
    return one_line(err)
