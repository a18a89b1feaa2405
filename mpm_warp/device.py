"""Device choice, made once at the edge: argument, then ``MPM_WARP_DEVICE``, then CUDA if present."""

from __future__ import annotations

import os

import warp as wp

from .errors import InvalidArgument

_initialised = False


def init_warp() -> None:
    """Initialise Warp once, quietly."""
    global _initialised
    if not _initialised:
        wp.config.quiet = True
        wp.init()
        _initialised = True


def resolve_device(device: str | None = None) -> str:
    """Return the Warp device name to use.

    Parameters
    ----------
    device : str or None
        ``"cpu"``, ``"cuda"`` or ``"cuda:N"``; ``None`` reads ``MPM_WARP_DEVICE``
        and falls back to the first CUDA device, else the CPU.
    """
    if device is not None and not isinstance(device, str):
        raise InvalidArgument("device", device, "None, 'cpu', 'cuda' or 'cuda:N' (a string)")
    init_warp()
    choice = device or os.environ.get("MPM_WARP_DEVICE") or None
    if choice is None:
        return "cuda:0" if wp.is_cuda_available() else "cpu"
    if choice == "cpu":
        return "cpu"
    if choice.startswith("cuda"):
        if not wp.is_cuda_available():
            raise InvalidArgument("device", choice, "'cpu' (no CUDA device is available on this machine)")
        if choice == "cuda":
            return "cuda:0"
        n = wp.get_cuda_device_count()
        index = choice[5:]
        if not (choice[4:5] == ":" and index.isdigit() and int(index) < n):
            raise InvalidArgument("device", choice, f"'cpu', 'cuda' or 'cuda:N' with N in [0, {n - 1}] (this machine "
                                  f"has {n} CUDA device{'s' * (n != 1)})")
        return choice
    raise InvalidArgument("device", choice, "'cpu', 'cuda' or 'cuda:N'")
