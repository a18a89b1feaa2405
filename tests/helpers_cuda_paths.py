"""Stand-ins that run the CUDA-only code paths on the CPU (docs/architecture.md, "CUDA-only code paths").

- :func:`cuda_looking`: replaces the ``wp`` of the given engine modules by Warp whose ``get_device``
  answers ``is_cuda = True`` (and a chosen ``free_memory``) for the CPU device; the arrays stay on the CPU.
  The stepper then builds its CUDA plan (one thread and grid copy, a grid node per grid-update thread,
  graphs on) and the memory guard takes its device path.
- :class:`CaptureGuard`: wraps ``wp.ScopedCapture`` (a real capture: Warp records graphs on the CPU too and
  replays them without running the work at capture time, as CUDA does). While a capture is open it
  records every allocation, host read or write of an array (``numpy``, ``list``, ``assign``), ``wp.copy``
  and synchronisation, with the line of the caller, and the operations captured (launches, ``zero_``,
  ``fill_``), so that a test can check that the captured body neither allocates nor reads the device
  and issues the same operations whatever the device state (no host branch on device values).
"""

from __future__ import annotations

import contextlib
import os
import traceback

import warp as wp
from warp._src import context as _ctx

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_HERE = os.path.abspath(__file__)
_WARP = os.path.dirname(os.path.abspath(wp.__file__)) + os.sep


class _CudaLookingDevice:
    """The CPU device, answering ``is_cuda`` True and ``free_memory`` as given."""

    is_cuda = True
    is_cpu = False

    def __init__(self, real, free_memory: int):
        self._real = real
        self.free_memory = free_memory

    def __getattr__(self, name):
        return getattr(self._real, name)


class _WarpOnCudaLookingDevice:
    """Warp, with ``get_device`` giving :class:`_CudaLookingDevice`."""

    def __init__(self, free_memory: int):
        self._free = free_memory

    def get_device(self, device=None):
        return _CudaLookingDevice(wp.get_device(device), self._free)

    def __getattr__(self, name):
        return getattr(wp, name)


def cuda_looking(monkeypatch, *modules, free_memory: int = 1 << 40) -> None:
    """Make ``modules`` (engine modules that ``import warp as wp``) see the CPU as a CUDA device."""
    for m in modules:
        monkeypatch.setattr(m, "wp", _WarpOnCudaLookingDevice(free_memory))


def _caller() -> str:
    """``file:line in function`` of the innermost caller outside Warp and this file."""
    for fr in reversed(traceback.extract_stack()[:-2]):
        f = os.path.abspath(fr.filename)
        if f != _HERE and not f.startswith(_WARP) and not f.startswith(os.path.dirname(contextlib.__file__)):
            return f"{os.path.relpath(f, ROOT) if f.startswith(ROOT) else f}:{fr.lineno} in {fr.name}"
    return "?"


def _kernel_key(kernel) -> str:
    return kernel.func.__qualname__


class CaptureGuard:
    """Guard every ``wp.ScopedCapture`` opened while installed (a context manager).

    Attributes
    ----------
    violations : list of str
        ``"<what> at <caller>"`` for each forbidden call made inside a capture.
    captures : list of list of tuple
        Per capture, the operations it recorded in order: ``("launch", kernel, dim)``, ``("zero", shape)``,
        ``("fill", shape)``.
    """

    FORBIDDEN = {"allocation": [(cls, "allocate") for cls in (
        _ctx.CpuDefaultAllocator, _ctx.CpuPinnedAllocator, _ctx.CudaDefaultAllocator, _ctx.CudaMempoolAllocator,
        _ctx.CudaManagedAllocator)],
        "host read (numpy)": [(wp.array, "numpy")], "host read (list)": [(wp.array, "list")],
        "host write (assign)": [(wp.array, "assign")], "copy": [(wp, "copy")],
        "synchronisation": [(wp, n) for n in ("synchronize", "synchronize_device", "synchronize_stream",
                                              "synchronize_event")]}

    def __init__(self):
        self.violations: list[str] = []
        self.captures: list[list[tuple]] = []
        self._ops: list[tuple] | None = None
        self._saved: list = []

    # ------------------------------------------------------------------ hooks while a capture is open
    def _patch(self, owner, name, make):
        real = getattr(owner, name)
        self._saved.append((owner, name, real))
        setattr(owner, name, make(real))

    def _open(self, check: bool = True) -> None:
        self._ops = []
        for what, targets in self.FORBIDDEN.items() if check else ():
            for owner, name in targets:
                def make(real, what=what, name=name):
                    def hooked(*a, **k):
                        self.violations.append(f"{what}: {name} at {_caller()}")
                        return real(*a, **k)
                    return hooked
                self._patch(owner, name, make)
        ops = self._ops

        def launch_rec(real):
            def launch(obj, *a, **k):
                ops.append(("launch", _kernel_key(obj.kernel), tuple(obj.bounds.shape)))
                return real(obj, *a, **k)
            return launch

        def wp_launch_rec(real):
            def launch(kernel, dim, *a, **k):
                ops.append(("launch", _kernel_key(kernel), tuple(dim) if hasattr(dim, "__len__") else (dim,)))
                return real(kernel, dim, *a, **k)
            return launch

        def fill_rec(kind):
            def make(real):
                def f(arr, *a, **k):
                    ops.append((kind, tuple(arr.shape)))
                    return real(arr, *a, **k)
                return f
            return make

        self._patch(_ctx.Launch, "launch", launch_rec)
        self._patch(wp, "launch", wp_launch_rec)
        self._patch(wp.array, "zero_", fill_rec("zero"))
        self._patch(wp.array, "fill_", fill_rec("fill"))

    def _close(self) -> None:
        for owner, name, real in reversed(self._saved):
            setattr(owner, name, real)
        self._saved.clear()
        self.captures.append(self._ops)
        self._ops = None

    # --------------------------------------------------------------------------------- installing
    def __enter__(self):
        guard = self
        real = self._real = wp.ScopedCapture

        class GuardedCapture(real):
            def __enter__(self):
                out = super().__enter__()
                guard._open()
                return out

            def __exit__(self, *exc):
                guard._close()
                return super().__exit__(*exc)

        wp.ScopedCapture = GuardedCapture
        return self

    def __exit__(self, *exc):
        wp.ScopedCapture = self._real
        return False


@contextlib.contextmanager
def recorded_ops(guard: CaptureGuard):
    """Record the operations issued while the block runs, without a capture and without checks, into
    ``guard.captures[-1]``: the eager counterpart of a captured body."""
    guard._open(check=False)
    try:
        yield
    finally:
        guard._close()
