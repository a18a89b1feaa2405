"""The JSON record beside a run of a batch (a sweep's or a field batch's case): written whole, read back as done.

A batch writes each case's run as ``ID.part.h5``, moves it to ``ID.h5`` once complete, then writes ``ID.json``
through :func:`~.space.atomic_write`; :func:`finished_record` is how a rerun of the batch knows a case is done
(its JSON says "ok" and its run file reads back with the recorded frame count), so a killed batch loses no
finished case and reruns none.
"""

from __future__ import annotations

import json
import os

from ..errors import MPMError
from .checkpoint import checkpoint_path_for
from .rundata import read_run
from .space import atomic_write

__all__ = ["write_record", "finished_record", "promote_part"]


def write_record(path: str, obj: dict, what: str, default=None) -> None:
    """Write ``obj`` as indented JSON to ``path`` atomically (``what`` names it in a full-disk error)."""
    def write(tmp):
        with open(tmp, "w") as fh:
            json.dump(obj, fh, indent=1, default=default)
            fh.write("\n")

    atomic_write(path, write, what)


def finished_record(out: str) -> dict | None:
    """The record ``out.json`` of a case finished earlier ("ok", and ``out.h5`` reads back with its frames); else
    None (a file holding anything else, ``[]`` included, is a case to run again)."""
    try:
        with open(out + ".json") as fh:
            rec = json.load(fh)
        if (isinstance(rec, dict) and rec.get("status") == "ok"
                and read_run(out + ".h5").n_frames == rec.get("n_frames")):
            return rec
    except (OSError, ValueError, MPMError):
        pass
    return None


def promote_part(out: str) -> None:
    """Move a complete ``out.part.h5`` (and its checkpoint, when there is one) to ``out.h5``: the case is done."""
    part = out + ".part.h5"
    if os.path.exists(checkpoint_path_for(part)):
        os.replace(checkpoint_path_for(part), checkpoint_path_for(out + ".h5"))
    os.replace(part, out + ".h5")
