"""HDF5 run files and checkpoints of mpm_warp (NumPy and h5py only; no Warp).

- :mod:`mpm_warp.io.runfile`: :class:`RunWriter` and the file layout (crash safety);
- :mod:`mpm_warp.io.rundata`: :class:`RunData`, :func:`read_run`;
- :mod:`mpm_warp.io.checkpoint`: :func:`write_checkpoint`, :func:`read_checkpoint`, :func:`checkpoint_path_for`;
- :mod:`mpm_warp.io.hdf5`: format names and the helpers they share.
"""

from .checkpoint import checkpoint_path_for, read_checkpoint, read_checkpoint_meta, write_checkpoint
from .hdf5 import CHECKPOINT_FORMAT, FORMAT, FORMAT_VERSION
from .rundata import RunData, read_run
from .runfile import RunWriter

__all__ = ["FORMAT", "FORMAT_VERSION", "CHECKPOINT_FORMAT", "RunWriter", "RunData", "read_run",
           "write_checkpoint", "read_checkpoint", "read_checkpoint_meta", "checkpoint_path_for"]
