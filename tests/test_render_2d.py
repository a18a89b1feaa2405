"""Rendering a real 2D PST run (a flat x-y section) and a 3D block: not blank, the fronts where the run says.

The 2D run is ``helpers_scenes.RUNNING_PST`` (conftest ``running_pst``): a 0.6 m column, its crack running to
the far end by 0.23 s. The numbers checked are the run's own: the fronts' positions (its ``front`` and
``deflection_front`` series) at the camera's pixels per metre, and the projected area of its elastic slab and
old snow (0.6 m x 0.33 m), drawn light grey under ``collapse``.
"""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from mpm_warp.cli import main
from mpm_warp.errors import InvalidArgument
from mpm_warp.io import read_run
from mpm_warp.post import render

pytestmark = pytest.mark.slow


def _rgb(png) -> np.ndarray:
    return np.asarray(Image.open(png))[..., :3].astype(int)


def assert_not_blank(img: np.ndarray, lo: float, hi: float, min_colours: int) -> None:
    """Drawn on: the non-white fraction of the image within (lo, hi), at least ``min_colours`` distinct colours."""
    drawn = 1.0 - np.all(img == 255, axis=-1).mean()
    assert lo < drawn < hi, drawn
    assert len(np.unique(img.reshape(-1, 3), axis=0)) >= min_colours


def _columns(img: np.ndarray, rgb) -> np.ndarray:
    return np.nonzero(np.all(img == rgb, axis=-1))[1]


def _column_of(meta: dict, x: float) -> float:
    w, h = meta["size"]
    cam = meta["camera"]
    return w / 2 + (x - cam["focal_point"][0]) * h / (2 * cam["parallel_scale"]) - 0.5


def test_2d_pst_is_a_flat_section_with_its_fronts(running_pst, tmp_path):
    run = read_run(running_pst)
    out = render.render_run(running_pst, out_dir=tmp_path, size=(640, 360), frames="0,-2,-1")
    meta = out.metadata
    assert meta["dimension"] == 2 and meta["camera_preset"] == "side"
    ppm = 360 / (2 * meta["camera"]["parallel_scale"])
    slab_and_old_snow = 0.6 * (0.3 + 0.03) * ppm ** 2          # px: the elastic groups, grey under "collapse"
    k = run.n_frames - 2                                        # t = 0.22 s: the crack is running
    front, deflection = float(run.scalars["front"][k]), float(run.scalars["deflection_front"][k])
    assert 0.3 < front < 0.6 and 0.0 < deflection < front      # the run's own numbers (the saw starts at x = 0)
    for png, fr in zip(out.pngs, meta["frames"], strict=True):
        img = _rgb(png)
        assert img.shape == (360, 640, 3)
        assert_not_blank(img, 0.3, 0.5, 500)                    # measured 0.38-0.39 and 614-1155 colours
        inert = int((np.abs(img - render.INERT_COLOR).sum(-1) <= 3).sum())
        assert inert == pytest.approx(slab_and_old_snow, rel=0.05)   # measured 71120 (frame 0) of 70878
        magenta, orange = _columns(img, render.FRONT_COLOR), _columns(img, render.DEFLECTION_COLOR)
        if fr["index"] == 0:                                    # settling: no front, no marker
            assert fr["front_position"] is None and fr["deflection_position"] is None
            assert magenta.size == 0 and orange.size == 0
            continue
        assert fr["front_position"] == pytest.approx(float(run.scalars["front"][fr["index"]]))
        assert abs(np.median(magenta) - _column_of(meta, fr["front_position"])) <= 2.0
    mid = meta["frames"][1]
    assert mid["index"] == k and mid["front_position"] == pytest.approx(front)
    assert mid["deflection_position"] == pytest.approx(deflection)
    orange = _columns(_rgb(out.pngs[1]), render.DEFLECTION_COLOR)
    assert orange.size > 100 and abs(np.median(orange) - _column_of(meta, deflection)) <= 2.0
    # the weak layer is coloured: collapse behind the front reaches the top of the colour range
    (wl,) = [g for g in run.attrs["groups"] if g["name"] == "weak_layer"]
    collapse = [render.FIELDS["collapse"].compute(run.frame(i), None)[wl["start"]:wl["end"]] for i in (0, k, k + 1)]
    assert out.clim[1] == pytest.approx(max(float(c.max()) for c in collapse), rel=1e-6) and out.clim[1] > 0.03


def test_2d_run_refuses_the_oblique_camera(running_pst, tmp_path):
    with pytest.raises(InvalidArgument, match=r"camera = 'oblique'.*2D run"):
        render.render_run(running_pst, camera="oblique", out_dir=tmp_path, frames="-1")


@pytest.mark.parametrize("fps", [0, -5, float("nan"), float("inf"), "fast", True])
def test_fps_must_be_positive(running_pst, tmp_path, fps):
    with pytest.raises(InvalidArgument, match="fps"):
        render.render_run(running_pst, out_dir=tmp_path, frames="-1", video=True, fps=fps)
    assert not list(tmp_path.iterdir())                         # refused before anything is drawn


@pytest.mark.parametrize("fps", ["0", "-5", "nan"])
def test_cli_fps_one_line(running_pst, tmp_path, capsys, fps):
    assert main(["render", running_pst, "--out", str(tmp_path / "r"), "--video", "--fps", fps]) == 2
    err = capsys.readouterr().err
    assert err.startswith("mpm-warp: error: fps = ") and err.count("\n") == 1


def test_cli_renders_a_2d_pst(running_pst, tmp_path, capsys):
    assert main(["render", running_pst, "--frames", "-1", "--out", str(tmp_path), "--size", "480", "270"]) == 0
    assert "1 frames of collapse [-]" in capsys.readouterr().out
    (png,) = tmp_path.glob("collapse_*.png")
    assert_not_blank(_rgb(png), 0.3, 0.5, 300)


def test_3d_block_is_not_blank(tmp_path):
    import mpm_warp

    path = str(tmp_path / "block.h5")
    mpm_warp.run("elastic_block", output=path, device="cpu", overrides=["time.end=0.03"])
    out = render.render_run(path, field="displacement", out_dir=tmp_path / "r", size=(480, 320), frames="-1")
    assert out.metadata["dimension"] == 3 and out.metadata["camera_preset"] == "oblique"
    assert_not_blank(_rgb(out.pngs[0]), 0.05, 0.6, 100)
