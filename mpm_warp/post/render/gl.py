"""OpenGL back end for off-screen rendering on headless machines (see :mod:`mpm_warp.post.render`)."""

from __future__ import annotations

import ctypes.util
import glob
import os
import sys

from ...errors import RenderingUnavailable

__all__ = ["choose_gl_backend", "setup_gl"]


def _has_lib(name: str) -> bool:
    return ctypes.util.find_library(name) is not None


def choose_gl_backend(environ=None) -> tuple[str | None, str | None]:
    """VTK OpenGL window class for off-screen rendering in ``environ`` (default ``os.environ``).

    Returns ``(window_class, problem)``: the class to put in ``VTK_DEFAULT_OPENGL_WINDOW`` (None:
    leave VTK's default) and, when nothing can render, a message saying what is missing (else None).
    """
    env = os.environ if environ is None else environ
    if env.get("VTK_DEFAULT_OPENGL_WINDOW") or not sys.platform.startswith("linux"):
        return None, None
    egl_vendor = (_has_lib("EGL_mesa") or _has_lib("EGL_nvidia")
                  or bool(glob.glob("/usr/share/glvnd/egl_vendor.d/*.json")))
    if _has_lib("EGL") and egl_vendor:
        return "vtkEGLRenderWindow", None
    if _has_lib("OSMesa"):
        return "vtkOSOpenGLRenderWindow", None
    if env.get("DISPLAY"):
        return None, None
    return None, ("off-screen rendering is unavailable: VTK needs an X display (DISPLAY is not set), "
                  "EGL (libEGL.so.1 with a vendor library such as libEGL_mesa.so.0; Debian/Ubuntu: "
                  "apt install libegl1 libegl-mesa0) or OSMesa (libOSMesa; apt install libosmesa6), "
                  "and none was found; or install VTK's self-contained OSMesa wheel: "
                  "pip install --extra-index-url https://wheels.vtk.org vtk-osmesa")


def setup_gl() -> None:
    """Set ``VTK_DEFAULT_OPENGL_WINDOW`` (read when VTK creates a window) or raise what is missing."""
    window, problem = choose_gl_backend()
    if problem:
        raise RenderingUnavailable(problem)
    if window:
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = window
