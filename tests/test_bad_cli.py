"""Bad input on the command line (docs/robustness.md): one line on stderr, exit status 2 (3 for a blow-up)."""

from __future__ import annotations

import pytest
from helpers_bad_input import BASE, TIME_TABLE, expect, load_scenario_text, one_line, run_cli, sub, write_scene

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


def test_cli_fixed_dt_above_the_limit_one_line(tmp_path, capsys):
    path = write_scene(tmp_path, sub("cfl = 0.4", "dt = 0.01").replace("end = 0.01", "end = 0.05"))
    line = run_cli(["run", path, "--quiet", "--out", str(tmp_path / "r.h5")], capsys)
    assert "time.dt = 0.01 is invalid" in line and "stability limit 1.11 dx / c_p" in line
    assert not (tmp_path / "r.h5").exists()


# ------------------------------------------------------------------ sweep --cases
@pytest.mark.parametrize("content, needles", [
    (b"time.end,time.cfl\n0.01\n", ("cases row (line 2 of", "['0.01']", "2 values", "it has 1")),
    (b"time.end\n0.01,0.3\n", ("cases row (line 2 of", "1 values", "it has 2")),
    (b"time.end,time.cfl\n0.01,0.3\n0.02,0.3,9\n", ("line 3 of", "it has 3")),
    (b"", ("it has nothing",)),
    (b"time.end\n\n", ("it has a header only",)),
    (b"time.end,\n0.01,\n", ("cases header", "non-empty",)),
    (b"time.end,time.end\n0.01,0.02\n", ("cases header", "distinct")),
    (b"time.end\n0.01\n\xff\xfe\n", ("a UTF-8 CSV file (byte",)),
], ids=["short-row", "long-row", "long-later-row", "empty", "header-only", "empty-key", "duplicate-key", "not-utf8"])
def test_cli_sweep_cases_one_line(tmp_path, capsys, content, needles):
    """Rows of the wrong length ran silently (a short row without its value, an extra value dropped), an empty
    file gave "0 runs" with exit 0, a non-UTF-8 file a UnicodeDecodeError: one line naming the row, exit 2, no run."""
    cases = tmp_path / "cases.csv"
    cases.write_bytes(content)
    line = run_cli(["sweep", "elastic_block", "--cases", str(cases), "--out", str(tmp_path / "sw"), "--quiet"], capsys)
    assert line.startswith("mpm-warp: error: cases")
    for n in needles:
        assert n in line, (n, line)
    assert not (tmp_path / "sw").exists()


# ------------------------------------------------------------------ a signal before stepping starts
def test_sigterm_before_stepping_ends_at_once(tmp_path):
    """SIGTERM while the scenario is read (a 16 MB file: seconds of parsing) ends the command at once, exit 143, one
    line, the lock released: before, it was taken as "stop after the current batch" of a run not started yet, and
    it took three signals to end."""
    import os
    import signal
    import subprocess
    import sys
    import time

    path = tmp_path / "big.toml"
    path.write_text(BASE.replace('description = "', 'junk = [' + ",".join(["0.5"] * 4_000_000) + ']\ndescription = "'))
    out = tmp_path / "r.h5"
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    proc = subprocess.Popen([sys.executable, "-m", "mpm_warp.cli", "run", str(path), "--out", str(out), "--quiet"],
                            stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": root})
    deadline = time.time() + 120
    while not os.path.exists(str(out) + ".lock") and time.time() < deadline and proc.poll() is None:
        time.sleep(0.01)                           # the output is claimed before the scenario is read
    assert proc.poll() is None, proc.stderr.read()
    t0 = time.perf_counter()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    waited = time.perf_counter() - t0
    lines = [ln for ln in err.splitlines() if "CUDA" not in ln]
    assert proc.returncode == 128 + signal.SIGTERM and waited < 3.0, (proc.returncode, waited, err)
    assert lines == ["mpm-warp: interrupted (SIGTERM); complete frames are kept in the output file"]
    assert not os.path.exists(str(out) + ".lock") and not out.exists()
