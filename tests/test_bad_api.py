"""Python API misuse (docs/robustness.md): one InvalidArgument line naming the argument, never a TypeError,
AttributeError or ZeroDivisionError from inside, and nothing written.

The calls of the issue: ``mw.Simulation("elastic_block")`` (AttributeError), ``device=3``, ``run.frame("x")``,
``sim.run(end_time=nan)``, ``sim.run(frame_interval=0)`` (ZeroDivisionError), ``mw.run(42)`` / ``mw.run(None)`` /
``output=123`` / ``read_run(None)`` ("expected str, bytes or os.PathLike object"), ``sim.run(end_time=-1)`` (a
1-frame file), a second ``sim.run`` (0 steps, a 1-frame file) and ``overrides="time.end=0.02"`` (misparsed).
"""

from __future__ import annotations

import math

import pytest

import mpm_warp as mw

SETS = ["time.end=0.01", "time.frame_interval=0.005"]


@pytest.fixture(scope="module")
def scenario():
    return mw.load_scenario("elastic_block", SETS)


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("api") / "run.h5")
    mw.run("elastic_block", out, "cpu", SETS)
    return out


def _refused(call, field: str, *needles: str) -> mw.InvalidArgument:
    with pytest.raises(mw.InvalidArgument) as info:
        call()
    err = info.value
    assert err.field == field and "\n" not in str(err) and str(err).startswith(f"{field} = ")
    for n in needles:
        assert n in str(err), (n, str(err))
    return err


@pytest.mark.parametrize("value, needle", [
    ("elastic_block", "mpm_warp.load_scenario"), (None, "a Scenario"), (42, "a Scenario"),
    ({"name": "x"}, "a Scenario"),
])
def test_simulation_needs_a_scenario(value, needle):
    _refused(lambda: mw.Simulation(value, device="cpu"), "scenario", needle)


@pytest.mark.parametrize("kwargs, field", [
    ({"device": 3}, "device"), ({"device": "gpu"}, "device"), ({"device": "cuda:x"}, "device"),
    ({"use_graph": "yes"}, "use_graph"), ({"n_threads": 0}, "n_threads"), ({"n_threads": "2"}, "n_threads"),
])
def test_simulation_arguments(scenario, kwargs, field):
    _refused(lambda: mw.Simulation(scenario, **{"device": "cpu", **kwargs}), field)


@pytest.mark.parametrize("kwargs, field, needle", [
    ({"end_time": math.nan}, "end_time", "finite"), ({"end_time": math.inf}, "end_time", "finite"),
    ({"end_time": -1.0}, "end_time", "(0, inf)"), ({"end_time": 0.0}, "end_time", "(0, inf)"),
    ({"end_time": "0.1"}, "end_time", "a number"), ({"end_time": 1e12}, "end_time", "at most 1e+08 steps"),
    ({"frame_interval": 0.0}, "frame_interval", "(0, inf)"), ({"frame_interval": math.nan}, "frame_interval", ""),
    ({"frame_interval": 1.0}, "frame_interval", "at most the end time"), ({"callback": 5}, "callback", "callable"),
    ({"output": 123}, "output", "file path"), ({"output": ""}, "output", "file path"),
    ({"append": "no"}, "append", "True or False"), ({"overwrite": 1}, "overwrite", "True or False"),
])
def test_simulation_run_arguments(scenario, tmp_path, kwargs, field, needle):
    """Refused before a step or a file: ``end_time=-1`` wrote a 1-frame file, ``frame_interval=0`` divided by 0."""
    sim = mw.Simulation(scenario, device="cpu")
    kwargs = {"output": str(tmp_path / "run.h5"), **kwargs}
    _refused(lambda: sim.run(**kwargs), field, needle)
    assert list(tmp_path.iterdir()) == [] and sim.time == 0.0


@pytest.mark.slow
def test_a_second_run_continues_or_is_refused(scenario, tmp_path):
    """After a first run to 0.01 s: a second run without output continues from there (never 0 steps in silence);
    one with an output, or one that would end where the first stopped, is refused by name and writes nothing."""
    sim = mw.Simulation(scenario, device="cpu")
    first = sim.run(None)
    assert first.frames == 2 and sim.time == pytest.approx(0.01)
    _refused(lambda: sim.run(None), "end_time", "t = 0.01 s, where this Simulation stopped")
    _refused(lambda: sim.run(str(tmp_path / "again.h5")), "output", "has run to t = 0.01 s")
    assert list(tmp_path.iterdir()) == []
    second = sim.run(None, end_time=0.02)
    assert second.frames == 2 and second.steps > 0 and sim.time == pytest.approx(0.02)


@pytest.mark.parametrize("scene", [42, None, ["elastic_block"], 3.5, ""])
def test_run_needs_a_scenario(scene, tmp_path):
    _refused(lambda: mw.run(scene, str(tmp_path / "r.h5"), "cpu"), "scenario", "a scenario file path")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kwargs, field", [
    ({"output": 123}, "output"), ({"output": b"run.h5"}, "output"), ({"overwrite": "no"}, "overwrite"),
    ({"on_start": 1}, "on_start"), ({"frame_intervall": 0.1}, "run_kwargs"), ({"overrides": 42}, "overrides"),
    ({"overrides": {1: 2}}, "overrides"), ({"device": 3}, "device"),
])
def test_run_arguments(tmp_path, kwargs, field):
    _refused(lambda: mw.run("elastic_block", **{"device": "cpu", "overrides": SETS, **kwargs}), field)
    assert list(tmp_path.iterdir()) == []


def test_one_override_as_a_string():
    """``overrides="time.end=0.06"`` was misparsed character by character ("override 't': expected key=value")."""
    assert mw.load_scenario("elastic_block", "time.end=0.06").time.end == 0.06
    assert mw.run("elastic_block", None, "cpu", "time.end=0.06").sim_time == pytest.approx(0.06)


@pytest.mark.parametrize("path", [None, 42, ""])
def test_read_run_and_resume_need_a_path(path):
    _refused(lambda: mw.read_run(path), "path", "a run file path")
    _refused(lambda: mw.resume(path, device="cpu"), "output", "a file path")


@pytest.mark.parametrize("index", ["x", 1.5, True, None, 3, -4])
def test_frame_index(run_file, index):
    run = mw.read_run(run_file)
    assert run.n_frames == 3
    _refused(lambda: run.frame(index), "frame", "an index in [-3, 3)")


@pytest.mark.parametrize("kwargs, field", [
    ({"size": ("a", "b")}, "size"), ({"size": (100,)}, "size"), ({"size": (640.5, 480)}, "size"),
    ({"size": (32, 32)}, "size"), ({"clim": (1,)}, "clim"), ({"clim": "ab"}, "clim"), ({"clim": (1, 0)}, "clim"),
    ({"frames": 1.5}, "frames"), ({"frames": [0, 0.5]}, "frames"), ({"field": None}, "field"),
    ({"fps": 0}, "fps"), ({"camera": 3}, "camera"), ({"video": "avi"}, "video"),
])
def test_render_arguments(run_file, tmp_path, kwargs, field):
    from mpm_warp.post.render import render_run

    _refused(lambda: render_run(run_file, **{"out_dir": str(tmp_path / "r"), "field": "p", **kwargs}), field)
    assert not (tmp_path / "r").exists() or not any((tmp_path / "r").iterdir())


@pytest.mark.parametrize("t_end", [math.nan, math.inf, -1.0, "1"])
def test_step_to_needs_a_time(scenario, t_end):
    """``sim.step_to(nan)`` returned 0 steps in silence."""
    _refused(lambda: mw.Simulation(scenario, device="cpu").step_to(t_end), "t_end")
