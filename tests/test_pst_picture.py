"""The main job's picture (:mod:`mpm_warp.post.pst_picture`, also ``mpm-warp plot``) of a flat and a sloped PST run.

Both runs are ``helpers_scenes.RUNNING_PST`` (conftest): on the flat column the crack runs to the far end; on the
30 degree slope it does not by 0.23 s. The picture is checked for being drawn on (its non-white fraction, its
colours), for its frame (the one where the damage front first reaches halfway from the cut to the far end zone)
and for the fronts the run stores: the damage front's magenta line, the slab-deflection front only once there is one.
"""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import mpm_warp as mw
from mpm_warp.cli import main
from mpm_warp.errors import InvalidArgument
from mpm_warp.post.fronts import scene_params
from mpm_warp.post.pst_picture import pst_picture, running_frame
from mpm_warp.scenes.pst.analysis import end_zone


def _rgb(png) -> np.ndarray:
    return np.asarray(Image.open(png))[..., :3].astype(int)


def _not_blank(img: np.ndarray) -> None:
    drawn = 1.0 - np.all(img >= 250, axis=-1).mean()
    assert 0.08 < drawn < 0.6, drawn                              # measured 0.18-0.22
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 300
    magenta = np.all(np.abs(img - (255, 0, 255)) <= 40, axis=-1).sum()
    assert magenta > 300                                          # the damage front, in both panels


def _halfway_frame(run) -> int:
    p = scene_params(run)
    goal = p.saw.cut_length + 0.5 * (p.length - end_zone(p) - p.saw.cut_length)
    hit = np.nonzero(run.scalars["front"] >= goal)[0]
    return int(hit[0]) if len(hit) else run.n_frames - 1


@pytest.mark.slow
def test_flat_pst_picture(running_pst, tmp_path):
    run = mw.read_run(running_pst)
    k = running_frame(run, scene_params(run))
    assert k == _halfway_frame(run) < run.n_frames - 1          # the crack ran: a frame before the last
    assert run.scalars["deflection_front"][k] > 0
    png = pst_picture(running_pst, str(tmp_path / "pst.png"))
    img = _rgb(png)
    assert img.shape == (832, 1560, 3)                            # 12 x 6.4 in at 130 dpi
    _not_blank(img)
    # the weak layer behind the front is coloured by its collapse: viridis' greens and blues, not only its purple
    purple = np.all(np.abs(img - (68, 1, 84)) <= 30, axis=-1).sum()
    lighter = ((img[..., 1] > img[..., 0] + 20) & (img[..., 1] > 60) & (img[..., 2] > 60)).sum()
    assert purple > 1000 and lighter > 200


@pytest.mark.slow
def test_sloped_pst_picture(sloped_pst, tmp_path):
    run = mw.read_run(sloped_pst)
    p = scene_params(run)
    assert p.slope_angle == 30.0
    assert running_frame(run, p) == _halfway_frame(run) == run.n_frames - 1      # no run: the last frame
    assert run.scalars["deflection_front"][-1] == 0.0              # no deflection front: none drawn
    img = _rgb(pst_picture(sloped_pst, str(tmp_path / "pst.png"), frame=-1))
    _not_blank(img)


@pytest.mark.slow
@pytest.mark.parametrize("which", ["running_pst", "sloped_pst"])
def test_cli_plot_of_a_pst(which, request, tmp_path, capsys):
    path = request.getfixturevalue(which)
    assert main(["plot", path, "--out", str(tmp_path)]) == 0
    files = capsys.readouterr().out.split()
    assert str(tmp_path / "pst.png") in files and str(tmp_path / "front.png") in files
    _not_blank(_rgb(tmp_path / "pst.png"))


def test_not_a_pst_is_refused_by_name(tmp_path):
    out = str(tmp_path / "block.h5")
    mw.run("elastic_block", out, "cpu", ["time.end=0.01", "time.frame_interval=0.01"])
    with pytest.raises(InvalidArgument, match=r"^path = .*block\.h5' is invalid: expected a PST run file"):
        pst_picture(out, str(tmp_path / "p.png"))


@pytest.mark.slow
def test_plotting_a_run_file_starts_no_simulation(running_pst, tmp_path, monkeypatch):
    """Post only reads run files: the stored calibration, never a material-point drive or a Simulation."""
    import mpm_warp.material_point as material_point
    import mpm_warp.scenes.weak_layer.paths as paths
    from mpm_warp.scenes.weak_layer import params as wl_params

    def forbidden(*a, **k):
        raise AssertionError("plotting started a simulation")
    monkeypatch.setattr(material_point, "drive_material_points", forbidden)
    monkeypatch.setattr(paths, "drive_material_points", forbidden)
    monkeypatch.setattr(mw.Simulation, "__init__", forbidden)
    wl_params._calibrate.cache_clear()                      # a cached calibration would hide a call
    _not_blank(_rgb(pst_picture(running_pst, str(tmp_path / "pst.png"))))
    assert main(["plot", running_pst, "--out", str(tmp_path / "cli")]) == 0
    with pytest.raises(AssertionError, match="started a simulation"):   # the guard does catch a drive
        paths.drive_material_points()
