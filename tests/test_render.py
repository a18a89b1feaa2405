"""Off-screen rendering of run files: image size, content, front marker pixel, colour range, film, CLI."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from PIL import Image

import mpm_warp
from mpm_warp.cli import main
from mpm_warp.errors import InvalidArgument
from mpm_warp.io import RunWriter, read_run
from mpm_warp.post import render
from mpm_warp.post.render import film, gl

SPEED, A0, DT = 20.0, 0.4, 0.01          # synthetic front: x_f = A0 + SPEED t [m], frames every DT [s]


def make_pst(path, n_frames: int = 4, h: float = 0.02, length: float = 2.0, from_end: str | None = None) -> str:
    """A PST-like column (base, weak layer, slab) whose weak layer collapses behind a known front.

    ``from_end=None`` stores ``front_position`` (x); ``"left"``/``"right"`` store a PST's ``front``
    and ``saw`` (distances from that end of the column), as :mod:`mpm_warp.scenes.pst` does. The
    collapse reference ``log_jp_ref`` is 0 (the settled layer of this column had ``log_jp = 0``).
    """
    g = np.mgrid[h / 2:length:h, h / 2:0.36:h, h / 2:0.1:h].reshape(3, -1).T
    group = np.where(g[:, 1] < 0.04, 0, np.where(g[:, 1] < 0.06, 1, 2)).astype(np.uint8)
    fields = {"x": ((3,), "float32", "m"), "v": ((3,), "float32", "m/s"), "log_jp": ((), "float32", "1"),
              "log_jp_ref": ((), "float32", "1"), "p": ((), "float32", "Pa"), "q": ((), "float32", "Pa")}
    scene = {"kind": "pst"} if from_end is None else {"kind": "pst", "length": length, "saw": {"from_end": from_end}}
    series = {"front_position": "m"} if from_end is None else {"front": "m", "saw": "m"}
    dist = g[:, 0] if from_end != "right" else length - g[:, 0]     # distance from the saw's end
    with RunWriter(path, n_particles=len(g), particle_fields=fields,
                   static_fields={"x0": (g, "m"), "group": (group, "1")},
                   scalar_series={**series, "kinetic_energy": "J"},
                   attrs={"scenario": {"name": "pst_synth", "scene": scene}, "grid": {"dx": 2 * h}}) as w:
        for k in range(n_frames):
            t = DT * k
            s = A0 + SPEED * t
            behind = dist < s
            x = g.copy()
            x[:, 1] -= 0.004 * behind * (group >= 1)
            front = {"front_position": np.nan if k == 0 else s} if from_end is None else \
                {"front": 0.0 if k == 0 else s, "saw": min(A0, 10 * t)}
            log_jp = np.where(behind & (group == 1), np.log(0.8 - k * 0.01), 0.0)
            if from_end is not None:                   # the sawn cut: log_jp = 5 as pst.py's saw sets it
                log_jp[(group == 1) & (dist < front["saw"])] = 5.0
            w.write_frame(t, 100 * k, {"x": x, "v": -0.1 * behind[:, None] * [0, 1, 0], "log_jp": log_jp,
                                       "log_jp_ref": np.zeros(len(g)), "p": 1000.0 * g[:, 0] + k, "q": 50.0 * g[:, 1]},
                          scalars={**front, "kinetic_energy": t})
    return str(path)


@pytest.fixture(scope="module")
def pst(tmp_path_factory):
    return make_pst(tmp_path_factory.mktemp("render") / "pst.h5")


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("block") / "block.h5")
    mpm_warp.run("elastic_block", output=out, overrides=["time.end=0.03"])
    return out


def _magenta_columns(img: np.ndarray) -> np.ndarray:
    mask = np.all(img[..., :3] == render.FRONT_COLOR, axis=-1)
    return np.nonzero(mask)[1]


def _near(img: np.ndarray, rgb, tol: int = 12) -> int:
    """Number of pixels within ``tol`` (sum of channel differences) of colour ``rgb``."""
    return int((np.abs(img[..., :3].astype(int) - rgb).sum(-1) <= tol).sum())


def _expected_column(meta: dict, x: float) -> float:
    """Image column of world x in the side view: parallel projection along -z, x to the right."""
    w, h = meta["size"]
    cam = meta["camera"]
    return w / 2 + (x - cam["focal_point"][0]) * h / (2 * cam["parallel_scale"]) - 0.5


@pytest.mark.slow
def test_side_view_size_content_and_front_marker(pst, tmp_path):
    out = render.render_run(pst, field="collapse", out_dir=tmp_path, size=(640, 360))
    assert out.pngs == [str(tmp_path / f"collapse_{i:04d}.png") for i in range(4)] and out.video is None
    assert out.metadata["camera_preset"] == "side" and out.metadata["camera"]["view_up"] == [0.0, 1.0, 0.0]
    for k, (png, fr) in enumerate(zip(out.pngs, out.metadata["frames"], strict=True)):
        img = np.asarray(Image.open(png))
        assert img.shape[:2] == (360, 640)
        assert img.std() > 20 and len(np.unique(img.reshape(-1, img.shape[-1]), axis=0)) > 50  # not blank
        # particles drawn flat in the colour map's colours: intact snow at the low end of viridis,
        # the most collapsed weak layer (last frame) at its top end
        assert _near(img, (68, 1, 84)) > 0.2 * img.shape[0] * img.shape[1]
        assert (_near(img, (253, 231, 37)) > 500) == (k == 3)
        cols = _magenta_columns(img)
        if k == 0:                                     # no front yet (NaN): no marker
            assert cols.size == 0 and fr["front_position"] is None
            continue
        xf = A0 + SPEED * DT * k
        assert fr["front_position"] == pytest.approx(xf)
        assert cols.size > 50
        assert abs(np.median(cols) - _expected_column(out.metadata, xf)) <= 2.0
        assert fr["front_px"] == pytest.approx(_expected_column(out.metadata, xf), abs=1.0)
    # the marker moves right by SPEED * DT metres per frame, at the camera's pixels per metre
    ppm = 360 / (2 * out.metadata["camera"]["parallel_scale"])
    px = [f["front_px"] for f in out.metadata["frames"][1:]]
    assert np.diff(px) == pytest.approx(SPEED * DT * ppm, rel=1e-6)


@pytest.mark.parametrize("from_end", ["left", "right"])
def test_front_of_a_pst_run_is_converted_to_x(tmp_path, from_end):
    """A PST's ``front`` is a distance from the saw's end: the marker sits at x = s or L - s."""
    run = make_pst(tmp_path / "p.h5", n_frames=3, length=2.0, from_end=from_end)
    out = render.render_run(run, field="collapse", out_dir=tmp_path, size=(480, 240), frames="0,2")
    assert np.asarray(Image.open(out.pngs[0])).shape[:2] == (240, 480)
    assert _magenta_columns(np.asarray(Image.open(out.pngs[0]))).size == 0       # front = 0: none yet
    s = A0 + SPEED * 2 * DT
    x = s if from_end == "left" else 2.0 - s
    assert out.metadata["frames"][1]["front_position"] == pytest.approx(x)
    img = np.asarray(Image.open(out.pngs[1]))
    assert abs(np.median(_magenta_columns(img)) - _expected_column(out.metadata, x)) <= 2.0
    # the sawn cut (1 - J_P = 1 - e^5 < 0) stays out of the colour range and is drawn grey
    assert out.metadata["data_range"][0] == pytest.approx(1 - np.exp(5.0), rel=1e-6)
    assert out.clim == pytest.approx((0.0, 1 - (0.8 - 0.02)), rel=1e-6)
    assert _near(img, render.BELOW_COLOR, tol=3) > 100


@pytest.mark.slow
def test_colour_range_is_the_data_range_over_the_film(pst, tmp_path):
    run = read_run(pst)
    collapse = [1 - np.exp(run.frame(i)["log_jp"].astype(float)) for i in range(run.n_frames)]
    out = render.render_run(pst, field="collapse", out_dir=tmp_path, size=(320, 240), frames="1:3")
    assert out.clim == pytest.approx((0.0, max(c.max() for c in collapse[1:3])))
    assert json.loads(open(out.metadata_path).read())["clim"] == pytest.approx(list(out.clim))
    p = [run.frame(i)["p"].astype(float) for i in (0, -1)]
    out = render.render_run(pst, field="p", out_dir=tmp_path, size=(320, 240), frames=[0, -1])
    assert out.clim == pytest.approx((min(a.min() for a in p), max(a.max() for a in p)))
    assert out.unit == "Pa" and [f["index"] for f in out.metadata["frames"]] == [0, 3]
    out = render.render_run(pst, field="q", out_dir=tmp_path, size=(320, 240), frames="-1", clim=(0, 100))
    assert out.clim == (0.0, 100.0)


def test_oblique_view_and_gif(pst, tmp_path):
    out = render.render_run(pst, field="velocity", camera="oblique", frames="2,3", out_dir=tmp_path,
                            size=(400, 300), video=True)
    assert out[-1] == out.video == str(tmp_path / "velocity.gif") and len(out) == 3
    with Image.open(out.video) as gif:
        assert gif.n_frames == 2 and gif.size == (400, 300)
    img = np.asarray(Image.open(out.pngs[0]))
    assert img.shape[:2] == (300, 400) and _magenta_columns(img).size > 10
    assert out.clim == pytest.approx((0.0, 0.1))


def test_mp4_without_ffmpeg_is_a_clear_error(pst, tmp_path, monkeypatch):
    monkeypatch.setattr(film.shutil, "which", lambda name: None)
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)
    with pytest.raises(render.RenderingUnavailable, match="ffmpeg"):
        render.render_run(pst, field="q", frames="-1", out_dir=tmp_path, size=(128, 128), video="mp4")


def test_bad_arguments(pst, block, tmp_path):
    with pytest.raises(InvalidArgument, match="field"):
        render.render_run(pst, field="temperature", out_dir=tmp_path)
    with pytest.raises(InvalidArgument, match="log_jp"):
        render.render_run(block, field="collapse", out_dir=tmp_path)
    with pytest.raises(InvalidArgument, match="frames"):
        render.render_run(pst, frames="7", out_dir=tmp_path)
    with pytest.raises(InvalidArgument, match="camera"):
        render.render_run(pst, camera="top", out_dir=tmp_path)


def test_parse_frames():
    assert render.parse_frames(None, 5) == [0, 1, 2, 3, 4] == render.parse_frames("all", 5)
    assert render.parse_frames("0,2,-1", 5) == [0, 2, 4]
    assert render.parse_frames("1:5:2", 5) == [1, 3]
    assert render.parse_frames(-2, 5) == [3]
    assert render.parse_frames([0, 4], 5) == [0, 4]
    for bad in ("x", "5", "3:3"):
        with pytest.raises(InvalidArgument):
            render.parse_frames(bad, 5)


def test_gl_backend_choice(monkeypatch):
    libs = set()
    monkeypatch.setattr(gl, "_has_lib", lambda name: name in libs)
    monkeypatch.setattr(gl.glob, "glob", lambda pattern: [])
    monkeypatch.setattr(gl.sys, "platform", "linux")
    assert render.choose_gl_backend({"VTK_DEFAULT_OPENGL_WINDOW": "vtkXOpenGLRenderWindow"}) == (None, None)
    assert render.choose_gl_backend({"DISPLAY": ":0"}) == (None, None)
    window, problem = render.choose_gl_backend({})
    assert window is None and all(s in problem for s in ("libEGL", "OSMesa", "DISPLAY", "vtk-osmesa"))
    libs.update({"EGL"})                               # glvnd's libEGL without a vendor library
    assert render.choose_gl_backend({})[0] is None
    libs.update({"OSMesa"})
    assert render.choose_gl_backend({}) == ("vtkOSOpenGLRenderWindow", None)
    libs.update({"EGL_mesa"})
    assert render.choose_gl_backend({"DISPLAY": ":0"}) == ("vtkEGLRenderWindow", None)


def test_missing_gl_is_a_clear_error(pst, tmp_path, monkeypatch):
    monkeypatch.setattr(gl, "choose_gl_backend", lambda: (None, "off-screen rendering is unavailable: no libEGL"))
    with pytest.raises(render.RenderingUnavailable, match="libEGL"):
        render.render_run(pst, out_dir=tmp_path)


def test_cli_render(pst, tmp_path, capsys):
    assert main(["render", pst, "--field", "p", "--frames", "-1", "--out", str(tmp_path), "--size", "320", "200"]) == 0
    assert "1 frames of p [Pa]" in capsys.readouterr().out
    assert Image.open(tmp_path / "p_0003.png").size == (320, 200)
    with pytest.raises(SystemExit):
        main(["render", pst, "--field", "nope"])


@pytest.mark.slow
def test_end_to_end_elastic_block(block, tmp_path):
    run = read_run(block)
    out = render.render_run(block, field="displacement", out_dir=tmp_path, size=(480, 320))
    assert out.metadata["camera_preset"] == "oblique" and len(out.pngs) == run.n_frames == 2
    d = np.linalg.norm(run.frame(-1)["x"].astype(float) - run.static["x0"].astype(float), axis=1)
    assert out.clim == pytest.approx((0.0, d.max()), rel=1e-6, abs=1e-12) and d.max() > 1e-3
    img = np.asarray(Image.open(out.pngs[-1]))
    assert img.shape[:2] == (320, 480) and img.std() > 20 and _magenta_columns(img).size == 0
    out = render.render_run(block, field="velocity", camera="side", out_dir=tmp_path)
    v = np.concatenate([np.linalg.norm(run.frame(i)["v"].astype(float), axis=1) for i in range(run.n_frames)])
    assert out.clim == pytest.approx((v.min(), v.max()), rel=1e-6) and v.max() > 0.2
