"""Bad input on the command line (docs/robustness.md): one line on stderr, exit status 2 (3 for a blow-up)."""

from __future__ import annotations

import pytest
from helpers_bad_input import BASE, TIME_TABLE, expect, load_scenario_text, one_line, sub, write_scene

import mpm_warp as mw
from mpm_warp.cli import main


@pytest.mark.parametrize("text, sets, needles", [
    pytest.param(sub("dx = 0.02", "dx = = 0.02"), [], ("not valid TOML",), id="syntax"),
    pytest.param(sub(TIME_TABLE, ""), [], ("missing section [time]",), id="missing-section"),
    pytest.param(sub("dx = 0.02", "dxx = 0.02"), [], ("'domain.dxx'", "did you mean 'domain.dx'"), id="misspelt"),
    pytest.param(sub("dx = 0.02", 'dx = "0.02"'), [], ("domain.dx", "'0.02'"), id="string-for-number"),
    pytest.param(sub("dx = 0.02", "dx = nan"), [], ("domain.dx", "nan"), id="nan"),
    pytest.param(sub("nu = 0.3", "nu = 0.5"), [], ("materials.snow.nu", "0.5"), id="nu-0.5"),
    pytest.param(sub("density = 250.0", "density = 0.0"), [], ("materials.snow.density", "0.0"), id="density-0"),
    pytest.param(sub('material = "snow"', 'material = "ice"'), [], ("blocks[0].material", "'ice'"),
                 id="unknown-material"),
    pytest.param(sub('model = "elastic"', 'model = "plastic"'), [], ("materials.snow.model", "'plastic'"),
                 id="unknown-model"),
    pytest.param(sub("hi = [0.2, 0.08, 0.04]", "hi = [0.6, 0.08, 0.04]"), [], ("blocks[0].lo/hi[0]",),
                 id="outside"),
    pytest.param(sub('fields = ["x", "v", "p", "q"]', 'fields = ["x", "strain"]'), [], ("output.fields", "'strain'"),
                 id="unknown-field"),
    pytest.param(BASE, ["time.cfl=abc"], ("time.cfl", "'abc'"), id="set-bad-value"),
    pytest.param(BASE, ["nonsense"], ("'nonsense'", "key=value"), id="set-no-equals"),
    pytest.param(BASE, ["time.cfll=0.3"], ("did you mean 'time.cfl'",), id="set-misspelt"),
    pytest.param(BASE, ["domain.dx=5.0"], ("domain.dx = 5.0", "blocks[0] is 0.1 x 0.06 x 0.04 m, inside one cell"),
                 id="dx-5m"),
    pytest.param(BASE, ["time.frame_interval=0.05"], ("time.frame_interval = 0.05", "at most time.end"),
                 id="frame-interval-above-end"),
    pytest.param(BASE, ["materials.snow.E=1e30"], ("1e+30", "at most 1e+08 steps", "9.17e+13 steps"), id="E-1e30"),
    pytest.param(BASE, ["materials.snow.density=1e-300"], ("1e-300", "at most 1e+08 steps"), id="density-1e-300"),
    pytest.param(BASE, ["blocks.0.velocity=[1e6, 0, 0]"], ("blocks[0].velocity", "Mach 1.36e+04"), id="v-1e6"),
])
def test_cli_bad_input_one_line_exit_2(tmp_path, capsys, text, sets, needles):
    path = write_scene(tmp_path, text)
    argv = ["run", path, "--quiet"]
    for s in sets:
        argv += ["--set", s]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    line = one_line(err)
    assert line.startswith("mpm-warp: error: ")
    assert "Traceback" not in err
    for n in needles:
        assert n in line, f"{n!r} not in {line!r}"
    assert out == ""


def test_cli_missing_file_exit_2(tmp_path, capsys):
    assert main(["run", str(tmp_path / "nope.toml"), "--quiet"]) == 2
    _, err = capsys.readouterr()
    assert "not found" in one_line(err)


def test_cli_blow_up_one_line_exit_3(tmp_path, capsys):
    """A fixed step 3x the stability limit: exit status 3, one line naming step, particle and cause."""
    c_p = mw.Elastic(1.0e6, 0.3, 250.0).p_wave_speed
    dt = 3.0 * 0.02 / c_p
    text = sub("cfl = 0.4", f"dt = {dt!r}\nallow_unstable_dt = true")
    text = text.replace("end = 0.01", f"end = {40 * dt!r}").replace("frame_interval = 0.005",
                                                                      f"frame_interval = {10 * dt!r}")
    text = text.replace("checkpoint_every = 5", "checkpoint_every = 5\nhealth_every = 5")
    path = write_scene(tmp_path, text)
    out_h5 = str(tmp_path / "run.h5")
    assert main(["run", path, "--quiet", "--out", out_h5, "--set", "materials.snow.nu=0.3"]) == 3
    _, err = capsys.readouterr()
    line = one_line(err)
    assert line.startswith("mpm-warp: simulation stopped at step ")
    assert "particle " in line and "|v| dt > dx" in line and "run.ckpt.h5" in line


def test_step_budget_states_the_bound_and_the_estimate(tmp_path):
    """E = 1e30 Pa: c_p = sqrt(E (1 - nu) / ((1 + nu)(1 - 2 nu)) / rho) = 7.34e13 m/s, dt = 0.4 dx / c_p = 1.09e-16 s,
    9.17e13 steps to 0.01 s; an initial speed is bounded by 100 c_p = 7.34e3 m/s for E = 1 MPa."""
    err = expect(tmp_path, sub("E = 1.0e6", "E = 1.0e30"), mw.InvalidArgument, "at most 1e+08 steps",
                  "c_p = 7.34e+13 m/s", "dt = 1.09e-16 s", "9.17e+13 steps")
    assert err.value == (1.0e30, 250.0)
    expect(tmp_path, sub('material = "snow"', 'material = "snow"\nvelocity = [0.0, -8.0e3, 0.0]'),
            mw.InvalidArgument, "blocks[0].velocity", "at most 100 times", "7.34e+03 m/s", "Mach 109")
    assert load_scenario_text(tmp_path, sub('material = "snow"', 'material = "snow"\nvelocity = [0.0, -7.0e3, 0.0]'))
