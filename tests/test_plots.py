"""Time-series plots: the front-speed fit, every figure from a known run and the numbers in its data files."""

from __future__ import annotations

import csv
import json
import os

import numpy as np
import pytest
from PIL import Image

import mpm_warp
from mpm_warp.cli import main
from mpm_warp.errors import InvalidArgument
from mpm_warp.io import RunWriter, read_run
from mpm_warp.post import fronts, plots
from mpm_warp.scenes.pst import PSTParams

T = np.linspace(0.0, 0.2, 41)                       # s, frames every 5 ms
C, T0, CUT, END = 25.0, 0.05, 0.3, 3.0              # front speed [m/s], start [s], saw cut and column end [m]


def front_of(t):
    """Saw phase (no front, then the cut length), steady run at C, stop at the column's end."""
    x = np.clip(CUT + C * (t - T0), CUT, END)
    return np.where(t < 0.02, np.nan, x)


def series():
    t = T
    gamma = 0.01 * t / t[-1]
    return {"front_position": front_of(t), "saw_position": np.minimum(10 * t, CUT),
            "marker_0_dx": 1e-3 * t, "marker_0_dy": -2e-3 * t, "marker_1_dx": 3e-4 * t ** 2, "marker_1_dy": -t ** 2,
            "shear_strain": gamma, "shear_stress": 2e3 * np.sin(300 * gamma), "mises_q": 3.5e3 * np.sin(300 * gamma),
            "axial_strain": -0.2 * gamma, "kinetic_energy": 0.5 * t, "elastic_energy": 1.0 - t ** 2}


def write_run(path, names) -> str:
    data = series()
    units = {n: ("m" if n.startswith(("front", "saw", "marker")) else "J" if n.endswith("energy")
                 else "Pa" if n in ("shear_stress", "mises_q") else "1") for n in names}
    with RunWriter(path, n_particles=1, particle_fields={"x": ((3,), "float64", "m")}, scalar_series=units,
                   attrs={"scenario": {"name": "synthetic", "scene": {"kind": "pst"}}}) as w:
        for k, t in enumerate(T):
            w.write_frame(t, k, {"x": np.zeros((1, 3))}, scalars={n: data[n][k] for n in names})
    return str(path)


def read_csv(path) -> dict[str, np.ndarray]:
    with open(path) as f:
        rows = list(csv.reader(f))
    return {name: np.array([float(r[j]) for r in rows[1:]]) for j, name in enumerate(rows[0])}


@pytest.fixture(scope="module")
def full_run(tmp_path_factory):
    return write_run(tmp_path_factory.mktemp("plots") / "full.h5", list(series()))


def test_fit_front_speed_on_the_steady_part():
    fit = fronts.fit_front_speed(T, front_of(T))
    assert fit["speed"] == pytest.approx(C, rel=1e-9)
    assert fit["intercept"] == pytest.approx(CUT - C * T0, rel=1e-9)
    assert fit["r2"] == pytest.approx(1.0)
    assert fit["window"] == pytest.approx([CUT + 0.2 * (END - CUT), CUT + 0.9 * (END - CUT)])
    # the window holds travel between 20 % and 90 % of the total: no plateau sample enters
    x_start, x_end = CUT + C * (fit["t_start"] - T0), CUT + C * (fit["t_end"] - T0)
    assert x_start >= CUT + 0.2 * (END - CUT) - 1e-9 and x_end <= CUT + 0.9 * (END - CUT) + 1e-9
    noisy = front_of(T) + 1e-3 * np.cos(37 * T)
    assert fronts.fit_front_speed(T, noisy)["speed"] == pytest.approx(C, rel=0.01)


def test_fit_front_speed_edge_cases():
    assert np.isnan(fronts.fit_front_speed(T, np.full_like(T, np.nan))["speed"])
    assert np.isnan(fronts.fit_front_speed(T, np.full_like(T, 0.5))["speed"])      # an arrested front
    with pytest.raises(InvalidArgument):
        fronts.fit_front_speed(T, front_of(T), lo=0.9, hi=0.2)
    with pytest.raises(InvalidArgument):
        fronts.fit_front_speed(T, front_of(T)[:-1])


def test_plot_run_writes_every_figure_and_its_numbers(full_run, tmp_path):
    files = plots.plot_run(full_run, tmp_path)
    names = [os.path.basename(f) for f in files]
    assert names == ["front.png", "front.csv", "front.json", "markers.png", "markers.csv", "shear.png", "shear.csv",
                     "energy.png", "energy.csv"]
    for f in files:
        if f.endswith(".png"):
            img = np.asarray(Image.open(f).convert("RGB"))
            assert img.shape[0] > 300 and img.std() > 10
    data = series()
    front = read_csv(tmp_path / "front.csv")
    assert np.array_equal(front["time [s]"], T)
    np.testing.assert_array_equal(front["front_position [m]"], data["front_position"])  # NaN where no front
    np.testing.assert_array_equal(front["saw_position [m]"], data["saw_position"])
    np.testing.assert_allclose(front["front_fit [m]"], CUT + C * (T - T0), rtol=1e-9)
    fit = json.loads((tmp_path / "front.json").read_text())
    assert fit["speed"] == pytest.approx(C, rel=1e-9) and fit["unit_speed"] == "m/s"
    markers = read_csv(tmp_path / "markers.csv")
    assert list(markers) == ["time [s]", "marker_0_dx [m]", "marker_0_dy [m]", "marker_1_dx [m]", "marker_1_dy [m]"]
    for k in ("marker_0_dx", "marker_1_dy"):
        np.testing.assert_array_equal(markers[f"{k} [m]"], data[k])
    shear = read_csv(tmp_path / "shear.csv")
    for k, unit in (("shear_strain", "1"), ("shear_stress", "Pa"), ("mises_q", "Pa"), ("axial_strain", "1")):
        np.testing.assert_array_equal(shear[f"{k} [{unit}]"], data[k])
    energy = read_csv(tmp_path / "energy.csv")
    np.testing.assert_array_equal(energy["kinetic_energy [J]"], data["kinetic_energy"])
    np.testing.assert_allclose(energy["total_energy [J]"], data["kinetic_energy"] + data["elastic_energy"])


def test_pst_series_names_and_fit_window(tmp_path):
    """A PST run stores ``front``/``saw`` (from the saw's end) and ``marker<k>_ux|uy``."""
    data = series()
    with RunWriter(tmp_path / "pst.h5", n_particles=1, particle_fields={"x": ((3,), "float64", "m")},
                   scalar_series={"front": "m", "deflection_front": "m", "saw": "m", "marker0_ux": "m",
                                  "marker0_uy": "m", "marker1_ux": "m", "marker1_uy": "m"},
                   attrs={"scenario": {"name": "pst", "scene": {"kind": "pst", "length": END,
                                                                "saw": {"cut_length": CUT}}}}) as w:
        for k, t in enumerate(T):
            f = np.nan_to_num(data["front_position"][k])
            w.write_frame(t, k, {"x": np.zeros((1, 3))},
                          scalars={"front": f, "deflection_front": f, "saw": data["saw_position"][k],
                                   "marker0_ux": data["marker_0_dx"][k], "marker0_uy": data["marker_0_dy"][k],
                                   "marker1_ux": data["marker_1_dx"][k], "marker1_uy": data["marker_1_dy"][k]})
    names = [os.path.basename(f) for f in plots.plot_run(tmp_path / "pst.h5", tmp_path)]
    assert names == ["front.png", "front.csv", "front.json", "markers.png", "markers.csv"]
    fit = json.loads((tmp_path / "front.json").read_text())
    assert fit["series"] == "front" and fit["speed"] == pytest.approx(C, rel=1e-9)
    # the positions of the PST's own mean speed: from a bin beyond the cut over 3 m, at most to the end zone
    bw = PSTParams().bin_width
    assert fit["window"] == pytest.approx([CUT + bw, min(CUT + 3.0, END - max(PSTParams().slab_thickness, 2 * bw))])
    front = read_csv(tmp_path / "front.csv")
    assert list(front) == ["time [s]", "front [m]", "deflection_front [m]", "saw [m]", "front_fit [m]"]
    markers = read_csv(tmp_path / "markers.csv")
    np.testing.assert_array_equal(markers["marker1_uy [m]"], data["marker_1_dy"])


def test_only_the_figures_a_run_supports(tmp_path):
    run = write_run(tmp_path / "shear.h5", ["shear_strain", "axial_strain", "kinetic_energy"])
    names = [os.path.basename(f) for f in plots.plot_run(run)]
    assert names == ["shear.png", "shear.csv", "energy.png", "energy.csv"]
    assert os.path.isfile(tmp_path / "shear_plots" / "shear.png")      # default folder beside the run
    assert plots.plot_run(write_run(tmp_path / "none.h5", ["shear_strain"]), tmp_path / "none") == []


def test_cli_plot(full_run, tmp_path, capsys):
    assert main(["plot", full_run, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out.split()
    assert str(tmp_path / "front.png") in out and len(out) == 9


def test_end_to_end_elastic_block(tmp_path):
    out = str(tmp_path / "block.h5")
    mpm_warp.run("elastic_block", output=out, overrides=["time.end=0.03"])
    run = read_run(out)
    files = plots.plot_run(out, tmp_path / "plots")
    assert [os.path.basename(f) for f in files] == ["energy.png", "energy.csv"]
    energy = read_csv(tmp_path / "plots" / "energy.csv")
    np.testing.assert_array_equal(energy["time [s]"], run.times)
    np.testing.assert_array_equal(energy["kinetic_energy [J]"], run.scalars["kinetic_energy"])
    assert energy["kinetic_energy [J]"][-1] > 0                         # the block has been falling


def test_pst_fit_faster_than_sound_is_no_speed(tmp_path):
    """A PST front line faster than the slab's P-wave speed (the front connected to damage ahead) is not a speed:
    ``front.json`` holds null with the reason, and ``c_max``."""
    t = np.linspace(0.0, 0.2, 201)
    front = np.clip(CUT + 400.0 * (t - T0), 0.0, END)           # 400 m/s, faster than c_p 164 m/s
    with RunWriter(tmp_path / "pst.h5", n_particles=1, particle_fields={"x": ((3,), "float64", "m")},
                   scalar_series={"front": "m"},
                   attrs={"scenario": {"name": "pst", "scene": {"kind": "pst", "length": END,
                                                                "saw": {"cut_length": CUT}}}}) as w:
        for k, tk in enumerate(t):
            w.write_frame(tk, k, {"x": np.zeros((1, 3))}, scalars={"front": front[k]})
    plots.plot_run(tmp_path / "pst.h5", tmp_path)
    fit = json.loads((tmp_path / "front.json").read_text())
    assert fit["c_max"] == pytest.approx(164.08, rel=1e-4) and fit["speed"] is None
    assert fit["speed_null"].startswith("nucleation ahead of the front: the line's 400 m/s exceeds")
