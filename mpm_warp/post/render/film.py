"""Joining rendered frames into a film: GIF (Pillow) or MP4 (ffmpeg)."""

from __future__ import annotations

import os
import shutil
import subprocess

from ...errors import RenderingUnavailable

__all__ = ["make_film", "ffmpeg"]


def ffmpeg() -> str:
    """Path of an ffmpeg executable (PATH, then imageio-ffmpeg's) or :class:`RenderingUnavailable`."""
    exe = shutil.which("ffmpeg")
    if exe is None:
        try:
            import imageio_ffmpeg

            exe = imageio_ffmpeg.get_ffmpeg_exe()
        except (ImportError, RuntimeError):
            raise RenderingUnavailable("an MP4 film needs ffmpeg: none on PATH and imageio-ffmpeg is not "
                                       "installed (pip install imageio-ffmpeg); or ask for a GIF "
                                       "(video='gif', --video gif)") from None
    return exe


def make_film(pngs: list[str], stem: str, fmt: str, fps: float) -> str:
    """Join PNG frames into ``stem.gif`` (Pillow) or ``stem.mp4`` (ffmpeg)."""
    if fmt == "gif":
        from PIL import Image

        images = [Image.open(p).convert("RGB") for p in pngs]
        images[0].save(stem + ".gif", save_all=True, append_images=images[1:], loop=0,
                       duration=max(int(round(1000 / fps)), 20))
        return stem + ".gif"
    exe, listing = ffmpeg(), stem + "_frames.txt"
    with open(listing, "w") as f:
        for p in pngs:
            f.write(f"file '{os.path.abspath(p)}'\nduration {1.0 / fps}\n")
    cmd = [exe, "-y", "-loglevel", "error", "-f", "concat", "-safe", "0", "-i", listing, "-vf",
           "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", "-r", str(fps), stem + ".mp4"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    os.remove(listing)
    if res.returncode != 0:
        raise RenderingUnavailable(f"ffmpeg failed ({res.returncode}): {res.stderr.strip()}")
    return stem + ".mp4"
