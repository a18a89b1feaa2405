"""HDF5 run files and checkpoints of mpm_warp (NumPy and h5py only; no Warp).

- :mod:`mpm_warp.io.runfile`: :class:`RunWriter` and the file layout (crash safety);
- :mod:`mpm_warp.io.rundata`: :class:`RunData`, :func:`read_run`;
- :mod:`mpm_warp.io.checkpoint`: :func:`write_checkpoint`, :func:`read_checkpoint` (SHA-256 verified),
  :func:`checkpoint_path_for`;
- :mod:`mpm_warp.io.opening`: :func:`open_read`, which never hangs on a damaged file;
- :mod:`mpm_warp.io.lock`: :func:`output_lock`, one writer per run file;
- :mod:`mpm_warp.io.paths`: :func:`check_output_file`, :func:`check_output_dir`: what may be written;
- :mod:`mpm_warp.io.space`: a full disk (:class:`OutOfSpace`, :func:`atomic_write`);
- :mod:`mpm_warp.io.records`: a batch case's JSON record beside its run (:func:`write_record`,
  :func:`finished_record`);
- :mod:`mpm_warp.io.hdf5`: format names and the helpers they share.
"""

from ..errors import OutputError
from .checkpoint import (
    checkpoint_is_intact,
    checkpoint_path_for,
    read_checkpoint,
    read_checkpoint_meta,
    write_checkpoint,
)
from .hdf5 import CHECKPOINT_FORMAT, FORMAT, FORMAT_VERSION
from .lock import is_live, output_lock
from .paths import check_output_dir, check_output_file
from .records import finished_record, promote_part, write_record
from .rundata import RunData, read_run
from .runfile import RunWriter
from .space import OutOfSpace, atomic_write, ensure_space, space_errno

__all__ = ["FORMAT", "FORMAT_VERSION", "CHECKPOINT_FORMAT", "RunWriter", "RunData", "read_run",
           "write_checkpoint", "read_checkpoint", "read_checkpoint_meta", "checkpoint_path_for",
           "checkpoint_is_intact", "output_lock", "is_live", "check_output_file", "check_output_dir", "OutOfSpace",
           "atomic_write", "ensure_space", "space_errno", "OutputError", "write_record", "finished_record",
           "promote_part"]
